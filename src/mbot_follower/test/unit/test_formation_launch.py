"""formation_fleet's generated launch lines without ROS: one controller per robot, its settings;
and formation.launch's parameters for the coordinator (roslaunch --dump-params, no node runs)."""
import os
import xml.etree.ElementTree as ET

import pytest

from mbot_follower.formation_launch import LOCKSTEP_POSE_WAIT, controller_lines, parse_args
from mbot_navigation.fleet_launch import read_world

MAPS_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", "..", "maps"))


def nodes(lines):
    return ET.fromstring("<launch>%s</launch>" % "".join(lines)).findall("node")


def params(node):
    return {p.get("name"): p.get("value") for p in node.findall("param")}


def test_one_controller_per_robot_in_its_namespace():
    world = read_world("trio", MAPS_DIR)
    found = nodes(controller_lines(world, "consensus"))
    assert [n.get("ns") for n in found] == ["leader", "follower_1", "follower_2"]
    assert all(params(n)["controller"] == "consensus" and "pose_wait" not in params(n) for n in found)


def test_lockstep_lets_the_controllers_wait_longer_for_tf():
    world = read_world("trio", MAPS_DIR)
    found = nodes(controller_lines(world, lockstep=True))
    assert all(float(params(n)["pose_wait"]) == LOCKSTEP_POSE_WAIT for n in found)


@pytest.mark.parametrize("text, value", [("true", True), ("True", True), ("1", True), ("false", False), ("0", False)])
def test_lockstep_reads_roslaunch_booleans(text, value):
    assert parse_args(["--world", "trio", "--lockstep", text]).lockstep is value


def test_lockstep_refuses_anything_else(capsys):
    with pytest.raises(SystemExit):
        parse_args(["--world", "trio", "--lockstep", "maybe"])
    assert "expected true or false, got 'maybe'" in capsys.readouterr().err


def test_formation_launch_hands_leader_and_lockstep_to_the_coordinator():
    """`roslaunch mbot_follower formation.launch leader:=NAME lockstep:=true`, its parameters
    only (roslaunch --dump-params starts no node)."""
    import subprocess

    import yaml

    def coordinator_params(*args):
        out = subprocess.check_output(["roslaunch", "--dump-params", "mbot_follower", "formation.launch"] + list(args),
                                      universal_newlines=True)
        return {k.split("/")[-1]: v for k, v in yaml.safe_load(out).items() if k.startswith("/coordinator/")}

    default = coordinator_params()
    assert (default["leader"], default["lockstep"]) == ("", False)   # the world's first robot leads
    chosen = coordinator_params("leader:=follower_2", "lockstep:=true")
    assert (chosen["leader"], chosen["lockstep"]) == ("follower_2", True)
