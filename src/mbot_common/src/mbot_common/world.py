"""World files (src/mbot_sim/WORLD_FORMAT.md), read exactly as strictly as stage_node reads them
(the C++ twin is world_file.h; both pass the same fixtures in test/fixtures/worlds).

    world = load_world(resolve_world("office"))
    for robot in world.robots:
        print(robot.name, robot.model, robot.pose.x, robot.pose.y, robot.pose.theta)
    world.map_data.occupancy       # the map, as map_server publishes it (mbot_common.maps)

Checked here: keys, types, ranges, unique names, faults naming a robot of the file, and that the
map loads. Not checked here: the geometry (a robot inside a wall or outside the map) and the
robot models; stage_node checks those when it builds the world.
"""
import math
from collections import namedtuple

from mbot_common.geometry import Pose2D
from mbot_common.maps import load_map
from mbot_common.strict_yaml import ConfigError, Reader, load_yaml

#: Shape of an obstacle: type "box" (length along its x, width along its y [m]) or "cylinder"
#: (radius [m]); the other sizes are 0.
Shape = namedtuple("Shape", "type length width radius")
#: A robot: name (its namespace and frame prefix), model (mbot_description), start pose in the
#: map (Pose2D), key (where it is in the file, e.g. "robots[1]", for messages).
#: A robot's 3D lidar (robots[i].lidar: true, false or a map of LIDAR_KEYS; world_file.h
#: LidarConfig): rate [Hz], points_per_frame, min/max_elevation [deg], range_min/max [m],
#: range_noise [m] (Gaussian sigma), range_quantization [m].
LIDAR_KEYS = ["rate", "points_per_frame", "min_elevation", "max_elevation", "range_min", "range_max", "range_noise",
              "range_quantization"]
Lidar = namedtuple("Lidar", ["enabled"] + LIDAR_KEYS)
NO_LIDAR = Lidar(False, 10.0, 20000, -7.0, 52.0, 0.1, 40.0, 0.02, 0.001)
Robot = namedtuple("Robot", "name model pose key lidar", defaults=(NO_LIDAR,))
#: A static box or cylinder besides the map walls; pose: Pose2D in the map.
#: height [m]: how tall the 3D lidar sees it.
Obstacle = namedtuple("Obstacle", "name shape pose key height", defaults=(1.0,))
#: A kinematic body that follows waypoints [(x, y) m] at speed [m/s]; mode "loop" or "ping_pong";
#: yielding in [0, 1]: how much it gives way to bodies within personal_radius [m] of its outline
#: (0: a blind waypoint follower).
MovingObstacle = namedtuple("MovingObstacle", "name shape waypoints speed mode yielding personal_radius key height",
                            defaults=(1.7,))
#: Every robot's IMU error model (noise.imu; world_file.h ImuNoiseConfig has the units): rate [Hz],
#: white noise densities, bias random walks, start-bias spreads, quantization steps, time_offset [s].
IMU_KEYS = ["rate", "gyro_noise_density", "gyro_random_walk", "gyro_bias_init", "accel_noise_density",
            "accel_random_walk", "accel_bias_init", "gyro_quantization", "accel_quantization", "time_offset"]
ImuNoise = namedtuple("ImuNoise", IMU_KEYS)
#: The defaults: a consumer MEMS IMU of the order of the ICM-20948 datasheet (as world_file.h).
IMU_DEFAULTS = ImuNoise(200.0, 2.6e-4, 2.0e-5, 5.0e-3, 2.3e-3, 4.0e-4, 0.05, 1.33e-4, 6.0e-4, 0.0)
_IMU_UNITS = ["[Hz]", "[rad/s/sqrt(Hz)]", "[rad/s^2/sqrt(Hz)]", "[rad/s]", "[m/s^2/sqrt(Hz)]",
              "[m/s^3/sqrt(Hz)]", "[m/s^2]", "[rad/s]", "[m/s^2]", "[s]"]
