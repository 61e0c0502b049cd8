"""The coordinator node without a master: its wait for overdue robots under lockstep (the node
is built without its ROS connections, the poses come from a stand-in for tf, the wall clock is a
fake that moves only when the node sleeps) and its leader pause on a stale scan."""
import threading

import pytest
import rospy
from sensor_msgs.msg import LaserScan

from mbot_follower.coordinator import NAVIGATING, FleetCoordinator
from mbot_follower.coordinator_node import NODE_PARAMS, CoordinatorNode, _age
from test_fleet_io import FakeWallClock

ROBOTS = ["robot_0", "robot_1", "robot_2"]
NOW = 100.0
WAIT = 0.5   # [s wall] loss_wall_wait in these tests


def node(lockstep=True):
    """A started coordinator at sim time NOW: every robot's pose current, robot_1's controller
    state 1.5 s old (overdue: the loss timeout is 1 s), robot_2's current."""
    n = CoordinatorNode.__new__(CoordinatorNode)
    n.params = dict(NODE_PARAMS, lockstep=lockstep, loss_wall_wait=WAIT)
    n.robots = ROBOTS
    n.core = FleetCoordinator(ROBOTS, "robot_0", "triangle", 1.5)
    n.lock = threading.RLock()
    n.last_heard_pose = {r: NOW for r in ROBOTS}
    n.last_heard_controller = {"robot_0": NOW, "robot_1": NOW - 1.5, "robot_2": NOW}
    n._startup_done = True
    n._waited_for = set()
    n._scan_waited = False
    n._look_up_poses = lambda now_ros: {}
    n._wall_clock = FakeWallClock()
    n._sleep = n._wall_clock.sleep
    return n


def timed_wait(n):
    started = n._wall_clock()
    n._wait_for_overdue(rospy.Time.from_sec(NOW), "robot_0", {})
    return n._wall_clock() - started


def deliver_later(n, robot, delay):
    n._wall_clock.at(n._wall_clock() + delay, lambda: n.last_heard_controller.__setitem__(robot, NOW))


def test_a_late_message_that_arrives_within_the_wait_ends_it_and_the_robot_is_not_overdue():
    n = node()
    deliver_later(n, "robot_1", 0.15)
    elapsed = timed_wait(n)
    assert 0.15 <= elapsed < 0.17                  # the first look after it came ends the wait
    assert n._overdue(NOW, "robot_0") == set()


def test_a_silent_robot_is_waited_for_once_and_again_after_it_was_heard():
    n = node()
    assert WAIT <= timed_wait(n) < WAIT + 0.02      # silent: the whole wait
    assert n._overdue(NOW, "robot_0") == {"robot_1"}   # still overdue: the loss follows
    assert timed_wait(n) == 0.0                     # the next cycles do not wait for it again
    n.last_heard_controller["robot_1"] = NOW        # heard again ...
    assert timed_wait(n) == 0.0
    n.last_heard_controller["robot_1"] = NOW - 1.5  # ... and silent again: a new wait
    assert timed_wait(n) >= WAIT


def test_no_wait_without_lockstep_or_before_the_start():
    assert timed_wait(node(lockstep=False)) == 0.0   # sim time would run on: waiting helps nothing
    n = node()
    n._startup_done = False                          # robots still coming up are not late
    assert timed_wait(n) == 0.0


def test_a_lost_robot_is_not_waited_for():
    n = node()
    n.core.members.remove("robot_1")
    n.core.lost.append("robot_1")
    assert timed_wait(n) == 0.0


def test_startup_waits_startup_timeout_of_wall_time_for_a_missing_robot(monkeypatch):
    monkeypatch.setattr(rospy, "loginfo_throttle", lambda period, text: None)
    n = node()
    n._startup_done = False
    n._wall_start = n._wall_clock()
    heard = {"robot_0": NOW, "robot_1": NOW, "robot_2": NOW - 5.0}
    assert not n._started(heard, NOW)
    n._wall_clock.sleep(NODE_PARAMS["startup_timeout"] + 0.1)
    assert n._started(heard, NOW)


# --- the leader pause on what the leader's laser sees (or no longer sees) ----------------------

