"""Plain tests (pytest, no master) of the robot_state_publishers helper's logic."""
import os
import sys

HERE = os.path.dirname(os.path.abspath(__file__))
sys.path.insert(0, os.path.join(HERE, "..", "..", "src"))
sys.path.insert(0, os.path.join(HERE, "..", "..", "..", "mbot_description", "src"))

from mbot_sim.robot_state_publishers import (RobotStatePublishers, plan_changes,  # noqa: E402
                                             prefixed_description, robot_set)

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


def test_publishers_ignore_joint_states_unless_asked():
    """The simulator publishes the wheels' tf: robot_state_publisher must not also read
    joint_states (each message costs it three master calls); with use_joint_states it does."""
    launcher = FakeLauncher()
    RobotStatePublishers(launcher, {}.__setitem__, {}.pop, DESCRIPTION_DIR).update({"robot_0": "mbot"})
    assert launcher.launched[0].remap_args == [("joint_states", RobotStatePublishers.UNUSED_JOINT_STATES)]
    launcher = FakeLauncher()
    RobotStatePublishers(launcher, {}.__setitem__, {}.pop, DESCRIPTION_DIR,
                         use_joint_states=True).update({"robot_0": "mbot"})
    assert launcher.launched[0].remap_args == []