#: Standard deviations of sensor noise: laser_range [m], odom_linear [m/s], odom_angular [rad/s];
#: imu: ImuNoise.
Noise = namedtuple("Noise", "laser_range odom_linear odom_angular imu", defaults=(IMU_DEFAULTS,))
#: Faults of a robot (mbot_msgs/SetFault): laser_dropout [0, 1], sensor_latency [s],
#: sensor_jitter [s], odom_drift [rad/s], drive_frozen, silenced.
Faults = namedtuple("Faults", "laser_dropout sensor_latency sensor_jitter odom_drift drive_frozen silenced")
#: The faults entry of the world file for one robot.
RobotFaults = namedtuple("RobotFaults", "robot faults key")
#: Everything a world file says. file: the world file as given; map: the map entry as written;
#: map_path: the map yaml (relative to the world file's directory); map_data: the loaded map
#: (MapData); physics_step [s]; real_time_factor (0 = as fast as possible); seed.
World = namedtuple("World", "file map map_path map_data physics_step real_time_factor seed robots obstacles "
                            "moving_obstacles noise faults wall_height", defaults=(2.5,))

TOP_KEYS = ["map", "physics_step", "real_time_factor", "seed", "robots", "obstacles", "moving_obstacles",
            "noise", "faults", "wall_height"]
FAULT_KEYS = ["laser_dropout", "sensor_latency", "sensor_jitter", "odom_drift", "drive_frozen", "silenced"]
NO_FAULTS = Faults(0.0, 0.0, 0.0, 0.0, False, False)


def _imu_noise(ir):
    """noise.imu, checked as world_file.cpp's readImuNoise()."""
    ir.check_keys(IMU_KEYS)
    values = []
    for key, unit, default in zip(IMU_KEYS, _IMU_UNITS, IMU_DEFAULTS):
        if key == "rate":
            value = ir.optional(key, float, default, what="a number > 0 [Hz]", check=lambda v: v > 0.0)
            if value > 10000.0:
                ir.expected(key, "a number in (0, 10000] [Hz]", ir.data[key])
        elif key == "time_offset":
            value = ir.optional(key, float, default, what="a number in [-1, 1] [s]", check=lambda v: abs(v) <= 1.0)
        else:
            value = ir.optional(key, float, default, what="a number >= 0 " + unit, check=lambda v: v >= 0.0)
        values.append(value)
    return ImuNoise(*values)


def check_name(name):
    """'' if `name` is a valid robot or body name (a ROS graph name without a leading slash:
    letters, digits and _, not starting with a digit, segments joined by /), else the problem."""
    bad = 'expected a name of letters, digits and _ (not starting with a digit), got "%s"' % name
    if not name:
        return bad
    for segment in name.split("/"):
        if not segment or segment[0].isdigit():
            return bad
        if not all((c.isascii() and c.isalnum()) or c == "_" for c in segment):
            return bad
    return ""


def check_faults(faults):
    """'' if the Faults are in range, else the problem with the field name, e.g.
    "laser_dropout: expected a probability in [0, 1], got 1.5"."""
    def bad(field, what, value):
        return "%s: expected %s, got %g" % (field, what, value)
    if not 0.0 <= faults.laser_dropout <= 1.0:
        return bad("laser_dropout", "a probability in [0, 1]", faults.laser_dropout)
    if not 0.0 <= faults.sensor_latency <= 10.0:
        return bad("sensor_latency", "a delay in [0, 10] s", faults.sensor_latency)
    if not 0.0 <= faults.sensor_jitter <= 10.0:
        return bad("sensor_jitter", "a standard deviation in [0, 10] s", faults.sensor_jitter)
    if not math.isfinite(faults.odom_drift):
        return bad("odom_drift", "a finite number [rad/s]", faults.odom_drift)
    return ""


def _directory_of(path):
    slash = path.rfind("/")
    return "." if slash < 0 else path[:slash]


def _text(r, key, what):
    """A scalar as text (as the C++ reader's text(): `name: 5` is the name "5")."""
    value = r.required(key, object)
    if value is None or isinstance(value, (dict, list)):
        r.expected(key, what, value)
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _name(r, key):
    name = _text(r, key, "a name")
    problem = check_name(name)
    if problem:
        r.fail(key, problem)
    return name


def _positive(r, key, unit):
    return r.required(key, float, what="a number > 0 " + unit, check=lambda v: v > 0.0)


def _numbers(r, key, value, n, what):
    """A list of exactly n numbers that is not a key of r's map (a waypoint)."""
    if not isinstance(value, list) or len(value) != n:
        r.expected(key, what, value)
    for item in value:
        if isinstance(item, bool) or not isinstance(item, (int, float)) or not math.isfinite(item):
            r.expected(key, what, item)
    return [float(v) for v in value]


