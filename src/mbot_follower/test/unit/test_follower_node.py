"""The follower node's threads and parameters, without a master: the node is built without its
ROS connections, poses come from a tf2 Buffer filled here, and the publishers record."""
import math
import sys
import threading

import pytest
import rospy
import tf2_ros
from geometry_msgs.msg import TransformStamped, Twist
from mbot_msgs.msg import FollowerState
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from std_msgs.msg import Float64

from mbot_follower import follower_node
from mbot_follower.fleet_io import Assignment
from mbot_follower.follower_node import FollowerController

TRIANGLE = Assignment("leader", "triangle", 1.2, {"leader": (0.0, 0.0), "follower_1": (-1.0, 0.6)}, {}, False)
COLUMN = Assignment("leader", "column", 1.2, {"leader": (0.0, 0.0), "follower_1": (-1.2, 0.0)}, {}, True)


class Recorder(object):
    def __init__(self):
        self.messages = []

    def publish(self, msg):
        self.messages.append(msg)


class Clock(object):
    """Sim time for rospy.Time.now(), set by the test."""

    def __init__(self, t):
        rospy.rostime.set_rostime_initialized(True)
        self.set(t)

    def set(self, t):
        self.t = t
        rospy.rostime._set_rostime(rospy.Time.from_sec(t))


@pytest.fixture
def clock():
    return Clock(100.0)


@pytest.fixture(autouse=True)
def no_subscriptions(monkeypatch):
    class Subscriber(object):
        def __init__(self, *args, **kwargs):
            pass

        def unregister(self):
            pass
    monkeypatch.setattr(follower_node.rospy, "Subscriber", Subscriber)


def node(clock):
    n = FollowerController.__new__(FollowerController)
    n.robot = "follower_1"
    n._init_state()
    n.params["pose_wait"] = 0.0
    n._msg = {"Twist": Twist, "FollowerState": FollowerState, "Float64": Float64, "Odometry": Odometry}
    n.cmd_pub, n.power_pub, n.state_pub = Recorder(), Recorder(), Recorder()
    n.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(5.0), debug=False)
    n._param_cache = type("Cache", (), {"values": lambda self: {}})()
    move(n, clock.t)
    n._on_scan(scan(clock.t))
    n._on_status(type("Status", (), {"state": "NAVIGATING", "paused": False})())
    return n


def move(n, t, leader_x=0.0):
    """The leader at (leader_x, 0), follower_1 near its triangle slot, both stamped t."""
    for child, x, y in (("leader", leader_x, 0.0), ("follower_1", leader_x - 1.3, 0.4)):
        tf = TransformStamped()
        tf.header.stamp = rospy.Time.from_sec(t)
        tf.header.frame_id = "map"
        tf.child_frame_id = "%s/base_link" % child
        tf.transform.translation.x, tf.transform.translation.y = x, y
        tf.transform.rotation.w = 1.0
        n.tf_buffer.set_transform(tf, "test")


def scan(t, ranges=None):
    msg = LaserScan()
    msg.header.stamp = rospy.Time.from_sec(t)
    msg.angle_min, msg.angle_increment = -math.pi, 2 * math.pi / 360
    msg.range_min, msg.range_max = 0.12, 8.0
    msg.ranges = ranges or [math.inf] * 360
    return msg


def last_mode(n):
    return n.state_pub.messages[-1].mode


def test_assignments_from_the_subscriber_thread_never_break_the_cycles_of_the_timer_thread(clock):
    """rospy runs _on_assignment and _cycle in two threads: a new assignment clears the trails
    and the leader's pose that a running cycle reads. Without the node's lock a cycle read them
    half-cleared (a path slot with no leader pose) and raised."""
    n = node(clock)
    stop = threading.Event()
    switch = sys.getswitchinterval()
    sys.setswitchinterval(1e-5)                      # switch threads often: the race shows within 400 cycles

    def assign():
        i = 0
        while not stop.is_set():
            n._on_assignment_data(COLUMN if i % 2 else TRIANGLE)
            i += 1

    thread = threading.Thread(target=assign)
    thread.start()
    try:
        for i in range(400):
            clock.set(100.0 + 0.05 * i)
            move(n, clock.t, leader_x=0.01 * i)
            n._on_scan(scan(clock.t))
            n._cycle(None)
    finally:
        stop.set()
        thread.join()
        sys.setswitchinterval(switch)
    assert n.cycle_failures == 0
    modes = {m.mode for m in n.state_pub.messages}
    assert modes & {"slot", "merge", "trail", "detour", "safety_stop"}, modes


