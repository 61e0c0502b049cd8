"""Tests of mbot_description.urdf_prefix and scripts/prefix_urdf."""
import os
import subprocess
import xml.etree.ElementTree as ET

import pytest

from paths import MODELS, PACKAGE_DIR, URDF_DIR
from mbot_description.urdf_prefix import prefix_urdf

PREFIX = "robot_3"


def read(model):
    with open(os.path.join(URDF_DIR, model + ".urdf")) as f:
        return f.read()


def names(robot, tag):
    return [element.get("name") for element in robot.findall(tag)]


@pytest.mark.parametrize("model", MODELS)
def test_every_link_and_joint_is_prefixed(model):
    original = ET.fromstring(read(model))
    prefixed = ET.fromstring(prefix_urdf(read(model), PREFIX))
    for tag in ("link", "joint"):
        assert len(names(original, tag)) > 0
        assert names(prefixed, tag) == [PREFIX + "/" + n for n in names(original, tag)]
    for joint_before, joint_after in zip(original.findall("joint"), prefixed.findall("joint")):
        for end in ("parent", "child"):
            before = joint_before.find(end).get("link")
            assert joint_after.find(end).get("link") == PREFIX + "/" + before


@pytest.mark.parametrize("model", MODELS)
def test_materials_and_robot_name_untouched(model):
    original = ET.fromstring(read(model))
    prefixed = ET.fromstring(prefix_urdf(read(model), PREFIX))
    assert prefixed.get("name") == original.get("name")

    def materials(robot):
        return [ET.tostring(m) for m in robot.iter("material")]

    assert len(materials(original)) > 0
    assert materials(prefixed) == materials(original)


@pytest.mark.parametrize("model", MODELS)
def test_check_urdf_accepts_the_prefixed_model(model, tmp_path):
    path = tmp_path / (model + "_prefixed.urdf")
    path.write_text(prefix_urdf(read(model), PREFIX))
    result = subprocess.run(["check_urdf", str(path)], capture_output=True, text=True)
    assert result.returncode == 0, result.stdout + result.stderr
    assert "root Link: %s/base_footprint" % PREFIX in result.stdout


def test_prefixing_twice_or_with_slashes_changes_nothing_more():
    once = prefix_urdf(read("mbot"), PREFIX)
    assert prefix_urdf(once, PREFIX) == once
    assert prefix_urdf(read("mbot"), "/" + PREFIX + "/") == once


def test_mimic_transmission_and_gazebo_references_follow():
    xml = """<robot name="r">
      <link name="a"/><link name="b"/><link name="c"/>
      <joint name="j1" type="revolute"><parent link="a"/><child link="b"/>
        <limit effort="1" velocity="1" lower="0" upper="1"/></joint>
      <joint name="j2" type="revolute"><parent link="b"/><child link="c"/>
        <mimic joint="j1"/><limit effort="1" velocity="1" lower="0" upper="1"/></joint>
      <transmission name="t"><joint name="j1"/></transmission>
      <gazebo reference="b"/><gazebo/>
    </robot>"""
    robot = ET.fromstring(prefix_urdf(xml, "r7"))
    assert robot.find("joint/mimic").get("joint") == "r7/j1"
    assert robot.find("transmission/joint").get("name") == "r7/j1"
    assert robot.find("transmission").get("name") == "t"
    assert robot.findall("gazebo")[0].get("reference") == "r7/b"
    assert robot.findall("gazebo")[1].get("reference") is None


@pytest.mark.parametrize("prefix", ["", "/", "robot 3", "3robot", "robot-3"])
def test_invalid_prefix_is_rejected(prefix):
    with pytest.raises(ValueError, match="prefix"):
        prefix_urdf(read("mbot"), prefix)


def test_invalid_documents_are_rejected():
    with pytest.raises(ValueError, match="not valid XML"):
        prefix_urdf("<robot", PREFIX)
    with pytest.raises(ValueError, match="<robot>"):
        prefix_urdf("<model/>", PREFIX)


def run_script(*args):
    env = dict(os.environ, PYTHONPATH=os.path.join(PACKAGE_DIR, "src"))
    script = os.path.join(PACKAGE_DIR, "scripts", "prefix_urdf")
    return subprocess.run([script] + list(args), capture_output=True, text=True, env=env)


def test_script_prints_the_prefixed_urdf():
    path = os.path.join(URDF_DIR, "mbot.urdf")
    result = run_script(path, PREFIX)
    assert result.returncode == 0, result.stderr
    assert result.stdout == prefix_urdf(read("mbot"), PREFIX)


def test_script_reports_bad_arguments():
    assert run_script().returncode == 2
    missing = run_script("/nonexistent/robot.urdf", PREFIX)
    assert missing.returncode == 1
    assert "/nonexistent/robot.urdf" in missing.stderr
    bad_prefix = run_script(os.path.join(URDF_DIR, "mbot.urdf"), "robot 3")
    assert bad_prefix.returncode == 1
    assert "prefix" in bad_prefix.stderr
