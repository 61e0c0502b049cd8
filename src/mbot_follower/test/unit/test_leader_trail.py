"""One definition of the leader's path (trail.LeaderTrail): it starts at the leader's pose at the
assignment's time, whoever builds it (coordinator, metrics collector, fleet probe, the follower
node itself) and however late the assignment reaches them, so a column's slots lie in the same
places for all of them."""
import math
from unittest import mock

import pytest
import rospy

from mbot_common.geometry import Pose2D
from mbot_follower.coordinator import FleetCoordinator
from mbot_follower.fleet_io import Assignment
from mbot_follower.metrics import MetricsCollector
from mbot_follower.trail import LEADER_TRAIL_LENGTH, LEADER_TRAIL_STEP, LeaderTrail, slot_pose, trail_start

COLUMN = {"L": (0.0, 0.0), "a": (-1.0, 0.0), "b": (-2.0, 0.0)}
ASSIGNED = 1.0   # [s] the assignment's time
END = 3.0        # [s]


def leader_at(t):
    """The leader drives 0.5 m/s along +x from (0, 0), turns left at (1, 0) and drives along +y."""
    s = 0.5 * t
    return Pose2D(s, 0.0, 0.0) if s <= 1.0 else Pose2D(1.0, s - 1.0, math.pi / 2)


def stamps(rate, until=END):
    return [round(k / rate, 4) for k in range(int(round(until * rate)) + 1)]


def test_a_leader_trail_starts_where_the_leader_was_at_the_assignment():
    poses = [(t,) + tuple(leader_at(t)) for t in stamps(50.0)]
    assert trail_start(poses, ASSIGNED)[0] == ASSIGNED
    assert trail_start(poses, 1.011)[0] == 1.0              # the newest not later than it
    assert trail_start(poses[60:], ASSIGNED)[0] == 1.2      # none before: the first after
    assert trail_start([], ASSIGNED) is None
    trail = LeaderTrail()
    assert (trail.min_step, trail.max_length) == (LEADER_TRAIL_STEP, LEADER_TRAIL_LENGTH)
    trail.restart(ASSIGNED)
    assert len(trail) == 0 and trail.since == ASSIGNED    # no pose yet: it starts at the next one
    trail.follow(0.5, 0.0, 0.0)
    trail.follow(0.52, 0.0, 0.0)                            # closer than LEADER_TRAIL_STEP: skipped
    trail.follow(0.6, 0.0, 0.0)
    assert [trail.point_behind(d) for d in (0.0, 0.1)] == [(0.6, 0.0), (0.5, 0.0)]
    assert trail.tail_heading == 0.0


def coordinator_trail():
    """The coordinator: its goal (the assignment) at ASSIGNED, then a cycle every 0.1 s."""
    robots = ["L", "a", "b"]
    core = FleetCoordinator(robots, "L", "column", 1.0)

    def poses(t):
        head = leader_at(t)
        return {"L": head, "a": Pose2D(head.x - 1.0, head.y, 0.0), "b": Pose2D(head.x - 2.0, head.y, 0.0)}

    assert core.set_goal(Pose2D(5.0, 5.0, 0.0), ASSIGNED, poses(ASSIGNED))[0]
    for t in stamps(10.0):
        if t > ASSIGNED:
            core.update(t, poses(t), {r: t for r in robots})
    return core._trail


def collector_trail():
    """The metrics collector: ground truth at 50 Hz, the assignment at ASSIGNED."""
    c = MetricsCollector()
    c.on_assignment(ASSIGNED, Assignment("L", "column", 1.0, COLUMN, {r: "L" for r in COLUMN}, True))
    c.on_status(ASSIGNED, "NAVIGATING", "goal", [])
    for t in stamps(50.0, END + 0.02):   # the last sample is at END
        c.on_pose("L", t, *leader_at(t))
    return c._trail


def probe_trail(monkeypatch):
    """The fleet probe: ground truth at 50 Hz; the assignment reaches it 0.3 s late."""
    from mbot_msgs.msg import FleetAssignment, SlotAssignment
    from nav_msgs.msg import Odometry

    import mbot_follower.fleet_probe as fp

    for name in ("Subscriber", "Publisher", "Timer"):
        monkeypatch.setattr(rospy, name, mock.Mock())
    probe = fp.FleetProbe(["L"])

    def truth(t):
        msg = Odometry()
        msg.header.stamp = rospy.Time.from_sec(t)
        p = leader_at(t)
        msg.pose.pose.position.x, msg.pose.pose.position.y = p.x, p.y
        msg.pose.pose.orientation.z, msg.pose.pose.orientation.w = math.sin(p.theta / 2), math.cos(p.theta / 2)
        probe._on_truth(msg, "L")

    assignment = FleetAssignment(leader="L", formation="column", spacing=1.0, along_path=True)
    assignment.header.stamp = rospy.Time.from_sec(ASSIGNED)
    for r, (x, y) in COLUMN.items():
        slot = SlotAssignment(robot=r)
        slot.offset.x, slot.offset.y = x, y
        assignment.slots.append(slot)
    for t in stamps(50.0):
        if t == ASSIGNED + 0.3:
            probe._on_assignment(assignment)
        truth(t)
    return probe.trail