def test_an_assignment_that_arrives_during_a_cycle_is_taken_after_the_cycle(clock):
    """The subscriber thread's assignment waits for the running cycle (deterministic: it is sent
    from inside the control law, half-way through the cycle)."""
    n = node(clock)
    n._on_assignment_data(TRIANGLE)
    real = n.law.compute
    seen = {}

    def compute(*args):
        thread = threading.Thread(target=n._on_assignment_data, args=(COLUMN,))
        thread.start()
        thread.join(0.3)
        seen["blocked"] = thread.is_alive()
        seen["assignment"] = n.assignment
        seen["thread"] = thread
        return real(*args)

    n.law.compute = compute
    n._cycle(None)
    seen["thread"].join(1.0)
    assert seen["blocked"] and seen["assignment"] is TRIANGLE   # the cycle's state stayed whole
    assert n.assignment is COLUMN and n._path_pending            # and the new one is taken after it


def test_a_failed_cycle_is_logged_holds_the_robot_still_and_the_next_cycle_runs(clock):
    n = node(clock)
    n._on_assignment_data(TRIANGLE)
    real = n.law.compute
    calls = []

    def fail_once(*args):
        calls.append(1)
        if len(calls) == 1:
            raise ZeroDivisionError("a bug in the law")
        return real(*args)

    n.law.compute = fail_once
    n._cycle(None)                                   # rospy's Timer would have ended here
    assert n.cycle_failures == 1
    assert n.cmd_pub.messages[-1].linear.x == 0.0 and n.cmd_pub.messages[-1].angular.z == 0.0
    clock.set(100.05)
    move(n, clock.t)
    n._on_scan(scan(clock.t))
    n._cycle(None)
    assert n.cycle_failures == 1
    assert last_mode(n) == "slot"
    assert n.cmd_pub.messages[-1].linear.x > 0.0     # it drives towards its slot again


def test_an_old_scan_holds_the_robot_still_and_a_current_one_lets_it_drive(clock):
    n = node(clock)
    n._on_assignment_data(TRIANGLE)
    clock.set(100.4)                                 # the scan of t=100 is 0.4 s old
    move(n, clock.t)
    n._cycle(None)
    assert last_mode(n) == "no_scan"
    assert n.cmd_pub.messages[-1].linear.x == 0.0
    n._on_scan(scan(clock.t))
    n._cycle(None)
    assert last_mode(n) == "slot"
    assert n.cmd_pub.messages[-1].linear.x > 0.0


def test_no_scan_at_all_holds_the_robot_still(clock):
    n = node(clock)
    n.scan = None
    n._on_assignment_data(TRIANGLE)
    n._cycle(None)
    assert last_mode(n) == "no_scan"


def test_parameters_change_while_running_and_rate_warns_that_it_needs_a_restart(clock, monkeypatch):
    n = node(clock)
    warnings = []
    monkeypatch.setattr(follower_node.rospy, "logwarn", lambda msg, *a: warnings.append(msg % a if a else msg))
    n._read_params({"max_linear_vel": 0.3, "max_scan_age": 0.5, "controller": "consensus", "rate": 10.0})
    assert n.config.max_linear_vel == 0.3
    assert n.params["max_scan_age"] == 0.5
    assert n.params["controller"] == "consensus" and type(n.law).__name__ == "Consensus"
    assert n.params["rate"] == 20.0                  # the timer runs at the old rate ...
    assert len(warnings) == 1 and "~rate" in warnings[0] and "restart" in warnings[0]
    n._read_params({"rate": 10.0})
    assert len(warnings) == 1                        # ... and says so once


def test_a_bad_value_while_running_is_refused_and_the_old_one_stays(clock):
    n = node(clock)
    n._read_params({"max_pose_age": "soon", "max_linear_vel": -1.0})
    assert n.params["max_pose_age"] == follower_node.NODE_PARAMS["max_pose_age"]
    assert n.config.max_linear_vel == 0.5