def _shape(r):
    kind = _text(r, "shape", "box or cylinder")
    if kind == "box":
        if "radius" in r:
            r.fail("radius", "a box has a size [length, width], not a radius")
        if "size" not in r:
            r.fail("size", "missing key (required for a box)")
        what = "a list of 2 numbers > 0 [length, width]"
        length, width = r.number_list("size", 2, what=what)
        if length <= 0.0 or width <= 0.0:
            r.expected("size", what, r.data["size"])
        return Shape("box", length, width, 0.0)
    if kind == "cylinder":
        if "size" in r:
            r.fail("size", "a cylinder has a radius, not a size")
        if "radius" not in r:
            r.fail("radius", "missing key (required for a cylinder)")
        return Shape("cylinder", 0.0, 0.0, _positive(r, "radius", "[m]"))
    r.expected("shape", "box or cylinder", r.data["shape"])


def _lidar(rr):
    """robots[i].lidar, checked as world_file.cpp's readLidar()."""
    value = rr.required("lidar", object)
    if isinstance(value, bool):
        return NO_LIDAR._replace(enabled=value)
    if not isinstance(value, dict):
        rr.expected("lidar", "true, false or a map of lidar settings", value)
    lr = rr.child("lidar")
    lr.check_keys(LIDAR_KEYS)
    rate = lr.optional("rate", float, NO_LIDAR.rate, what="a number > 0 [Hz]", check=lambda v: v > 0.0)
    points = lr.optional("points_per_frame", int, NO_LIDAR.points_per_frame, what="an integer in [1, 1000000]",
                         check=lambda v: 1 <= v <= 1000000)
    elevation = "a number in (-90, 90) [deg]"
    low = lr.optional("min_elevation", float, NO_LIDAR.min_elevation, what=elevation, check=lambda v: -90.0 < v < 90.0)
    high = lr.optional("max_elevation", float, NO_LIDAR.max_elevation, what=elevation, check=lambda v: -90.0 < v < 90.0)
    if not high > low:
        lr.fail("max_elevation", "expected more than min_elevation (%g deg)" % low)
    range_min = lr.optional("range_min", float, NO_LIDAR.range_min, what="a number >= 0 [m]", check=lambda v: v >= 0.0)
    range_max = lr.optional("range_max", float, NO_LIDAR.range_max, what="a number > 0 [m]", check=lambda v: v > 0.0)
    if not range_max > range_min:
        lr.fail("range_max", "expected more than range_min (%g m)" % range_min)
    noise = lr.optional("range_noise", float, NO_LIDAR.range_noise, what="a number >= 0 [m]", check=lambda v: v >= 0.0)
    step = lr.optional("range_quantization", float, NO_LIDAR.range_quantization, what="a number >= 0 [m]",
                       check=lambda v: v >= 0.0)
    return Lidar(True, rate, points, low, high, range_min, range_max, noise, step)


def _height(r, default):
    return r.optional("height", float, default, what="a number > 0 [m]", check=lambda v: v > 0.0)


def _pose(r, key="pose"):
    return Pose2D(*r.number_list(key, 3, what="a list of 3 numbers [x, y, yaw]"))


