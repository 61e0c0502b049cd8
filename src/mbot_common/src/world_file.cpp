/**
 * @file world_file.cpp
 * @brief The strict world file reader (WORLD_FORMAT.md), moved from mbot_sim's world_config.cpp;
 *        it also loads the map. mbot_common/world.py mirrors it check by check.
 */
#include "mbot_common/world_file.h"

#include <cctype>
#include <cmath>
#include <set>
#include <sstream>

namespace mbot_common
{
namespace
{
using Reader = StrictYaml<WorldConfigError>;

std::string formatNumber(double v)
{
  std::ostringstream out;
  out << v;
  return out.str();
}

std::string directoryOf(const std::string& path)
{
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? std::string(".") : path.substr(0, slash);
}

Pose2D readPose(const Reader& r, const YAML::Node& node, const std::string& key)
{
  const std::vector<double> v = r.numbers(node, key, 3, "a list of 3 numbers [x, y, yaw]");
  return Pose2D{v[0], v[1], v[2]};
}

/// A positive number [m] or similar.
double positive(const Reader& r, const YAML::Node& node, const std::string& key, const std::string& unit)
{
  const std::string what = "a number > 0 " + unit;
  const double v = r.number(node, key, what);
  if (v <= 0.0) r.expected(key, what, node);
  return v;
}

double nonNegative(const Reader& r, const YAML::Node& node, const std::string& key, const std::string& unit)
{
  const std::string what = "a number >= 0 " + unit;
  const double v = r.number(node, key, what);
  if (v < 0.0) r.expected(key, what, node);
  return v;
}

void readImuNoise(const Reader& r, const YAML::Node& imu, ImuNoiseConfig& out)
{
  r.checkKeys(imu, "noise.imu",
              {"rate", "gyro_noise_density", "gyro_random_walk", "gyro_bias_init", "accel_noise_density",
               "accel_random_walk", "accel_bias_init", "gyro_quantization", "accel_quantization", "time_offset"});
  auto non_negative = [&](const char* key, const char* unit, double& value) {
    if (imu[key]) value = nonNegative(r, imu[key], std::string("noise.imu.") + key, unit);
  };
  if (imu["rate"])
  {
    const std::string what = "a number in (0, 10000] [Hz]";
    out.rate = positive(r, imu["rate"], "noise.imu.rate", "[Hz]");
    if (out.rate > 10000.0) r.expected("noise.imu.rate", what, imu["rate"]);
  }
  non_negative("gyro_noise_density", "[rad/s/sqrt(Hz)]", out.gyro_noise_density);
  non_negative("gyro_random_walk", "[rad/s^2/sqrt(Hz)]", out.gyro_random_walk);
  non_negative("gyro_bias_init", "[rad/s]", out.gyro_bias_init);
  non_negative("accel_noise_density", "[m/s^2/sqrt(Hz)]", out.accel_noise_density);
  non_negative("accel_random_walk", "[m/s^3/sqrt(Hz)]", out.accel_random_walk);
  non_negative("accel_bias_init", "[m/s^2]", out.accel_bias_init);
  non_negative("gyro_quantization", "[rad/s]", out.gyro_quantization);
  non_negative("accel_quantization", "[m/s^2]", out.accel_quantization);
  if (imu["time_offset"])
  {
    const std::string what = "a number in [-1, 1] [s]";
    out.time_offset = r.number(imu["time_offset"], "noise.imu.time_offset", what);
    if (!(std::abs(out.time_offset) <= 1.0)) r.expected("noise.imu.time_offset", what, imu["time_offset"]);
  }
}

/// A robot's `lidar:` (true / false / a map of its settings).
LidarConfig readLidar(const Reader& r, const YAML::Node& node, const std::string& key)
{
  LidarConfig lidar;
  const std::string what = "true, false or a map of lidar settings";
  if (!node.IsMap())
  {
    bool on = false;
    if (!node.IsScalar() || node.Tag() == "!" || !YAML::convert<bool>::decode(node, on)) r.expected(key, what, node);
    lidar.enabled = on;
    return lidar;
  }
  lidar.enabled = true;
  r.checkKeys(node, key,
              {"rate", "points_per_frame", "min_elevation", "max_elevation", "range_min", "range_max", "range_noise",
               "range_quantization"});
  auto sub = [&](const char* k) { return Reader::join(key, k); };
  if (node["rate"]) lidar.rate = positive(r, node["rate"], sub("rate"), "[Hz]");
  if (node["points_per_frame"])
  {
    const long long n = r.integer(node["points_per_frame"], sub("points_per_frame"), "an integer in [1, 1000000]");
    if (n < 1 || n > 1000000)
      r.expected(sub("points_per_frame"), "an integer in [1, 1000000]", node["points_per_frame"]);
    lidar.points_per_frame = static_cast<int>(n);
  }
  const std::string el_what = "a number in (-90, 90) [deg]";
  for (const char* k : {"min_elevation", "max_elevation"})
  {
    if (!node[k]) continue;
    const double v = r.number(node[k], sub(k), el_what);
    if (!(v > -90.0 && v < 90.0)) r.expected(sub(k), el_what, node[k]);
    (std::string(k) == "min_elevation" ? lidar.min_elevation : lidar.max_elevation) = v;
  }
  if (!(lidar.max_elevation > lidar.min_elevation))
    r.fail(sub("max_elevation"), "expected more than min_elevation (" + formatNumber(lidar.min_elevation) + " deg)");
  if (node["range_min"]) lidar.range_min = nonNegative(r, node["range_min"], sub("range_min"), "[m]");
  if (node["range_max"]) lidar.range_max = positive(r, node["range_max"], sub("range_max"), "[m]");
  if (!(lidar.range_max > lidar.range_min))
    r.fail(sub("range_max"), "expected more than range_min (" + formatNumber(lidar.range_min) + " m)");
  if (node["range_noise"]) lidar.range_noise = nonNegative(r, node["range_noise"], sub("range_noise"), "[m]");
  if (node["range_quantization"])
    lidar.range_quantization = nonNegative(r, node["range_quantization"], sub("range_quantization"), "[m]");
  return lidar;
}

std::string readName(const Reader& r, const YAML::Node& node, const std::string& key)
{
  const std::string name = r.text(node, key, "a name");
  const std::string problem = checkName(name);
  if (!problem.empty()) r.fail(key, problem);
  return name;
}

/// shape + size (box) or radius (cylinder); `item` is the obstacle's map.
ShapeConfig readShape(const Reader& r, const YAML::Node& item, const std::string& where)
{
  ShapeConfig shape;
  const std::string key = Reader::join(where, "shape");
  const std::string type = r.text(item["shape"], key, "box or cylinder");
  if (type == "box")
  {
    shape.type = ShapeConfig::Type::BOX;
    if (item["radius"]) r.fail(Reader::join(where, "radius"), "a box has a size [length, width], not a radius");
    if (!item["size"]) r.fail(Reader::join(where, "size"), "missing key (required for a box)");
    const std::string size_key = Reader::join(where, "size");
    const std::string what = "a list of 2 numbers > 0 [length, width]";
    const std::vector<double> size = r.numbers(item["size"], size_key, 2, what);
    if (size[0] <= 0.0 || size[1] <= 0.0) r.expected(size_key, what, item["size"]);
    shape.length = size[0];
    shape.width = size[1];
  }
  else if (type == "cylinder")
  {
    shape.type = ShapeConfig::Type::CYLINDER;
    if (item["size"]) r.fail(Reader::join(where, "size"), "a cylinder has a radius, not a size");
    if (!item["radius"]) r.fail(Reader::join(where, "radius"), "missing key (required for a cylinder)");
    shape.radius = positive(r, item["radius"], Reader::join(where, "radius"), "[m]");
  }
  else
  {
    r.expected(key, "box or cylinder", item["shape"]);
  }
  return shape;
}

/// A list at `key` (absent = empty); each item must be a map.
std::vector<YAML::Node> listOfMaps(const Reader& r, const YAML::Node& root, const std::string& key)
{
  std::vector<YAML::Node> out;
  const YAML::Node node = root[key];
  if (!node || node.IsNull()) return out;
  if (!node.IsSequence()) r.expected(key, "a list", node);
  for (size_t i = 0; i < node.size(); ++i)
  {
    if (!node[i].IsMap()) r.expected(Reader::index(key, i), "a map", node[i]);
    out.push_back(node[i]);
  }
  return out;
}

}  // namespace

std::string checkName(const std::string& name)
{
  // A ROS graph name path without a leading slash: robot_3, fleet/robot_3 (tf2 rejects a
  // leading slash in frame ids).
  auto bad = [&]() {
    return "expected a name of letters, digits and _ (not starting with a digit), got \"" + name + "\"";
  };
  if (name.empty()) return bad();
  bool segment_start = true;
  for (const char c : name)
  {
    const unsigned char u = static_cast<unsigned char>(c);
    if (c == '/')
    {
      if (segment_start) return bad();
      segment_start = true;
      continue;
    }
    if (!(std::isalnum(u) || c == '_') || (segment_start && std::isdigit(u))) return bad();
    segment_start = false;
  }
  if (segment_start) return bad();
  return "";
}

std::string checkFaults(const FaultConfig& f)
{
  auto bad = [](const std::string& field, const std::string& what, double v) {
    return field + ": expected " + what + ", got " + formatNumber(v);
  };
  if (!(f.laser_dropout >= 0.0 && f.laser_dropout <= 1.0))
    return bad("laser_dropout", "a probability in [0, 1]", f.laser_dropout);
  if (!(f.sensor_latency >= 0.0 && f.sensor_latency <= 10.0))
    return bad("sensor_latency", "a delay in [0, 10] s", f.sensor_latency);
  if (!(f.sensor_jitter >= 0.0 && f.sensor_jitter <= 10.0))
    return bad("sensor_jitter", "a standard deviation in [0, 10] s", f.sensor_jitter);
  if (!std::isfinite(f.odom_drift)) return bad("odom_drift", "a finite number [rad/s]", f.odom_drift);
  return "";
}

WorldConfig loadWorldConfig(const std::string& path)
{
  const Reader r(path);
  const YAML::Node root = r.load();
  r.checkKeys(root, "",
              {"map", "physics_step", "real_time_factor", "seed", "robots", "obstacles", "moving_obstacles", "noise",
               "faults", "wall_height"},
              {"map"});

  WorldConfig config;
  config.file = path;
  config.map = r.text(root["map"], "map", "a map_server yaml file name");
  if (config.map.empty()) r.expected("map", "a map_server yaml file name", root["map"]);
  config.map_path = config.map[0] == '/' ? config.map : directoryOf(path) + "/" + config.map;

  if (root["physics_step"])
  {
    config.physics_step = positive(r, root["physics_step"], "physics_step", "[s]");
    if (config.physics_step > 0.1) r.expected("physics_step", "a number in (0, 0.1] [s]", root["physics_step"]);
  }
  if (root["real_time_factor"])
    config.real_time_factor = nonNegative(r, root["real_time_factor"], "real_time_factor", "(0 = as fast as possible)");
  if (root["wall_height"]) config.wall_height = positive(r, root["wall_height"], "wall_height", "[m]");
  if (root["seed"])
  {
    const long long seed = r.integer(root["seed"], "seed", "an integer >= 0");
    if (seed < 0 || seed > 0xffffffffLL) r.expected("seed", "an integer in [0, 4294967295]", root["seed"]);
    config.seed = static_cast<unsigned>(seed);
  }

  // Every body (robot, obstacle, moving obstacle) has a unique name: contacts report names.
  std::set<std::string> names{"map"};
  auto claim = [&](const std::string& name, const std::string& key) {
    if (!names.insert(name).second)
      r.fail(key, "duplicate name \"" + name + "\" (robot and obstacle names must be unique, \"map\" is the walls)");
  };

  const std::vector<YAML::Node> robots = listOfMaps(r, root, "robots");
  for (size_t i = 0; i < robots.size(); ++i)
  {
    const YAML::Node& item = robots[i];
    RobotConfig robot;
    robot.key = Reader::index("robots", i);
    r.checkKeys(item, robot.key, {"name", "model", "pose", "lidar"}, {"name", "pose"});
    robot.name = readName(r, item["name"], Reader::join(robot.key, "name"));
    claim(robot.name, Reader::join(robot.key, "name"));
    if (item["model"]) robot.model = readName(r, item["model"], Reader::join(robot.key, "model"));
    robot.pose = readPose(r, item["pose"], Reader::join(robot.key, "pose"));
    if (item["lidar"]) robot.lidar = readLidar(r, item["lidar"], Reader::join(robot.key, "lidar"));
    config.robots.push_back(robot);
  }

  const std::vector<YAML::Node> obstacles = listOfMaps(r, root, "obstacles");
  for (size_t i = 0; i < obstacles.size(); ++i)
  {
    const YAML::Node& item = obstacles[i];
    ObstacleConfig obstacle;
    obstacle.key = Reader::index("obstacles", i);
    r.checkKeys(item, obstacle.key, {"name", "shape", "size", "radius", "pose", "height"}, {"shape", "pose"});
    obstacle.name =
        item["name"] ? readName(r, item["name"], Reader::join(obstacle.key, "name")) : "obstacle_" + std::to_string(i);
    claim(obstacle.name, Reader::join(obstacle.key, "name"));
    obstacle.shape = readShape(r, item, obstacle.key);
    obstacle.pose = readPose(r, item["pose"], Reader::join(obstacle.key, "pose"));
    if (item["height"]) obstacle.height = positive(r, item["height"], Reader::join(obstacle.key, "height"), "[m]");
    config.obstacles.push_back(obstacle);
  }

  const std::vector<YAML::Node> movers = listOfMaps(r, root, "moving_obstacles");
  for (size_t i = 0; i < movers.size(); ++i)
  {
    const YAML::Node& item = movers[i];
    MovingObstacleConfig mover;
    mover.key = Reader::index("moving_obstacles", i);
    r.checkKeys(
        item, mover.key,
        {"name", "shape", "size", "radius", "waypoints", "speed", "mode", "yielding", "personal_radius", "height"},
        {"shape", "waypoints", "speed"});
    mover.name = item["name"] ? readName(r, item["name"], Reader::join(mover.key, "name"))
                              : "moving_obstacle_" + std::to_string(i);
    claim(mover.name, Reader::join(mover.key, "name"));
    mover.shape = readShape(r, item, mover.key);

    const std::string wp_key = Reader::join(mover.key, "waypoints");
    const YAML::Node wps = item["waypoints"];
    const std::string wp_what = "a list of at least 2 points [[x, y], ...]";
    if (!wps.IsSequence() || wps.size() < 2) r.expected(wp_key, wp_what, wps);
    for (size_t k = 0; k < wps.size(); ++k)
    {
      const std::vector<double> p = r.numbers(wps[k], Reader::index(wp_key, k), 2, "a point [x, y]");
      if (k > 0 && std::hypot(p[0] - mover.waypoints.back().x, p[1] - mover.waypoints.back().y) < 1e-6)
        r.fail(Reader::index(wp_key, k), "the same point as the waypoint before it");
      mover.waypoints.push_back(Point2D{p[0], p[1]});
    }
    mover.speed = positive(r, item["speed"], Reader::join(mover.key, "speed"), "[m/s]");
    if (item["mode"])
    {
      const std::string mode = r.text(item["mode"], Reader::join(mover.key, "mode"), "loop or ping_pong");
      if (mode == "loop")
        mover.mode = MovingObstacleConfig::Mode::LOOP;
      else if (mode == "ping_pong")
        mover.mode = MovingObstacleConfig::Mode::PING_PONG;
      else
        r.expected(Reader::join(mover.key, "mode"), "loop or ping_pong", item["mode"]);
    }
    if (item["yielding"])
    {
      const std::string key = Reader::join(mover.key, "yielding");
      const std::string what = "a number in [0, 1] (0: it does not give way)";
      mover.yielding = r.number(item["yielding"], key, what);
      if (mover.yielding < 0.0 || mover.yielding > 1.0) r.expected(key, what, item["yielding"]);
    }
    if (item["personal_radius"])
      mover.personal_radius = positive(r, item["personal_radius"], Reader::join(mover.key, "personal_radius"), "[m]");
    if (item["height"]) mover.height = positive(r, item["height"], Reader::join(mover.key, "height"), "[m]");
    config.moving_obstacles.push_back(mover);
  }

  if (root["noise"] && !root["noise"].IsNull())
  {
    const YAML::Node noise = root["noise"];
    r.checkKeys(noise, "noise", {"laser_range", "odom_linear", "odom_angular", "imu"});
    if (noise["laser_range"])
      config.noise.laser_range = nonNegative(r, noise["laser_range"], "noise.laser_range", "[m]");
    if (noise["odom_linear"])
      config.noise.odom_linear = nonNegative(r, noise["odom_linear"], "noise.odom_linear", "[m/s]");
    if (noise["odom_angular"])
      config.noise.odom_angular = nonNegative(r, noise["odom_angular"], "noise.odom_angular", "[rad/s]");
    if (noise["imu"] && !noise["imu"].IsNull()) readImuNoise(r, noise["imu"], config.noise.imu);
  }

  const std::vector<YAML::Node> faults = listOfMaps(r, root, "faults");
  std::set<std::string> faulted;
  for (size_t i = 0; i < faults.size(); ++i)
  {
    const YAML::Node& item = faults[i];
    RobotFaultConfig fault;
    fault.key = Reader::index("faults", i);
    r.checkKeys(item, fault.key,
                {"robot", "laser_dropout", "sensor_latency", "sensor_jitter", "odom_drift", "drive_frozen", "silenced"},
                {"robot"});
    const std::string robot_key = Reader::join(fault.key, "robot");
    fault.robot = r.text(item["robot"], robot_key, "a robot name");
    bool known = false;
    for (const auto& robot : config.robots) known = known || robot.name == fault.robot;
    if (!known) r.fail(robot_key, "no robot named \"" + fault.robot + "\" in robots");
    if (!faulted.insert(fault.robot).second)
      r.fail(robot_key, "a second faults entry for \"" + fault.robot + "\" (one entry per robot)");

    FaultConfig& f = fault.faults;
    auto num = [&](const char* key, double& out) {
      if (item[key]) out = r.number(item[key], Reader::join(fault.key, key));
    };
    num("laser_dropout", f.laser_dropout);
    num("sensor_latency", f.sensor_latency);
    num("sensor_jitter", f.sensor_jitter);
    num("odom_drift", f.odom_drift);
    if (item["drive_frozen"]) f.drive_frozen = r.boolean(item["drive_frozen"], Reader::join(fault.key, "drive_frozen"));
    if (item["silenced"]) f.silenced = r.boolean(item["silenced"], Reader::join(fault.key, "silenced"));
    const std::string problem = checkFaults(f);
    if (!problem.empty())
      r.fail(fault.key + "." + problem.substr(0, problem.find(':')), problem.substr(problem.find(':') + 2));
    config.faults.push_back(fault);
  }

  try
  {
    config.map_data = loadMap(config.map_path);
  }
  catch (const MapError& e)
  {
    r.fail("map", e.what());
  }
  return config;
}

}  // namespace mbot_common
