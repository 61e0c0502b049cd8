"""The world file of one fleet run: the chosen world copied next to the run (its map path made
absolute, so that the copy works from there), with more robots when the run asks for more than
the world has.

Robots are added on a lattice (`spacing` apart) around the world's first robot, behind and beside
it first (where a formation forms), then ahead: every one on a free cell (the map, the world's
obstacles and the moving obstacles' paths, kept `wall_margin` away), reachable from the first
robot, and `spacing` away from every other robot. They are called robot_<i> (i = their place in
the fleet, the next free number if that name is taken), with the first robot's model and heading.
A smaller count keeps the first robots of the file.

fleet.launch runs main() while roslaunch reads it (a command parameter), so the file is there
before any node starts:

    rosrun mbot_bringup fleet_world --world trio --robots 10 --out RUN_DIR/world.yaml   # prints the path
    rosrun mbot_bringup fleet_world --names RUN_DIR/world.yaml                            # [robot, ...]

Pure Python (numpy, scipy, mbot_common); no ROS.
"""
import math
import os
import sys

import numpy as np
import yaml
from scipy import ndimage

from mbot_common.geometry import Pose2D, transform_point
from mbot_common.paths import resolve_world
from mbot_common.strict_yaml import ConfigError, load_yaml
from mbot_common.world import Robot, load_world
from mbot_follower.free_space import FreeSpace

MODES = ("formation", "dispatch")   # fleet.launch's modes (checked here: the launch cannot)


class PlacementConfig(object):
    """Where added robots may stand."""

    def __init__(self, spacing=1.0, robot_radius=0.15, wall_margin=0.3, max_distance=12.0):
        self.spacing = spacing            # lattice step, and the least distance between two robots [m]
        self.robot_radius = robot_radius  # [m]
        self.wall_margin = wall_margin    # free space between a robot's edge and a wall or obstacle [m]
        self.max_distance = max_distance  # farthest lattice point from the first robot [m]


def _cell_centres(world_map):
    """(x, y) [m] of every cell centre, two arrays [height, width] (the map has no rotation)."""
    ys, xs = np.mgrid[0:world_map.height, 0:world_map.width]
    return (world_map.origin[0] + (xs + 0.5) * world_map.resolution,
            world_map.origin[1] + (ys + 0.5) * world_map.resolution)


def _near_segment(cx, cy, a, b, radius):
    """True where a cell centre is within radius [m] of the segment a -> b (points (x, y))."""
    ax, ay = a
    dx, dy = b[0] - ax, b[1] - ay
    length2 = dx * dx + dy * dy
    u = np.clip(((cx - ax) * dx + (cy - ay) * dy) / length2, 0.0, 1.0) if length2 > 0 else 0.0
    return (cx - ax - u * dx) ** 2 + (cy - ay - u * dy) ** 2 <= radius * radius


def _reach(shape):
    """How far a body reaches from its centre [m]: a cylinder's radius, a box's half diagonal."""
    return shape.radius if shape.type == "cylinder" else 0.5 * math.hypot(shape.length, shape.width)


def obstacle_occupancy(world):
    """The map's occupancy with the world's obstacles added as occupied cells: a static obstacle
    as the disc its footprint fits in, a moving obstacle along its whole path."""
    occupancy = world.map_data.occupancy.copy()
    cx, cy = _cell_centres(world.map_data)
    for o in world.obstacles:
        p = (o.pose.x, o.pose.y)
        occupancy[_near_segment(cx, cy, p, p, _reach(o.shape))] = 100
    for mo in world.moving_obstacles:
        points = list(mo.waypoints) + ([mo.waypoints[0]] if mo.mode == "loop" else [])
        for a, b in zip(points, points[1:]):
            occupancy[_near_segment(cx, cy, a, b, _reach(mo.shape))] = 100
    return occupancy