def test_a_follower_receives_the_poses_of_the_robots_its_cycle_needs_and_no_others(clock):
    n = node(clock)
    star = Assignment("leader", "triangle", 1.2, {"leader": (0.0, 0.0), "follower_1": (-1.0, 0.6),
                                                  "follower_2": (-1.0, -0.6), "follower_3": (-2.0, 0.0)}, {}, False)
    assert n._robots_needed(None) == {"follower_1"}
    assert n._robots_needed(star) == {"follower_1", "leader"}
    column = Assignment("leader", "column", 1.2, {"leader": (0.0, 0.0), "follower_2": (-1.2, 0.0),
                                                  "follower_1": (-2.4, 0.0), "follower_3": (-3.6, 0.0)}, {}, True)
    assert n._robots_needed(column) == {"follower_1", "leader", "follower_2"}   # the robot ahead on the path
    chain = star._replace(follows={"follower_1": "follower_3"})
    assert n._robots_needed(chain) == {"follower_1", "leader", "follower_3"}
    n.params["controller"] = "consensus"
    assert n._robots_needed(star) == set(star.slots)                          # every neighbour
    leading = star._replace(leader="follower_1")
    assert n._robots_needed(leading) == {"follower_1"}                         # its move_base drives it


def test_overruns_and_late_starts_are_counted_and_published(clock, monkeypatch):
    """A cycle whose computation takes longer than the period (50 ms) is an overrun; a cycle that
    the timer starts a period or more after its time is a late start; ~state carries both."""
    from rospy.timer import TimerEvent

    n = node(clock)
    n._on_assignment_data(TRIANGLE)
    t = rospy.Time.from_sec(clock.t)

    def event(late):
        return TimerEvent(t, t, t, t + rospy.Duration.from_sec(late), None)

    n._cycle(event(0.01))                             # on time, quick
    msg = n.state_pub.messages[-1]
    assert (msg.overruns, msg.late_starts) == (0, 0)
    n._cycle(event(0.05))                             # one period late
    assert (n.state_pub.messages[-1].overruns, n.state_pub.messages[-1].late_starts) == (0, 1)
    wall = [1000.0]
    monkeypatch.setattr(follower_node.time, "time", lambda: wall[0])
    real_step = n._step

    def slow_step(now):
        real_publish = n._publish_state

        def later(*args, **kwargs):
            wall[0] += 0.06                           # 60 ms of computing pass before the state
            n._publish_state = real_publish
            return real_publish(*args, **kwargs)
        n._publish_state = later
        return real_step(now)
    n._step = slow_step
    n._cycle(event(0.0))
    assert (n.state_pub.messages[-1].overruns, n.state_pub.messages[-1].late_starts) == (1, 1)
    assert n.state_pub.messages[-1].cycle_time == pytest.approx(0.06)


# --- consensus in a chain: every pose and slot in the frame of the robot followed ----------------

CHAIN = Assignment("leader", "wedge", 1.2,
                   {"leader": (0.0, 0.0), "follower_1": (-1.0, 0.6), "follower_2": (-2.0, 1.2),
                    "follower_3": (-2.0, 0.0)},
                   {"follower_1": "leader", "follower_2": "follower_1", "follower_3": "follower_1"}, False)


def place(n, t, poses):
    for child, (x, y, theta) in poses.items():
        tf = TransformStamped()
        tf.header.stamp = rospy.Time.from_sec(t)
        tf.header.frame_id = "map"
        tf.child_frame_id = "%s/base_link" % child
        tf.transform.translation.x, tf.transform.translation.y = x, y
        tf.transform.rotation.z, tf.transform.rotation.w = math.sin(theta / 2), math.cos(theta / 2)
        n.tf_buffer.set_transform(tf, "test")


def chain_poses(f3_off=0.0):
    """follower_1 on its slot but turned 60 deg; follower_2 and follower_3 on their slots seen
    from follower_1 (the chain's rule: the formation faces the way the robot ahead faces)."""
    from mbot_common.geometry import Pose2D, compose

    f1 = Pose2D(-1.0, 0.6, math.radians(60))
    f2 = compose(f1, Pose2D(-1.0, 0.6, 0.0))
    f3 = compose(f1, Pose2D(-1.0 + f3_off, -0.6, 0.0))
    return {"leader": (0.0, 0.0, 0.0), "follower_1": tuple(f1), "follower_2": tuple(f2), "follower_3": tuple(f3)}


def chain_node(clock, controller):
    n = node(clock)
    n.robot = "follower_2"
    n.params["controller"] = controller
    n.law = follower_node.make_control_law(controller)
    n._on_assignment_data(CHAIN)
    clock.set(clock.t + 0.05)     # node() put the triangle's poses at the old time: these are newer
    return n


