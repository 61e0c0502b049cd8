"""Bring up a whole fleet's navigation from a world file: the map server with the world's map and,
for every robot of the world, its localization and its nav node (navigation.launch).

roslaunch has no loops, so fleet_navigation.launch starts the node ``fleet_navigation`` (main()
below), which

1. finds the world file (a name means ``maps/NAME.world.yaml`` in the workspace, as stage_node
   looks it up; anything with a ``/`` or ending in ``.yaml`` is a path),
2. reads its ``map`` and ``robots`` (name, model, pose),
3. writes a launch file with one ``<include>`` of map_server.launch and one of navigation.launch
   per robot (fleet_launch_xml()), and
4. runs it with roslaunch's Python API until it is shut down (its processes stop with it).

Everything except main() works without ROS, so that it can be tested on its own.
"""
import os
import tempfile
from collections import namedtuple
from xml.sax.saxutils import quoteattr

import yaml

#: One robot of a world file: name, model and start pose [m, m, rad] in the map.
Robot = namedtuple("Robot", "name model x y yaw")
#: What the fleet launch needs from a world file: the map yaml's absolute path and the robots.
World = namedtuple("World", "path map_path robots")

LOCALIZATIONS = ("fake", "pf")


class WorldFileError(ValueError):
    """A world file that cannot be used; the message names the file and the key."""


def find_maps_directory(start_dir):
    """The first ``maps`` directory next to ``start_dir`` or one of its ancestors, or None
    (for ``src/mbot_navigation`` that is the workspace's ``maps``)."""
    d = os.path.abspath(start_dir)
    while True:
        candidate = os.path.join(d, "maps")
        if os.path.isdir(candidate):
            return candidate
        parent = os.path.dirname(d)
        if parent == d:
            return None
        d = parent


def resolve_world_path(world, maps_dir):
    """The world file that ``world`` means: a path (contains ``/`` or ends in ``.yaml``) as given,
    else ``<maps_dir>/<world>.world.yaml``. Raises WorldFileError when there is no such file."""
    if "/" in world or world.endswith(".yaml"):
        path = os.path.abspath(world)
    else:
        if not maps_dir:
            raise WorldFileError("world %r: no maps directory to look it up in" % world)
        path = os.path.join(maps_dir, world + ".world.yaml")
    if not os.path.isfile(path):
        raise WorldFileError("world %r: no such file %s" % (world, path))
    return path


def _number(value, where):
    if isinstance(value, bool) or not isinstance(value, (int, float)):
        raise WorldFileError("%s: expected a number, got %r" % (where, value))
    return float(value)


def read_world(path):
    """Read the map and the robots of a world file (src/mbot_sim/WORLD_FORMAT.md).

    Only the keys this launcher needs are read; stage_node checks the whole file. Raises
    WorldFileError naming the file and the key for a missing or mistyped one.
    """
    name = os.path.basename(path)
    try:
        with open(path) as f:
            data = yaml.safe_load(f)
    except (OSError, yaml.YAMLError) as error:
        raise WorldFileError("%s: cannot read: %s" % (path, error))
    if not isinstance(data, dict):
        raise WorldFileError("%s: expected a dictionary at the top level" % name)
    map_file = data.get("map")
    if not isinstance(map_file, str) or not map_file:
        raise WorldFileError("%s: map: expected the path of a map yaml, got %r" % (name, map_file))
    map_path = os.path.normpath(os.path.join(os.path.dirname(os.path.abspath(path)), map_file))
    entries = data.get("robots", [])
    if not isinstance(entries, list):
        raise WorldFileError("%s: robots: expected a list, got %r" % (name, entries))
    robots = []
    for i, entry in enumerate(entries):
        where = "%s: robots[%d]" % (name, i)
        if not isinstance(entry, dict) or not isinstance(entry.get("name"), str):
            raise WorldFileError("%s.name: expected a robot name" % where)
        model = entry.get("model", "mbot")
        if not isinstance(model, str):
            raise WorldFileError("%s.model: expected a model name, got %r" % (where, model))
        pose = entry.get("pose")
        if not isinstance(pose, list) or len(pose) != 3:
            raise WorldFileError("%s.pose: expected a list of 3 numbers [x, y, yaw], got %r" % (where, pose))
        x, y, yaw = (_number(v, "%s.pose" % where) for v in pose)
        robots.append(Robot(entry["name"], model, x, y, yaw))
    return World(os.path.abspath(path), map_path, robots)