def place_robots(world, count, config=None):
    """The robots of a fleet of `count` in `world` (mbot_common.world.World): the world's first
    `count` robots, and as many new ones as are missing (module docstring). ConfigError when
    the world has no robot or there is no room for them all."""
    config = config or PlacementConfig()
    if not world.robots:
        raise ConfigError("%s: robots: the world has no robot to place more next to" % world.file)
    if count <= len(world.robots):
        return list(world.robots[:count])
    m = world.map_data
    origin = (m.origin[0], m.origin[1])
    occupancy = obstacle_occupancy(world)
    stand = FreeSpace(occupancy, m.resolution, origin, config.robot_radius + config.wall_margin)
    # reachable: the free cells (for the robot's radius alone) connected to the first robot
    passable = FreeSpace(occupancy, m.resolution, origin, config.robot_radius)
    first = world.robots[0]
    cell = passable.cell(first.pose.x, first.pose.y)
    if cell is None or not passable.free[cell]:
        raise ConfigError("%s: %s.pose: the first robot is not on a free cell, so no robots can be placed near it"
                          % (world.file, first.key))
    labels, _ = ndimage.label(passable.free, structure=np.ones((3, 3), dtype=bool))
    reachable = labels == labels[cell]

    k = int(config.max_distance / config.spacing)
    candidates = []
    for i in range(-k, k + 1):
        for j in range(-k, k + 1):
            local = (i * config.spacing, j * config.spacing)
            d = math.hypot(*local)
            if d == 0.0 or d > config.max_distance:
                continue
            x, y = transform_point(first.pose, *local)
            rc = stand.cell(x, y)
            if rc is None or not stand.free[rc] or not reachable[rc]:
                continue
            # behind and beside the first robot before ahead of it; nearer before farther
            candidates.append((local[0] > 1e-9, d, x, y))
    candidates.sort()

    robots = list(world.robots)
    names = set(r.name for r in robots)
    for _, _, x, y in candidates:
        if len(robots) == count:
            break
        if any(math.hypot(x - r.pose.x, y - r.pose.y) < config.spacing - 1e-9 for r in robots):
            continue
        number = len(robots)
        while "robot_%d" % number in names:
            number += 1
        name = "robot_%d" % number
        names.add(name)
        robots.append(Robot(name, first.model, Pose2D(round(x, 3), round(y, 3), first.pose.theta),
                            "robots[%d]" % len(robots)))
    if len(robots) < count:
        raise ConfigError("%s: robots: room for only %d robots within %.0f m of %s (%.1f m apart, %.2f m from walls); "
                          "asked for %d" % (world.file, len(robots), config.max_distance, first.name, config.spacing,
                                            config.wall_margin, count))
    return robots


def run_world(world_path, count=None, config=None):
    """(YAML text of the run's world, robot names): the world file `world_path` with its map path
    made absolute and `count` robots (None: the world's)."""
    world = load_world(world_path)
    data = load_yaml(world_path)
    data["map"] = os.path.abspath(world.map_path)
    robots = world.robots if count is None else place_robots(world, count, config)
    entries = {r["name"]: r for r in (data.get("robots") or [])}
    data["robots"] = [entries[r.name] if r.name in entries else
                      {"name": r.name, "model": r.model, "pose": [r.pose.x, r.pose.y, r.pose.theta]} for r in robots]
    kept = set(r.name for r in robots)
    if data.get("faults"):
        data["faults"] = [f for f in data["faults"] if f["robot"] in kept]
    header = "# The world of this run: %s with %d robots (written by mbot_bringup fleet_world).\n" % (
        world_path, len(robots))
    return header + yaml.safe_dump(data, default_flow_style=None, sort_keys=False), [r.name for r in robots]


def write_run_world(world, out, count=None, config=None):
    """Write the run's world for `world` (a name or a path) to `out`; returns its robot names.
    The written file is read back with the strict reader, so a run never starts on a bad one."""
    text, names = run_world(resolve_world(world), count, config)
    directory = os.path.dirname(os.path.abspath(out))
    try:
        os.makedirs(directory, exist_ok=True)
        tmp = out + ".tmp"
        with open(tmp, "w") as f:
            f.write(text)
        os.replace(tmp, out)
    except OSError as error:
        raise ConfigError("%s: cannot write the run's world: %s" % (out, error.strerror or error))
    load_world(out)
    return names


#: The most robots a run may have (the fleet benchmark's largest size is 40).
MAX_ROBOTS = 60


def parse_count(text):
    """--robots: '' (the world's robots) or an integer 1..MAX_ROBOTS."""
    if text == "":
        return None
    try:
        count = int(text)
    except ValueError:
        count = None
    if count is None or not 1 <= count <= MAX_ROBOTS:
        raise ConfigError("robots: expected a number of robots from 1 to %d (or nothing: the world's), "
                          "got \"%s\"" % (MAX_ROBOTS, text))
    return count


def main(argv=None):
    import argparse

    parser = argparse.ArgumentParser(prog="fleet_world", description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", help="world name (maps/NAME.world.yaml) or path")
    parser.add_argument("--robots", default="", help="number of robots (empty: the world's)")
    parser.add_argument("--out", help="the run's world file to write")
    parser.add_argument("--mode", default="formation",
                        help="fleet.launch's mode, checked here: %s" % " or ".join(MODES))
    parser.add_argument("--spacing", type=float, default=PlacementConfig().spacing, help="[m] between added robots")
    parser.add_argument("--names", metavar="WORLD_FILE", help="print the robots of a world file as a YAML list")
    args = parser.parse_args([a for a in (sys.argv[1:] if argv is None else argv) if ":=" not in a])
    try:
        if args.names:
            print(yaml.safe_dump([r.name for r in load_world(args.names).robots], default_flow_style=True).strip())
            return 0
        if not args.world or not args.out:
            parser.error("--world and --out are required (or --names WORLD_FILE)")
        if args.mode not in MODES:
            raise ConfigError("mode: expected %s, got \"%s\"" % (" or ".join(MODES), args.mode))
        write_run_world(args.world, args.out, parse_count(args.robots), PlacementConfig(spacing=args.spacing))
    except ConfigError as error:
        print("fleet_world: %s" % error, file=sys.stderr)
        return 1
    print(os.path.abspath(args.out))
    return 0


if __name__ == "__main__":
    sys.exit(main())
