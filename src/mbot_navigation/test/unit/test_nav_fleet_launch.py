"""mbot_navigation.fleet_launch without ROS: world files (read by mbot_common), the generated launch file."""
import os
import sys
import xml.etree.ElementTree as ET

import pytest

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(PACKAGE_DIR, "src"))  # as the devel space would

from mbot_common.paths import find_maps_directory  # noqa: E402
from mbot_common.strict_yaml import ConfigError  # noqa: E402
from mbot_navigation.fleet_launch import fleet_launch_xml, read_world  # noqa: E402

MAPS_DIR = os.path.abspath(os.path.join(PACKAGE_DIR, "..", "..", "maps"))
OFFICE_MAP = os.path.join(MAPS_DIR, "office.yaml")


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_finds_the_workspace_maps_and_resolves_names(tmp_path):
    assert find_maps_directory(PACKAGE_DIR) == MAPS_DIR
    assert read_world("office", MAPS_DIR).file == os.path.join(MAPS_DIR, "office.world.yaml")
    path = write(tmp_path, "one.world.yaml", "map: %s\nrobots:\n  - {name: a, pose: [0, 0, 0]}\n" % OFFICE_MAP)
    assert read_world(path).file == path
    with pytest.raises(ConfigError, match='world "no_such_world": no world file of that name'):
        read_world("no_such_world", MAPS_DIR)


def test_reads_the_office_world():
    world = read_world(os.path.join(MAPS_DIR, "office.world.yaml"))
    assert os.path.normpath(world.map_path) == OFFICE_MAP
    assert [r.name for r in world.robots] == ["robot_0", "robot_1", "robot_2"]
    assert world.robots[1].model == "mbot"
    assert tuple(world.robots[1].pose) == (2.0, -3.0, 0.0)


def test_world_errors_name_file_and_key(tmp_path):
    # The same strict reader as stage_node: a launch never starts a fleet the simulator refuses.
    with pytest.raises(ConfigError, match=r"bad\.world\.yaml.*map"):
        read_world(write(tmp_path, "bad.world.yaml", "robots: []\n"))
    with pytest.raises(ConfigError, match=r"p\.world\.yaml: robots\[0\]\.pose"):
        read_world(write(tmp_path, "p.world.yaml", "map: %s\nrobots:\n  - name: a\n    pose: [1, 2]\n" % OFFICE_MAP))
    with pytest.raises(ConfigError, match=r"n\.world\.yaml: robots\[1\]\.name"):
        read_world(write(tmp_path, "n.world.yaml",
                         "map: %s\nrobots:\n  - {name: a, pose: [0, 0, 0]}\n  - {pose: [1, 1, 0]}\n" % OFFICE_MAP))
    with pytest.raises(ConfigError, match=r"m\.world\.yaml: map"):
        read_world(write(tmp_path, "m.world.yaml", "map: no_such_map.yaml\nrobots: []\n"))
    with pytest.raises(ConfigError, match=r"k\.world\.yaml: robots\[0\]\.colour: unknown key"):
        read_world(write(tmp_path, "k.world.yaml",
                         "map: %s\nrobots:\n  - {name: a, pose: [0, 0, 0], colour: red}\n" % OFFICE_MAP))


def test_launch_file_has_the_map_server_and_one_navigation_per_robot(tmp_path):
    world = read_world(write(tmp_path, "two.world.yaml", "map: %s\nrobots:\n" % OFFICE_MAP
                             + "  - {name: leader, model: mbot_omni, pose: [1.5, -2, 0.5]}\n"
                             "  - {name: follower_1, pose: [0, 0, 3.14159]}\n"))
    root = ET.fromstring(fleet_launch_xml(world, localization="pf", base_global_planner="ompl",
                                          config_dir="/cfg dir"))
    includes = root.findall("include")
    assert [i.get("file").split("/")[-1] for i in includes] == [
        "map_server.launch", "navigation.launch", "navigation.launch"]
    assert includes[0].find("arg").get("value") == OFFICE_MAP
    args = [{a.get("name"): a.get("value") for a in i.findall("arg")} for i in includes[1:]]
    assert args[0]["robot"] == "leader" and args[0]["model"] == "mbot_omni"
    assert (args[0]["initial_pose_x"], args[0]["initial_pose_y"], args[0]["initial_pose_a"]) == ("1.5", "-2", "0.5")
    assert args[1]["robot"] == "follower_1" and args[1]["model"] == "mbot"
    assert {a["localization"] for a in args} == {"pf"}
    assert {a["base_global_planner"] for a in args} == {"ompl"}
    assert {a["config_dir"] for a in args} == {"/cfg dir"}
    assert args[0]["seed"] != args[1]["seed"]  # each particle filter its own random stream
    only = ET.fromstring(fleet_launch_xml(world, robots=["follower_1"]))
    assert len(only.findall("include")) == 2
    with pytest.raises(ValueError, match="localization"):
        fleet_launch_xml(world, localization="amcl")


