"""Plain tests (pytest, no master) of the robot_state_publishers helper's logic."""
import math
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "src"))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "mbot_description", "src"))

from mbot_sim.robot_state_publishers import (FixedFramesPublisher, RobotStatePublishers,  # noqa: E402
                                             fixed_joints, plan_changes, prefixed_description,
                                             quaternion_from_rpy, robot_set)

DESCRIPTION_DIR = os.path.join(HERE, "..", "..", "..", "mbot_description")


def test_robot_set_reads_the_parameter_value():
    assert robot_set([{"name": "a", "model": "mbot"}, {"name": "b"}]) == {"a": "mbot", "b": "mbot"}
    assert robot_set(None) == {}


def test_plan_starts_new_stops_gone_and_restarts_changed_models():
    running = {"a": "mbot", "b": "mbot", "c": "mbot"}
    wanted = {"a": "mbot", "c": "mbot_omni", "d": "mbot"}
    start, stop = plan_changes(running, wanted)
    assert start == ["c", "d"]
    assert stop == ["b", "c"]
    assert plan_changes(wanted, wanted) == ([], [])


def test_prefixed_description_prefixes_links_and_joints():
    text = prefixed_description(DESCRIPTION_DIR, "mbot", "robot_7")
    assert '<link name="robot_7/base_laser"' in text
    assert '<joint name="robot_7/left_wheel_joint"' in text
    assert 'name="base_link"' not in text


class FakeProcess(object):
    def __init__(self):
        self.stopped = False

    def stop(self):
        self.stopped = True


class FakeLauncher(object):
    def __init__(self):
        self.launched = []   # roslaunch Node objects
        self.processes = []  # what launch() returned, in the same order

    def launch(self, node):
        self.launched.append(node)
        self.processes.append(FakeProcess())
        return self.processes[-1]


def test_update_sets_descriptions_launches_and_stops():
    params = {}
    launcher = FakeLauncher()
    pubs = RobotStatePublishers(launcher, params.__setitem__, params.pop, DESCRIPTION_DIR)
    pubs.update({"robot_0": "mbot", "robot_1": "mbot"})
    assert sorted(params) == ["/robot_0/robot_description", "/robot_1/robot_description"]
    assert [n.namespace.rstrip("/") for n in launcher.launched] == ["/robot_0", "/robot_1"]
    assert all(n.type == "robot_state_publisher" for n in launcher.launched)
    pubs.update({"robot_1": "mbot"})  # robot_0 removed
    assert "/robot_0/robot_description" not in params
    assert launcher.processes[0].stopped and not launcher.processes[1].stopped
    assert len(launcher.launched) == 2  # nothing new started
    pubs.stop_all()
    assert params == {}
    assert launcher.processes[1].stopped


def test_quaternion_from_rpy_is_urdfs_fixed_axis_order():
    s = math.sqrt(0.5)
    assert quaternion_from_rpy(0.0, 0.0, math.pi / 2) == pytest.approx((0.0, 0.0, s, s))
    assert quaternion_from_rpy(math.pi / 2, 0.0, 0.0) == pytest.approx((s, 0.0, 0.0, s))
    # R = Rz(90) Rx(90) maps the body's z axis to (1, 0, 0) (Rx: z -> -y, Rz: -y -> +x)
    x, y, z, w = quaternion_from_rpy(math.pi / 2, 0.0, math.pi / 2)
    v = (2 * (x * z + w * y), 2 * (y * z - w * x), 1 - 2 * (x * x + y * y))
    assert v == pytest.approx((1.0, 0.0, 0.0), abs=1e-12)


def test_fixed_joints_are_the_urdfs_fixed_joints_with_their_origins():
    joints = fixed_joints(prefixed_description(DESCRIPTION_DIR, "mbot", "robot_7"))
    by_child = {child: (parent, xyz, q) for parent, child, xyz, q in joints}
    assert sorted(by_child) == ["robot_7/base_laser", "robot_7/base_link", "robot_7/caster", "robot_7/imu_link",
                                "robot_7/lidar_link"]
    parent, xyz, q = by_child["robot_7/base_laser"]
    assert parent == "robot_7/base_link"
    assert xyz == pytest.approx((0.05, 0.0, 0.12))  # laser_joint in mbot.urdf
    assert q == pytest.approx((0.0, 0.0, 0.0, 1.0))
    assert all("wheel" not in child for child in by_child)  # the wheels move: the simulator's
    with pytest.raises(ValueError, match="joint j origin xyz"):
        fixed_joints('<robot name="r"><joint name="j" type="fixed"><parent link="a"/><child link="b"/>'
                     '<origin xyz="1 2"/></joint></robot>')


def test_fixed_frames_of_every_robot_in_one_message_sent_again_when_the_fleet_changes():
    params, sent = {}, []
    pubs = FixedFramesPublisher(sent.append, params.__setitem__, params.pop, DESCRIPTION_DIR, lambda: 12.5)
    pubs.update({"robot_0": "mbot", "robot_1": "mbot_omni"})
    assert sorted(params) == ["/robot_0/robot_description", "/robot_1/robot_description"]
    assert len(sent) == 1
    children = sorted(t[1] for t in sent[0])
    assert "robot_0/base_laser" in children and "robot_1/base_laser" in children
    assert all(t[4] == 12.5 for t in sent[0])
    pubs.update({"robot_0": "mbot", "robot_1": "mbot_omni"})
    assert len(sent) == 1  # nothing changed, nothing sent
    pubs.update({"robot_1": "mbot_omni", "robot_2": "mbot"})
    assert len(sent) == 2
    assert "/robot_0/robot_description" not in params
    children = {t[1].split("/")[0] for t in sent[1]}
    assert children == {"robot_1", "robot_2"}