def follower_trail(monkeypatch, arrives, assigned=ASSIGNED):
    """Follower a's node, built without a master (as test_follower_node.py does): the leader's and
    its own poses in its tf buffer at 50 Hz, a cycle every 0.05 s; the assignment (stamped
    `assigned`) reaches it at `arrives` [s]."""
    import tf2_ros
    from geometry_msgs.msg import TransformStamped, Twist
    from mbot_msgs.msg import FollowerState
    from nav_msgs.msg import Odometry
    from sensor_msgs.msg import LaserScan

    from mbot_follower import follower_node

    class Recorder(object):
        def publish(self, msg):
            pass

    monkeypatch.setattr(follower_node.rospy, "Subscriber", mock.Mock())
    rospy.rostime.set_rostime_initialized(True)
    n = follower_node.FollowerController.__new__(follower_node.FollowerController)
    n.robot = "a"
    n._init_state()
    n.params["pose_wait"] = 0.0
    n._msg = {"Twist": Twist, "FollowerState": FollowerState, "Odometry": Odometry}
    n.cmd_pub, n.state_pub = Recorder(), Recorder()
    n.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(5.0), debug=False)
    n._param_cache = type("Cache", (), {"values": lambda self: {}})()
    n._on_status(type("Status", (), {"state": "NAVIGATING", "paused": False})())

    def place(t):
        head = leader_at(t)
        for child, pose in (("L", head), ("a", Pose2D(head.x - 1.0, head.y, head.theta))):
            tf = TransformStamped()
            tf.header.stamp = rospy.Time.from_sec(t)
            tf.header.frame_id = "map"
            tf.child_frame_id = "%s/base_link" % child
            tf.transform.translation.x, tf.transform.translation.y = pose.x, pose.y
            tf.transform.rotation.z, tf.transform.rotation.w = math.sin(pose.theta / 2), math.cos(pose.theta / 2)
            n.tf_buffer.set_transform(tf, "test")

    column = Assignment("L", "column", 1.0, COLUMN, {r: "L" for r in COLUMN}, True)
    for t in stamps(50.0):
        place(t)
        rospy.rostime._set_rostime(rospy.Time.from_sec(t))
        if abs(t - arrives) < 1e-9:
            n._on_assignment_data(column, rospy.Time.from_sec(assigned))
        if round(t * 50) % 5 == 0:   # the node's cycles: every 0.1 s here
            scan = LaserScan()
            scan.header.stamp = rospy.Time.from_sec(t)
            scan.angle_min, scan.angle_increment, scan.range_max = -math.pi, 2 * math.pi / 360, 8.0
            scan.ranges = [math.inf] * 360
            n._on_scan(scan)
            n._cycle(None)
    assert n.cycle_failures == 0
    return n.path


def test_coordinator_collector_probe_and_follower_put_a_columns_slots_on_the_same_path(monkeypatch):
    trails = {"coordinator": coordinator_trail(), "collector": collector_trail(), "probe": probe_trail(monkeypatch),
              "follower": follower_trail(monkeypatch, ASSIGNED + 0.3)}
    head = leader_at(END)
    start = leader_at(ASSIGNED)
    for who, trail in trails.items():
        assert trail.since == ASSIGNED, who
        assert trail.point_behind(trail.length()) == pytest.approx((start.x, start.y), abs=1e-9), who
        for offset in ((-0.5, 0.0), (-1.0, 0.0), (-1.0, 0.3), (-2.0, 0.0)):
            slot = slot_pose(head, offset, trail)
            truth = slot_pose(head, offset, trails["collector"])
            # the same path; only where each one's points fall (its rate) differs, by millimetres
            assert math.hypot(slot.x - truth.x, slot.y - truth.y) < 0.01, (who, offset)
    # the leader at (1, 0.5): 1 m behind it is back on the first leg, past the corner (its points
    # cut the corner by a few mm); 2 m behind is before the path's start (0.5, 0), straight on
    assert slot_pose(head, (-1.0, 0.0), trails["probe"])[:2] == pytest.approx((0.5, 0.0), abs=0.02)
    assert slot_pose(head, (-2.0, 0.0), trails["probe"])[:2] == pytest.approx((-0.5, 0.0), abs=0.02)


def test_a_follower_whose_assignment_arrives_after_the_corner_has_the_path_round_it(monkeypatch):
    """The assignment of 1.8 s (the leader at (0.9, 0), 0.1 m before the corner) reaches follower
    a only at 2.4 s, 0.2 m past it: its path still starts at (0.9, 0) and turns the corner, as the
    collector's, from the poses in its tf buffer (a path begun where the leader was when the
    assignment came put the slots on the straight line behind (1, 0.2), 0.4 m off)."""
    assigned = 1.8
    collector = MetricsCollector()
    collector.on_assignment(assigned, Assignment("L", "column", 1.0, COLUMN, {r: "L" for r in COLUMN}, True))
    collector.on_status(assigned, "NAVIGATING", "goal", [])
    for t in stamps(50.0, END + 0.02):
        collector.on_pose("L", t, *leader_at(t))
    follower = follower_trail(monkeypatch, 2.4, assigned)
    assert follower.since == assigned
    assert follower.point_behind(follower.length()) == pytest.approx((0.9, 0.0), abs=1e-9)
    head = leader_at(END)
    # not -0.5, the corner itself: there points 5 cm apart cut it by up to 1.3 cm, as their phase falls
    for offset in ((-0.3, 0.0), (-0.8, 0.0), (-1.0, 0.3), (-2.0, 0.0)):
        slot, truth = slot_pose(head, offset, follower), slot_pose(head, offset, collector._trail)
        assert math.hypot(slot.x - truth.x, slot.y - truth.y) < 0.01, offset
