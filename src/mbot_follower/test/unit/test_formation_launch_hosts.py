"""formation_fleet for a fleet across hosts: --robots starts only those robots' stacks, an
unknown name is an error naming it, and --no-map-server leaves the map server to the first host."""
import os
import xml.etree.ElementTree as ET

import pytest

from mbot_follower.formation_launch import controller_lines, select_robots, without_map_server
from mbot_navigation.fleet_launch import fleet_launch_xml, read_world

MAPS_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "maps"))


def launched(text):
    """(robots with a navigation include, robots with a controller, map server included)"""
    root = ET.fromstring(text)
    nav = [a.get("value") for i in root.findall("include") if i.get("file").endswith("/navigation.launch")
           for a in i.findall("arg") if a.get("name") == "robot"]
    controllers = [n.get("ns") for n in root.findall("node") if n.get("type") == "follower_controller"]
    map_server = any(i.get("file").endswith("/map_server.launch") for i in root.findall("include"))
    return nav, controllers, map_server


def part(world, names, map_server=True):
    robots = select_robots(world, names)
    text = fleet_launch_xml(world, robots=robots, extra_lines=controller_lines(world, leader_max_vel=0.35,
                                                                               robots=robots))
    return text if map_server else without_map_server(text)


def test_a_subset_starts_only_its_robots():
    world = read_world("trio", MAPS_DIR)
    assert launched(part(world, "")) == (["leader", "follower_1", "follower_2"],
                                         ["leader", "follower_1", "follower_2"], True)
    assert launched(part(world, "follower_2, leader")) == (["leader", "follower_2"], ["leader", "follower_2"], True)
    speed = [p.get("name") for p in ET.fromstring(part(world, "follower_1")).findall("param")]
    assert speed == ["/follower_1/move_base/DWAPlannerROS/max_vel_x"]


def test_the_other_hosts_run_no_map_server():
    world = read_world("trio", MAPS_DIR)
    assert launched(part(world, "follower_1", map_server=False)) == (["follower_1"], ["follower_1"], False)


def test_an_unknown_robot_is_named():
    world = read_world("trio", MAPS_DIR)
    with pytest.raises(ValueError) as error:
        select_robots(world, "leader,follower_9")
    assert "follower_9 not in" in str(error.value) and "leader, follower_1, follower_2" in str(error.value)


def test_no_map_server_to_leave_out_is_an_error():
    with pytest.raises(ValueError) as error:
        without_map_server("<launch><node pkg='a' type='b' name='c'/></launch>")
    assert "no map server" in str(error.value)


@pytest.mark.parametrize("args, message", [
    (["part:=robot", "host_robots:=leader"], "ERROR_part_must_be_all_or_robots"),
    (["part:=robots"], "ERROR_part_robots_needs_host_robots"),
])
def test_formation_launch_refuses_a_bad_part(args, message):
    import subprocess

    result = subprocess.run(["roslaunch", "--nodes", "mbot_follower", "formation.launch"] + args,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
    assert message in result.stdout


def test_formation_launch_part_robots_starts_only_the_stacks():
    """The first host's launch has the simulator and the fleet's nodes; part:=robots only a
    formation_fleet of its own name, told to leave out the map server."""
    import subprocess

    def nodes(*args):
        out = subprocess.check_output(["roslaunch", "--nodes", "mbot_follower", "formation.launch"] + list(args),
                                      universal_newlines=True)
        return out.split()

    assert nodes("host_robots:=leader") == ["/stage_node", "/robot_state_publishers", "/formation_fleet",
                                            "/fleet_tf_relay", "/coordinator", "/metrics_collector"]
    import roslaunch.config
    import rospkg

    path = os.path.join(rospkg.RosPack().get_path("mbot_follower"), "launch", "formation.launch")
    config = roslaunch.config.load_config_default([(path, ["part:=robots", "host_robots:=follower_1"])], None,
                                                  verbose=False)
    assert [n.name for n in config.nodes if not n.name.startswith("formation_fleet_")] == []
    assert len(config.nodes) == 1 and "--robots 'follower_1' --no-map-server" in " ".join(config.nodes[0].args.split())


def test_across_hosts_the_coordinator_waits_longer_for_the_robots():
    """The other hosts start their robots once the first host's master is up: later than its own."""
    import subprocess

    import yaml

    def startup_timeout(*args):
        out = subprocess.check_output(["roslaunch", "--dump-params", "mbot_follower", "formation.launch"] + list(args),
                                      universal_newlines=True)
        return yaml.safe_load(out).get("/coordinator/startup_timeout")

    assert startup_timeout() is None                    # the coordinator's own default
    assert startup_timeout("host_robots:=leader") == 150.0