def scan(stamp, distance=5.0):
    """A scan of the leader stamped `stamp` [s sim]: everything `distance` away."""
    msg = LaserScan()
    msg.header.stamp = rospy.Time.from_sec(stamp)
    msg.angle_min, msg.angle_increment = -1.0, 0.1
    msg.ranges = [distance] * 21
    return msg


@pytest.fixture
def warnings(monkeypatch):
    said = []
    monkeypatch.setattr(rospy, "logwarn_throttle", lambda period, text: said.append(text))
    return said


def scan_node(since):
    n = node()
    n.leader_scan, n._scan_robot, n._scan_since = None, "robot_0", since
    return n


def test_a_current_clear_scan_is_no_reason_to_pause_and_a_close_obstacle_is(warnings):
    n = scan_node(since=NOW - 10.0)
    n._on_scan(scan(NOW - 0.1))
    assert n._obstacle_ahead("robot_0", NOW) is False
    n._on_scan(scan(NOW - 0.1, distance=0.8))
    assert n._obstacle_ahead("robot_0", NOW) == "obstacle in front of the leader robot_0"
    assert warnings == []


def test_a_scan_older_than_max_scan_age_pauses_the_fleet_with_a_warning_naming_robot_and_age(warnings):
    n = scan_node(since=NOW - 10.0)
    n._on_scan(scan(NOW - 0.25))                     # clear and current (0.3 s limit)
    assert n._obstacle_ahead("robot_0", NOW) is False
    n._on_scan(scan(NOW - 0.45))                     # clear, but old: the leader is blind
    why = n._obstacle_ahead("robot_0", NOW)
    assert why == "the leader robot_0's scan: newest scan is 0.45 s old (limit ~max_scan_age 0.30 s)"
    assert len(warnings) == 1 and "robot_0" in warnings[0] and "0.45 s old" in warnings[0]
    n.params["max_scan_age"] = 0.5                   # the limit is the parameter's
    assert n._obstacle_ahead("robot_0", NOW) is False


def test_no_scan_pauses_once_max_scan_age_has_passed_since_the_subscription(warnings):
    n = scan_node(since=NOW - 0.2)                   # a new leader's scan is on its way
    assert n._obstacle_ahead("robot_0", NOW) is False
    n = scan_node(since=NOW - 0.4)
    assert n._obstacle_ahead("robot_0", NOW) == "the leader robot_0's scan: no scan yet"
    assert "robot_0" in warnings[0]


def timed_scan_wait(n):
    started = n._wall_clock()
    n._wait_for_scan("robot_0", NOW)
    return n._wall_clock() - started


def test_under_lockstep_a_stale_scan_that_comes_within_the_wait_does_not_pause_the_fleet(warnings, monkeypatch):
    """trio_switch under stress: the node's scan thread fell 0.35 s of sim time behind and the
    fleet paused with a clear view. Sim time waits for this node's heartbeat meanwhile."""
    said = []
    monkeypatch.setattr(rospy, "logwarn", lambda text, *args: said.append(text % args))
    n = scan_node(since=NOW - 10.0)
    n._on_scan(scan(NOW - 0.35))
    n._wall_clock.at(n._wall_clock() + 0.12, lambda: n._on_scan(scan(NOW - 0.05)))
    assert 0.12 <= timed_scan_wait(n) < 0.14           # the first look after it came ends the wait
    assert n._obstacle_ahead("robot_0", NOW) is False and warnings == []
    assert len(said) == 1 and "the leader robot_0's scan came 0.1" in said[0] and "wall time late" in said[0]


def test_a_scan_that_stays_stale_is_waited_for_once_per_spell_and_then_pauses(warnings):
    n = scan_node(since=NOW - 10.0)
    n._on_scan(scan(NOW - 0.45))
    assert WAIT <= timed_scan_wait(n) < WAIT + 0.02     # silent: the whole wait
    assert "0.45 s old" in n._obstacle_ahead("robot_0", NOW)
    assert timed_scan_wait(n) == 0.0                    # the next cycles do not wait again
    n._on_scan(scan(NOW - 0.1))                         # current again ...
    assert timed_scan_wait(n) == 0.0
    n._on_scan(scan(NOW - 0.45))                        # ... and stale again: a new wait
    assert timed_scan_wait(n) >= WAIT
    n = scan_node(since=NOW - 10.0)
    n.params["lockstep"] = False                        # sim time would run on: waiting helps nothing
    n._on_scan(scan(NOW - 0.45))
    assert timed_scan_wait(n) == 0.0


