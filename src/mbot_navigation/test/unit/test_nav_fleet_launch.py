"""mbot_navigation.fleet_launch without ROS: world files, the generated launch file."""
import os
import sys
import xml.etree.ElementTree as ET

import pytest

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(PACKAGE_DIR, "src"))  # as the devel space would

from mbot_navigation.fleet_launch import (WorldFileError, find_maps_directory, fleet_launch_xml,  # noqa: E402
                                          read_world, resolve_world_path)

MAPS_DIR = os.path.abspath(os.path.join(PACKAGE_DIR, "..", "..", "maps"))


def write(tmp_path, name, text):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def test_finds_the_workspace_maps_and_resolves_names():
    assert find_maps_directory(PACKAGE_DIR) == MAPS_DIR
    assert resolve_world_path("office", MAPS_DIR) == os.path.join(MAPS_DIR, "office.world.yaml")
    test_world = os.path.join(PACKAGE_DIR, "test", "fixtures", "worlds", "nav_office.world.yaml")
    assert resolve_world_path(test_world, None) == test_world
    with pytest.raises(WorldFileError, match="no such file"):
        resolve_world_path("no_such_world", MAPS_DIR)
    with pytest.raises(WorldFileError, match="no maps directory"):
        resolve_world_path("office", None)


def test_reads_the_office_world():
    world = read_world(os.path.join(MAPS_DIR, "office.world.yaml"))
    assert world.map_path == os.path.join(MAPS_DIR, "office.yaml")
    assert [r.name for r in world.robots] == ["robot_0", "robot_1", "robot_2"]
    assert world.robots[1].model == "mbot"
    assert (world.robots[1].x, world.robots[1].y, world.robots[1].yaw) == (2.0, -3.0, 0.0)


def test_world_errors_name_file_and_key(tmp_path):
    with pytest.raises(WorldFileError, match=r"bad\.world\.yaml: map: expected"):
        read_world(write(tmp_path, "bad.world.yaml", "robots: []\n"))
    with pytest.raises(WorldFileError, match=r"robots\[0\]\.pose: expected a list of 3 numbers"):
        read_world(write(tmp_path, "p.world.yaml", "map: m.yaml\nrobots:\n  - name: a\n    pose: [1, 2]\n"))
    with pytest.raises(WorldFileError, match=r"robots\[1\]\.name"):
        read_world(write(tmp_path, "n.world.yaml",
                         "map: m.yaml\nrobots:\n  - {name: a, pose: [0, 0, 0]}\n  - {pose: [1, 1, 0]}\n"))
    with pytest.raises(WorldFileError, match=r"robots\[0\]\.pose: expected a number"):
        read_world(write(tmp_path, "t.world.yaml", "map: m.yaml\nrobots:\n  - {name: a, pose: [0, x, 0]}\n"))


def test_launch_file_has_the_map_server_and_one_navigation_per_robot(tmp_path):
    world = read_world(write(tmp_path, "two.world.yaml", "map: maps/two.yaml\nrobots:\n"
                             "  - {name: leader, model: mbot_omni, pose: [1.5, -2, 0.5]}\n"
                             "  - {name: follower_1, pose: [0, 0, 3.14159]}\n"))
    root = ET.fromstring(fleet_launch_xml(world, localization="pf", base_global_planner="ompl",
                                          config_dir="/cfg dir"))
    includes = root.findall("include")
    assert [i.get("file").split("/")[-1] for i in includes] == [
        "map_server.launch", "navigation.launch", "navigation.launch"]
    assert includes[0].find("arg").get("value") == str(tmp_path / "maps" / "two.yaml")
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
