"""Bring up a formation fleet from a world file: what mbot_navigation's fleet launcher starts
(the map server, every robot's localization and navigation) plus one ``follower_controller``
per robot, in its namespace. formation.launch starts this node (``formation_fleet``) next to the
simulator and the coordinator; roslaunch has no loops, so the per-robot part is generated.

Every robot gets a controller, the leader too: its controller stays passive while it leads, and
takes over if the leader role moves to another robot (a lost leader is replaced; a robot that
comes back rejoins as a follower).

A fleet split across hosts runs this node once per host: ``--robots a,b`` starts only those
robots' stacks, and ``--no-map-server`` leaves the map server to the first host (one
``/map_server`` per master: ROS 1 shuts down the older of two nodes with the same name).
"""
import xml.etree.ElementTree as ET
from xml.sax.saxutils import quoteattr

from mbot_common.paths import find_maps_directory
from mbot_navigation.fleet_launch import LOCALIZATIONS, fleet_launch_xml, read_world, run_launch_text

OMNI_MODELS = ("mbot_omni",)
#: How long a follower polls for a current tf pose under lockstep [s wall]. Sim time waits for
#: its command meanwhile, so a longer wait costs nothing, and a loaded machine delivers /tf late.
LOCKSTEP_POSE_WAIT = 0.5


def controller_lines(world, controller="slot_tracking", output="log", config_file="", leader_max_vel=0.0,
                     lockstep=False, robots=None):
    """Launch XML lines: one follower_controller node per robot of `world` (of `robots`, names,
    when given), and, when leader_max_vel > 0, that speed limit [m/s] for every robot's move_base
    (any robot may lead): followers can only keep up with a leader slower than themselves. Under
    the simulator's `lockstep` the controllers wait LOCKSTEP_POSE_WAIT for a current pose."""
    lines = []
    for robot in world.robots:
        if robots is not None and robot.name not in robots:
            continue
        if leader_max_vel > 0.0:
            lines.append('  <param name=%s value="%g"/>' % (
                quoteattr("/%s/move_base/DWAPlannerROS/max_vel_x" % robot.name), leader_max_vel))
        lines.append('  <node pkg="mbot_follower" type="follower_controller" name="follower_controller" ns=%s '
                     'output=%s>' % (quoteattr(robot.name), quoteattr(output)))
        if config_file:
            lines.append('    <rosparam file=%s command="load"/>' % quoteattr(config_file))
        lines.append('    <param name="controller" value=%s/>' % quoteattr(controller))
        lines.append('    <param name="omni" value="%s"/>' % ("true" if robot.model in OMNI_MODELS else "false"))
        if lockstep:
            lines.append('    <param name="pose_wait" value="%g"/>' % LOCKSTEP_POSE_WAIT)
        lines.append("  </node>")
    return lines


def select_robots(world, text):
    """The names of `text` ("a,b"; empty: None, every robot), each one of `world`'s robots.
    ValueError naming the unknown ones."""
    names = [n.strip() for n in text.split(",") if n.strip()]
    if not names:
        return None
    known = [r.name for r in world.robots]
    unknown = [n for n in names if n not in known]
    if unknown:
        raise ValueError("--robots: %s not in %s (its robots: %s)" % (", ".join(unknown), world.file, ", ".join(known)))
    return names


def without_map_server(text):
    """Launch XML `text` without the map server: its <include> of map_server.launch and any
    <node> of the map_server package. ValueError when there was none (the generator changed)."""
    root = ET.fromstring(text)
    found = [e for e in root if (e.tag == "include" and e.get("file", "").endswith("/map_server.launch"))
             or (e.tag == "node" and e.get("pkg") == "map_server")]
    if not found:
        raise ValueError("no map server in the generated launch: cannot leave it out")
    for element in found:
        root.remove(element)
    return ET.tostring(root, encoding="unicode") + "\n"


def launch_bool(text):
    """A roslaunch boolean (true/false/1/0, any case), read by roslaunch's own converter."""
    import argparse

    from roslaunch.loader import convert_value

    try:
        return convert_value(text.strip(), "bool")
    except ValueError:
        raise argparse.ArgumentTypeError("expected true or false, got %r" % text)


def parse_args(argv):
    import argparse

    parser = argparse.ArgumentParser(prog="formation_fleet", description=__doc__.split("\n\n")[0])
    parser.add_argument("--world", required=True, help="world name (maps/NAME.world.yaml) or path")
    parser.add_argument("--localization", default="fake", choices=LOCALIZATIONS)
    parser.add_argument("--controller", default="slot_tracking")
    parser.add_argument("--controller-config", default="", help="yaml of follower_controller parameters")
    parser.add_argument("--leader-max-vel", type=float, default=0.0, help="move_base speed limit [m/s]; 0: the model's")
    parser.add_argument("--config-dir", default="", help="folder with the nav_*.yaml files")
    parser.add_argument("--output", default="log", choices=("log", "screen"))
    parser.add_argument("--lockstep", default=False, type=launch_bool,
                        help="true: the simulator runs in lockstep (longer tf waits cost no sim time)")
    parser.add_argument("--robots", default="", help="a,b: only these robots' stacks (a fleet across hosts); "
                                                     "empty: every robot of the world")
    parser.add_argument("--nav-host", default=False, type=launch_bool,
                        help="true: one fleet_host process loads this host's nav nodes and fake localizations")
    parser.add_argument("--no-map-server", action="store_true",
                        help="leave out the map server (it runs on the first host)")
    return parser.parse_args([a for a in argv if ":=" not in a])


def main(argv=None):
    """Node ``formation_fleet`` (no rospy, like fleet_navigation: only roslaunch's API)."""
    import sys

    import rospkg

    from mbot_follower.control_laws import CONTROL_LAWS

    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        if args.controller not in CONTROL_LAWS:
            raise ValueError("controller %r: expected one of %s" % (args.controller, ", ".join(sorted(CONTROL_LAWS))))
        maps = find_maps_directory(rospkg.RosPack().get_path("mbot_follower"))
        world = read_world(args.world, maps)
        robots = select_robots(world, args.robots)
        # shutdown_costmaps: only the leader drives with its nav node; the others sleep (no laser,
        # costmaps or tf) until the coordinator sends one of them a goal as the new leader.
        text = fleet_launch_xml(world, args.localization, config_dir=args.config_dir, output=args.output,
                                robots=robots, shutdown_costmaps=True, nav_host=args.nav_host,
                                extra_lines=controller_lines(world, args.controller, args.output,
                                                             args.controller_config, args.leader_max_vel,
                                                             args.lockstep, robots))
        if args.no_map_server:
            text = without_map_server(text)
    except ValueError as error:
        print("formation_fleet: %s" % error, file=sys.stderr)
        return 1
    here = [r.name for r in world.robots] if robots is None else robots
    print("formation_fleet: %d of %d robots of %s: %s (controller %s)%s" % (
        len(here), len(world.robots), world.file, ", ".join(here), args.controller,
        "" if not args.no_map_server else "; no map server here"))
    return run_launch_text(text, "formation_fleet")