def test_the_stale_scan_pause_reaches_the_fleet_state_as_a_pause():
    core = FleetCoordinator(ROBOTS, "robot_0", "line", 1.5)
    core.phase = NAVIGATING
    core._set_phase(NAVIGATING, NOW, "test")
    core.target = None
    actions = core._navigating(NOW, {}, "ACTIVE", "the leader robot_0's scan: no scan yet", False, ())
    assert core.paused and actions == [("cancel", "robot_0")]
    assert core.reason == "paused: the leader robot_0's scan: no scan yet"


def test_the_loss_log_gives_no_negative_ages():
    # a pose stamped after the cycle read its clock is current, not -0.25 s old
    assert (_age(100.25, 100.0), _age(98.9, 100.0), _age(None, 100.0)) == (0.0, 100.0 - 98.9, float("inf"))


# --- parameters: rosparam set applies, or says it needs a restart -------------------------------

class FakeParamCache(object):
    def __init__(self, values):
        self.params = dict(values)

    def values(self):
        return dict(self.params)


@pytest.fixture
def logs(monkeypatch):
    said = {"warn": [], "err": []}
    monkeypatch.setattr(rospy, "logwarn", lambda text, *args: said["warn"].append(text % args))
    monkeypatch.setattr(rospy, "logerr_throttle", lambda period, text: said["err"].append(text))
    monkeypatch.setattr(rospy, "loginfo", lambda text, *args: None)
    return said


def param_node(**values):
    from mbot_follower.coordinator import CoordinatorConfig

    n = node()
    n.params = dict(NODE_PARAMS)
    config = CoordinatorConfig()
    n._init_params(config)
    start = dict(NODE_PARAMS, **vars(config))
    start.update(values)
    n._param_cache = FakeParamCache(start)
    n._read_params(n._param_cache.values(), config, startup=True)
    n.core = FleetCoordinator(ROBOTS, "robot_0", "triangle", 1.5, config)
    return n


def test_a_changed_live_parameter_applies_at_the_next_refresh(logs):
    n = param_node(pause_distance=1.0, formation="line")
    assert n.params["pause_distance"] == 1.0
    n._param_cache.params.update(pause_distance=1.5, max_scan_age=0.5, loss_timeout=2, pause_time=0.5)
    n._refresh_params(NOW)
    assert (n.params["pause_distance"], n.params["max_scan_age"]) == (1.5, 0.5)
    assert (n.core.config.loss_timeout, n.core.config.pause_time) == (2.0, 0.5)
    assert isinstance(n.core.config.loss_timeout, float)
    n._param_cache.params["pause_distance"] = 0.9    # read again only after ~param_refresh (sim time)
    n._refresh_params(NOW + 0.5)
    assert n.params["pause_distance"] == 1.5
    n._refresh_params(NOW + 1.0)
    assert n.params["pause_distance"] == 0.9
    assert logs["warn"] == [] and logs["err"] == []


def test_a_changed_start_only_parameter_warns_once_that_it_needs_a_restart(logs):
    n = param_node(formation="line")
    n._param_cache.params.update(rate=20.0, formation="wedge")
    for t in (NOW, NOW + 1.0, NOW + 2.0):
        n._refresh_params(t)
    assert n.params["rate"] == NODE_PARAMS["rate"]
    assert sorted(logs["warn"]) == [
        "coordinator: ~formation changed to 'wedge': it takes effect when the node restarts (running with 'line')",
        "coordinator: ~rate changed to 20.0: it takes effect when the node restarts (running with 10.0)"]


def test_a_bad_value_is_an_error_at_the_start_and_refused_later(logs):
    with pytest.raises(ValueError, match=r"parameter ~pause_distance: expected a float, got 'near'"):
        param_node(pause_distance="near")
    with pytest.raises(ValueError, match=r"parameter ~debug_mode: expected a bool, got 'false'"):
        param_node(debug_mode="false")
    n = param_node()
    n._param_cache.params["loss_timeout"] = "soon"
    n._refresh_params(NOW)
    assert n.core.config.loss_timeout == 1.0
    assert logs["err"] == ["coordinator: parameter ~loss_timeout: expected a float, got 'soon': refused, keeping 1.0"]