def fleet_launch_xml(world, localization="fake", base_global_planner="astar", config_dir="", output="log",
                     robots=None, extra_lines=()):
    """The text of a launch file that starts the map server (the world's map) and, per robot,
    navigation.launch (localization + nav node).

    :param world: a World (read_world())
    :param robots: names of the robots to include (default: all of the world's)
    :param extra_lines: more launch XML lines to put inside <launch> (other packages' nodes)
    """
    if localization not in LOCALIZATIONS:
        raise ValueError("localization: expected one of %s, got %r" % (", ".join(LOCALIZATIONS), localization))
    lines = ["<launch>",
             "  <!-- generated by mbot_navigation.fleet_launch from %s -->" % world.path.replace("--", "- -"),
             '  <include file="$(find mbot_navigation)/launch/map_server.launch">',
             "    <arg name=\"map\" value=%s/>" % quoteattr(world.map_path),
             "  </include>"]
    for seed, robot in enumerate(world.robots, start=1):
        if robots is not None and robot.name not in robots:
            continue
        args = [("robot", robot.name), ("model", robot.model), ("localization", localization),
                ("initial_pose_x", "%.6g" % robot.x), ("initial_pose_y", "%.6g" % robot.y),
                ("initial_pose_a", "%.6g" % robot.yaw), ("seed", str(seed)),
                ("base_global_planner", base_global_planner), ("output", output)]
        if config_dir:
            args.append(("config_dir", config_dir))
        lines.append('  <include file="$(find mbot_navigation)/launch/navigation.launch">')
        lines += ["    <arg name=%s value=%s/>" % (quoteattr(k), quoteattr(v)) for k, v in args]
        lines.append("  </include>")
    lines += list(extra_lines)
    lines.append("</launch>")
    return "\n".join(lines) + "\n"


def parse_args(argv):
    """The node's command line (fleet_navigation.launch passes its args on)."""
    import argparse

    parser = argparse.ArgumentParser(prog="fleet_navigation", description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", required=True, help="world name (maps/NAME.world.yaml) or path")
    parser.add_argument("--localization", default="fake", choices=LOCALIZATIONS)
    parser.add_argument("--base-global-planner", default="astar")
    parser.add_argument("--config-dir", default="", help="folder with the nav_*.yaml files")
    parser.add_argument("--output", default="log", choices=("log", "screen"))
    # roslaunch adds remappings such as __name:=fleet_navigation
    return parser.parse_args([a for a in argv if ":=" not in a])


def main(argv=None):
    """Node ``fleet_navigation``. It uses no rospy (a rospy node would process every /clock
    message, thousands per second at a high real-time factor): only roslaunch's API."""
    import sys

    import rospkg

    args = parse_args(sys.argv[1:] if argv is None else argv)
    package_dir = rospkg.RosPack().get_path("mbot_navigation")
    try:
        world = read_world(resolve_world_path(args.world, find_maps_directory(package_dir)))
        text = fleet_launch_xml(world, args.localization, args.base_global_planner, args.config_dir, args.output)
    except ValueError as error:
        print("fleet_navigation: %s" % error, file=sys.stderr)
        return 1

    print("fleet_navigation: %d robots of %s (%s localization): %s" % (
        len(world.robots), world.path, args.localization, ", ".join(r.name for r in world.robots)))
    return run_launch_text(text, "fleet_navigation")


def run_launch_text(text, name):
    """Run the launch file `text` with roslaunch's API inside this process until this process is
    told to stop (SIGINT/SIGTERM: 0) or a required node of it exits (1). Its processes stop with
    it. `name` prefixes the temporary file and the messages."""
    import signal
    import sys
    import time

    import roslaunch

    handle, path = tempfile.mkstemp(prefix=name + "_", suffix=".launch")
    with os.fdopen(handle, "w") as f:
        f.write(text)
    stop_requested = []

    def on_signal(signum, _frame):
        stop_requested.append(signum)

    # roslaunch's process monitor installs its own handlers (they stop the fleet) and then calls these.
    signal.signal(signal.SIGINT, on_signal)
    signal.signal(signal.SIGTERM, on_signal)
    run_id = roslaunch.rlutil.get_or_generate_uuid(None, False)  # the outer roslaunch's /run_id
    parent = roslaunch.parent.ROSLaunchParent(run_id, [path], is_core=False)
    status = 0
    try:
        parent.start()
        while not parent.pm.is_shutdown and not stop_requested:
            time.sleep(0.2)  # wall time
        if not stop_requested:
            print("%s: a required node exited; stopping" % name, file=sys.stderr)
            status = 1
    finally:
        parent.shutdown()
        os.remove(path)
    return status