def test_nav_manager_and_shutdown_costmaps_options(tmp_path):
    world = read_world(write(tmp_path, "three.world.yaml", "map: %s\nrobots:\n" % OFFICE_MAP
                             + "".join("  - {name: r%d, pose: [%d, 0, 0]}\n" % (i, i) for i in range(3))))

    def parse(**options):
        root = ET.fromstring(fleet_launch_xml(world, **options))
        navs = [{a.get("name"): a.get("value") for a in i.findall("arg")} for i in root.findall("include")
                if i.get("file").endswith("/navigation.launch")]
        return root.findall("node"), navs

    # Defaults: a process per robot, awake while idle (move_base's defaults).
    nodes, navs = parse()
    assert nodes == []
    assert all("manager" not in a and "shutdown_costmaps" not in a and "required" not in a for a in navs)

    nodes, navs = parse(nav_manager=True, shutdown_costmaps=True)
    assert [(n.get("pkg"), n.get("type"), n.get("name"), n.get("args"), n.get("required")) for n in nodes] == [
        ("nodelet", "nodelet", "nav_manager", "manager", "true")]
    assert {p.get("name"): p.get("value") for p in nodes[0].findall("param")} == {"num_worker_threads": "3"}
    # A killed loader unloads its robot only: the loaders are not required, the manager is.
    assert [(a["robot"], a["manager"], a["required"], a["shutdown_costmaps"]) for a in navs] == [
        (r, "nav_manager", "false", "true") for r in ("r0", "r1", "r2")]

    # One host's share of a fleet: its own manager, named after its first robot.
    nodes, navs = parse(nav_manager=True, robots=["r2", "r1"])
    assert [n.get("name") for n in nodes] == ["nav_manager_r2"]
    assert {p.get("name"): p.get("value") for p in nodes[0].findall("param")} == {"num_worker_threads": "2"}
    assert [(a["robot"], a["manager"], a["seed"]) for a in navs] == [("r1", "nav_manager_r2", "2"),
                                                                     ("r2", "nav_manager_r2", "3")]

    with pytest.raises(ValueError, match="shutdown_costmaps: expected True or False, got 'yes'"):
        fleet_launch_xml(world, shutdown_costmaps="yes")
    with pytest.raises(ValueError, match="nav_manager: expected True or False, got 1"):
        fleet_launch_xml(world, nav_manager=1)


def test_nav_host_loads_every_nav_node_and_fake_localization_in_one_process(tmp_path):
    import yaml

    world = read_world(write(tmp_path, "three.world.yaml", "map: %s\nrobots:\n" % OFFICE_MAP
                             + "".join("  - {name: r%d, pose: [%d, 0, 0]}\n" % (i, i) for i in range(3))))
    root = ET.fromstring(fleet_launch_xml(world, nav_host=True, robots=["r2", "r0"]))
    nodes = root.findall("node")
    assert [(n.get("pkg"), n.get("type"), n.get("name"), n.get("required")) for n in nodes] == [
        ("mbot_navigation", "fleet_host", "nav_host_r2", "true")]
    nodelets = yaml.safe_load(nodes[0].find("rosparam").text)
    assert nodelets == [{"name": "/r0/move_base", "type": "mbot_navigation/NavNodelet"},
                        {"name": "/r0/fake_localization", "type": "mbot_localization/FakeLocalization"},
                        {"name": "/r2/move_base", "type": "mbot_navigation/NavNodelet"},
                        {"name": "/r2/fake_localization", "type": "mbot_localization/FakeLocalization"}]
    navs = [{a.get("name"): a.get("value") for a in i.findall("arg")} for i in root.findall("include")
            if i.get("file").endswith("/navigation.launch")]
    assert [(a["robot"], a["host"]) for a in navs] == [("r0", "nav_host_r2"), ("r2", "nav_host_r2")]
    # a particle filter is no nodelet: it stays a process of its own (navigation.launch starts it)
    root = ET.fromstring(fleet_launch_xml(world, nav_host=True, localization="pf"))
    assert "fake_localization" not in root.find("node").find("rosparam").text
    with pytest.raises(ValueError, match="nav_manager and nav_host: choose one"):
        fleet_launch_xml(world, nav_host=True, nav_manager=True)
    with pytest.raises(ValueError, match="nav_host: expected True or False"):
        fleet_launch_xml(world, nav_host="true")