def test_consensus_neighbours_in_a_chain_are_in_the_frame_of_the_robot_followed(clock):
    n = chain_node(clock, "consensus")
    place(n, clock.t, chain_poses())
    now = rospy.Time.from_sec(clock.t)
    neighbours = n._neighbours(CHAIN, now, "follower_1")
    assert len(neighbours) == 2                       # follower_1 and follower_3, not the leader nor itself
    for pose, slot in neighbours:                     # every neighbour on its slot, seen from follower_1
        assert (pose.x, pose.y) == pytest.approx(slot, abs=1e-6)
    assert sorted(slot for _, slot in neighbours) == pytest.approx([(-1.0, -0.6), (0.0, 0.0)])


def test_in_a_chain_the_robots_that_track_this_one_are_no_neighbours_of_it(clock):
    """follower_2 and follower_3 track follower_1 and hold their slots where follower_1 faces: their
    errors swing with follower_1's heading. Compared with the leader-frame slots they pulled
    follower_1 off its own slot (a rigid echelon chain: steady RMS 0.155-0.184 m against
    0.04-0.05 m with slot tracking); taken in follower_1's frame they steered it by its own
    heading (the echelon did not form in 60 s). follower_1 has no neighbours; a robot tracked
    by nobody sees all the others."""
    n = chain_node(clock, "consensus")
    n.robot = "follower_1"
    place(n, clock.t, chain_poses())
    now = rospy.Time.from_sec(clock.t)
    assert n._neighbours(CHAIN, now, "leader") == []
    n.robot = "follower_3"
    assert sorted(slot for _, slot in n._neighbours(CHAIN, now, "follower_1")) == pytest.approx(
        [(-1.0, 0.6), (0.0, 0.0)])


def test_in_a_chain_the_robot_tracked_is_seen_with_its_own_error(clock):
    """follower_2 tracks follower_1: follower_1 in its own frame is always at (0, 0), so its error
    against the leader was invisible. It is its slot error in the leader's frame, turned."""
    n = chain_node(clock, "consensus")
    poses = chain_poses()
    x, y, theta = poses["follower_1"]
    poses["follower_1"] = (x + 0.3, y, theta)    # 0.3 m off its slot along the leader's x
    place(n, clock.t, poses)
    f1_seen = [pose for pose, slot in n._neighbours(CHAIN, rospy.Time.from_sec(clock.t), "follower_1")
               if slot == pytest.approx((0.0, 0.0))][0]
    turned = math.radians(-60)
    assert (f1_seen.x, f1_seen.y) == pytest.approx((0.3 * math.cos(turned), 0.3 * math.sin(turned)), abs=1e-6)


def test_the_consensus_law_runs_in_the_node_and_acts_only_on_a_neighbours_error(clock):
    """The node's cycle (tf in, cmd_vel and ~state out) with the consensus law against slot
    tracking: the same command while every neighbour is on its slot (the chain's frames agree),
    a different one when follower_3 is 0.5 m off its slot."""
    commands = {}
    for controller in ("slot_tracking", "consensus"):
        for off in (0.0, 0.5):
            n = chain_node(clock, controller)
            place(n, clock.t, chain_poses(off))
            n._on_scan(scan(clock.t))
            n._cycle(None)
            assert last_mode(n) == "slot"
            c = n.cmd_pub.messages[-1]
            commands[controller, off] = (c.linear.x, c.linear.y, c.angular.z)
    assert commands["consensus", 0.0] == pytest.approx(commands["slot_tracking", 0.0], abs=1e-9)
    assert commands["slot_tracking", 0.5] == pytest.approx(commands["slot_tracking", 0.0], abs=1e-9)
    assert commands["consensus", 0.5] != pytest.approx(commands["consensus", 0.0], abs=1e-3)


def test_the_state_names_the_control_law_that_ran_each_cycle(clock):
    """FollowerState.controller is the node's ~controller of that cycle, also after rosparam set."""
    n = node(clock)
    n._on_assignment_data(TRIANGLE)
    n._cycle(None)
    assert (last_mode(n), n.state_pub.messages[-1].controller) == ("slot", "slot_tracking")
    n._read_params({"controller": "consensus"})
    clock.set(100.05)
    move(n, clock.t)
    n._on_scan(scan(clock.t))
    n._cycle(None)
    assert (last_mode(n), n.state_pub.messages[-1].controller) == ("slot", "consensus")
    n.assignment = None
    n._cycle(None)                                   # held still: the law in force all the same
    assert (last_mode(n), n.state_pub.messages[-1].controller) == ("idle", "consensus")
