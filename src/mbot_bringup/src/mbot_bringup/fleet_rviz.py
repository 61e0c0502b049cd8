"""The rviz view of one fleet: the template rviz/fleet.rviz (map, the simulator's robots and
obstacles on /stage/markers, the formation's slots and links on /fleet/markers, tf) plus, for
every robot of the world, its laser scan and its global plan in the robot's colour, with the
view centred on the map and scaled so that the whole map fits the window; or, with `--follow
FRAME`, a view that follows that frame (the coordinator's `fleet` frame, the middle of the
fleet) and shows `--view-width` metres across (default: room for a column of the world's robots
at `--spacing`), so that robots, scans, slots and links are big enough to read.

rviz needs one display per topic, so a view that shows any fleet's scans is written per run;
fleet.launch writes it while roslaunch reads the launch file (a command parameter), before rviz starts:

    rosrun mbot_bringup fleet_rviz --world RUN_DIR/world.yaml --out RUN_DIR/fleet.rviz   # prints the path

Replay a recorded run in it: `rosbag play RUN_DIR/run.bag --clock` and `rviz -d RUN_DIR/fleet.rviz`.
Pure Python (yaml, mbot_common); no ROS.
"""
import argparse
import copy
import os
import sys

import yaml

from mbot_bringup.colors import robot_colors
from mbot_common.paths import resolve_world
from mbot_common.strict_yaml import ConfigError
from mbot_common.world import load_world

TEMPLATE = os.path.join(os.path.dirname(__file__), "..", "..", "rviz", "fleet.rviz")
VIEW_PX = (1160, 800)   # the template window's render area, about [px] (width, height)
MARGIN = 0.92           # share of the render area the map may fill
MIN_FOLLOW_WIDTH = 10.0  # a view that follows the fleet shows at least this much [m across]


def _rgb(color):
    """rviz's colour text "R; G; B" (0-255) of an (r, g, b) in [0, 1]."""
    return "; ".join(str(int(round(255 * c))) for c in color)


def robot_displays(robot, color):
    """The rviz group of one robot: its model (URDF from NAME/robot_description, frames already
    prefixed), its laser scan (points) and its global plan (a line)."""
    return {
        "Class": "rviz/Group",
        "Name": robot,
        "Enabled": True,
        "Value": True,
        "Displays": [
            {"Class": "rviz/RobotModel", "Name": "Model", "Enabled": True, "Value": True,
             "Robot Description": "%s/robot_description" % robot, "TF Prefix": "", "Alpha": 1,
             "Collision Enabled": False, "Visual Enabled": True, "Update Interval": 0},
            {"Class": "rviz/LaserScan", "Name": "Scan", "Enabled": True, "Value": True,
             "Topic": "/%s/scan" % robot, "Color Transformer": "FlatColor", "Color": _rgb(color),
             "Style": "Flat Squares", "Size (m)": 0.05, "Size (Pixels)": 3, "Alpha": 1,
             "Decay Time": 0, "Position Transformer": "XYZ", "Queue Size": 10, "Selectable": True,
             "Use Fixed Frame": True, "Use rainbow": False, "Unreliable": False},
            {"Class": "rviz/Path", "Name": "Global plan", "Enabled": True, "Value": True,
             "Topic": "/%s/move_base/global_plan" % robot, "Color": _rgb(color), "Alpha": 1,
             "Line Style": "Billboards", "Line Width": 0.04, "Buffer Length": 1,
             "Head Diameter": 0.3, "Head Length": 0.2, "Length": 0.3, "Pose Style": "None",
             "Radius": 0.03, "Shaft Diameter": 0.1, "Shaft Length": 0.1, "Queue Size": 10,
             "Offset": {"X": 0, "Y": 0, "Z": 0}, "Unreliable": False},
        ],
    }


def follow_width(robots, spacing):
    """Metres across a view that follows the fleet: a column of `robots` at `spacing` [m] and
    2 m on each side, at least MIN_FOLLOW_WIDTH."""
    return max(MIN_FOLLOW_WIDTH, (robots - 1) * spacing + 4.0)


def fleet_view(template, robots, map_box, follow="", width=0.0):
    """The template config with one group per robot (robots: [(name, (r, g, b))], in the order
    of the world file) and the view on map_box (x0, x1, y0, y1) [m]; with `follow` a frame, the
    view follows it and shows `width` m across (no more than the map)."""
    config = copy.deepcopy(template)
    manager = config["Visualization Manager"]
    manager["Displays"].extend(robot_displays(name, color) for name, color in robots)
    x0, x1, y0, y1 = map_box
    view = manager["Views"]["Current"]
    if follow:
        if not (width > 0.0):
            raise ValueError("view width %r: expected a number > 0 [m]" % width)
        width = min(width, x1 - x0, (y1 - y0) * VIEW_PX[0] / VIEW_PX[1])
        view["Target Frame"] = follow
        view["X"] = view["Y"] = 0.0
        view["Scale"] = round(VIEW_PX[0] / width, 2)
        return config
    view["X"] = round(0.5 * (x0 + x1), 3)
    view["Y"] = round(0.5 * (y0 + y1), 3)
    view["Scale"] = round(MARGIN * min(VIEW_PX[0] / (x1 - x0), VIEW_PX[1] / (y1 - y0)), 2)
    return config


def map_box(map_data):
    """(x0, x1, y0, y1) [m] of the map (no rotation: stage_node's maps have none)."""
    ox, oy, _ = map_data.origin
    return (ox, ox + map_data.width * map_data.resolution, oy, oy + map_data.height * map_data.resolution)


def write_fleet_view(world_path, out_path, template_path=TEMPLATE, follow="", spacing=1.0, width=0.0):
    """Write the fleet view of the world world_path (a file, or a name in maps/) to out_path;
    returns out_path. follow: a frame to follow, width [m] across (0: follow_width of the world's
    robots at spacing [m])."""
    world = load_world(resolve_world(world_path))
    names = [r.name for r in world.robots]
    colors = robot_colors(names, names)
    with open(template_path) as f:
        template = yaml.safe_load(f)
    width = width or follow_width(len(names), spacing)
    config = fleet_view(template, [(n, colors[n]) for n in names], map_box(world.map_data), follow, width)
    out_dir = os.path.dirname(os.path.abspath(out_path))
    if not os.path.isdir(out_dir):
        os.makedirs(out_dir)
    with open(out_path, "w") as f:
        f.write("# Written by mbot_bringup fleet_rviz for %s\n" % world_path)
        yaml.safe_dump(config, f, default_flow_style=False, sort_keys=False)
    return out_path


def main(argv=None):
    parser = argparse.ArgumentParser(description="Write the rviz view of a world's fleet.")
    parser.add_argument("--world", required=True, help="the world: a file, or a name in maps/")
    parser.add_argument("--out", required=True, help="the rviz config to write")
    parser.add_argument("--template", default=TEMPLATE, help="the rviz config to start from")
    parser.add_argument("--follow", default="", help="a tf frame the view follows (e.g. fleet); default: the whole map")
    parser.add_argument("--spacing", type=float, default=1.0, help="the formation's spacing [m] (sizes a follow view)")
    parser.add_argument("--view-width", type=float, default=0.0,
                        help="metres across a follow view (0: a column of the world's robots fits)")
    args = parser.parse_args(argv)
    try:
        print(write_fleet_view(args.world, args.out, args.template, args.follow, args.spacing, args.view_width))
    except (ConfigError, IOError, OSError, ValueError) as error:
        sys.stderr.write("fleet_rviz: %s\n" % error)
        return 1
    return 0