def load_world(path):
    """Read the world file `path` strictly and load its map. ConfigError "<file>: <key>: <problem>"
    with the same texts as stage_node; a map error reads "<file>: map: <the map's error>"."""
    r = Reader(load_yaml(path), path)
    r.check_keys(TOP_KEYS, required=["map"])

    map_file = _text(r, "map", "a map_server yaml file name")
    if not map_file:
        r.expected("map", "a map_server yaml file name", r.data["map"])
    map_path = map_file if map_file.startswith("/") else _directory_of(path) + "/" + map_file

    physics_step = 0.01  # [s]
    if "physics_step" in r:
        physics_step = _positive(r, "physics_step", "[s]")
        if physics_step > 0.1:
            r.expected("physics_step", "a number in (0, 0.1] [s]", r.data["physics_step"])
    real_time_factor = r.optional("real_time_factor", float, 1.0, what="a number >= 0 (0 = as fast as possible)",
                                  check=lambda v: v >= 0.0)
    wall_height = r.optional("wall_height", float, 2.5, what="a number > 0 [m]", check=lambda v: v > 0.0)
    seed = r.optional("seed", int, 0, what="an integer >= 0")
    if not 0 <= seed <= 0xffffffff:
        r.expected("seed", "an integer in [0, 4294967295]", seed)

    # Every body (robot, obstacle, moving obstacle) has a unique name: contacts report names.
    names = {"map"}

    def claim(reader, name):
        if name in names:
            reader.fail("name", 'duplicate name "%s" (robot and obstacle names must be unique, "map" is the walls)'
                        % name)
        names.add(name)

    robots = []
    for i, rr in enumerate(r.children("robots", required=False)):
        rr.check_keys(["name", "model", "pose", "lidar"], required=["name", "pose"])
        name = _name(rr, "name")
        claim(rr, name)
        model = _name(rr, "model") if "model" in rr else "mbot"
        pose = _pose(rr)
        robots.append(Robot(name, model, pose, "robots[%d]" % i, _lidar(rr) if "lidar" in rr else NO_LIDAR))

    obstacles = []
    for i, orr in enumerate(r.children("obstacles", required=False)):
        orr.check_keys(["name", "shape", "size", "radius", "pose", "height"], required=["shape", "pose"])
        name = _name(orr, "name") if "name" in orr else "obstacle_%d" % i
        claim(orr, name)
        shape = _shape(orr)
        pose = _pose(orr)
        obstacles.append(Obstacle(name, shape, pose, "obstacles[%d]" % i, _height(orr, 1.0)))

    moving_obstacles = []
    for i, mr in enumerate(r.children("moving_obstacles", required=False)):
        mr.check_keys(["name", "shape", "size", "radius", "waypoints", "speed", "mode", "yielding", "personal_radius",
                       "height"], required=["shape", "waypoints", "speed"])
        name = _name(mr, "name") if "name" in mr else "moving_obstacle_%d" % i
        claim(mr, name)
        shape = _shape(mr)
        points = mr.required("waypoints", object)
        if not isinstance(points, list) or len(points) < 2:
            mr.expected("waypoints", "a list of at least 2 points [[x, y], ...]", points)
        waypoints = []
        for k, point in enumerate(points):
            x, y = _numbers(mr, "waypoints[%d]" % k, point, 2, "a point [x, y]")
            if waypoints and math.hypot(x - waypoints[-1][0], y - waypoints[-1][1]) < 1e-6:
                mr.fail("waypoints[%d]" % k, "the same point as the waypoint before it")
            waypoints.append((x, y))
        speed = _positive(mr, "speed", "[m/s]")
        mode = "loop"
        if "mode" in mr:
            mode = _text(mr, "mode", "loop or ping_pong")
            if mode not in ("loop", "ping_pong"):
                mr.expected("mode", "loop or ping_pong", mr.data["mode"])
        yielding = mr.optional("yielding", float, 1.0, what="a number in [0, 1] (0: it does not give way)",
                               check=lambda v: 0.0 <= v <= 1.0)
        personal_radius = mr.optional("personal_radius", float, 0.8, what="a number > 0 [m]", check=lambda v: v > 0.0)
        moving_obstacles.append(MovingObstacle(name, shape, waypoints, speed, mode, yielding, personal_radius,
                                               "moving_obstacles[%d]" % i, _height(mr, 1.7)))

    nr = r.child("noise", required=False)
    nr.check_keys(["laser_range", "odom_linear", "odom_angular", "imu"])

    def non_negative(key, unit):
        return nr.optional(key, float, 0.0, what="a number >= 0 " + unit, check=lambda v: v >= 0.0)
    noise = Noise(non_negative("laser_range", "[m]"), non_negative("odom_linear", "[m/s]"),
                  non_negative("odom_angular", "[rad/s]"), _imu_noise(nr.child("imu", required=False)))

    faults = []
    for i, fr in enumerate(r.children("faults", required=False)):
        fr.check_keys(["robot"] + FAULT_KEYS, required=["robot"])
        robot = _text(fr, "robot", "a robot name")
        if robot not in [rb.name for rb in robots]:
            fr.fail("robot", 'no robot named "%s" in robots' % robot)
        if robot in [f.robot for f in faults]:
            fr.fail("robot", 'a second faults entry for "%s" (one entry per robot)' % robot)
        values = Faults(*[fr.optional(key, float, 0.0) for key in FAULT_KEYS[:4]] +
                        [fr.optional(key, bool, False) for key in FAULT_KEYS[4:]])
        problem = check_faults(values)
        if problem:
            field, _, rest = problem.partition(": ")
            fr.fail(field, rest)
        faults.append(RobotFaults(robot, values, "faults[%d]" % i))
    r.finish()

    try:
        map_data = load_map(map_path)
    except ConfigError as error:
        raise ConfigError("%s: map: %s" % (path, error))
    return World(path, map_file, map_path, map_data, physics_step, real_time_factor, seed, robots, obstacles,
                 moving_obstacles, noise, faults, wall_height)
