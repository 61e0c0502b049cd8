"""The ROS-side helpers the nodes share (fleet_io.py) that run without a master."""
import math

import pytest
import rospy

from mbot_follower import fleet_io
from mbot_follower.fleet_io import quiet_at_shutdown


def closed_topic():
    raise rospy.ROSException("publish() to a closed topic")


def closed_buffer():
    raise ValueError("I/O operation on closed file.")   # rospy's publish() as its buffer closes


@pytest.mark.parametrize("cycle", [closed_topic, closed_buffer])
def test_a_cycle_that_publishes_as_the_node_shuts_down_ends_quietly(monkeypatch, cycle):
    monkeypatch.setattr(rospy, "is_shutdown", lambda: True)
    assert quiet_at_shutdown(cycle)() is None


def test_a_value_error_while_the_node_runs_is_raised(monkeypatch):
    monkeypatch.setattr(rospy, "is_shutdown", lambda: False)
    with pytest.raises(ValueError, match="closed file"):
        quiet_at_shutdown(closed_buffer)()


def test_the_same_error_while_the_node_runs_is_raised(monkeypatch):
    monkeypatch.setattr(rospy, "is_shutdown", lambda: False)
    with pytest.raises(rospy.ROSException, match="closed topic"):
        quiet_at_shutdown(closed_topic)()


def test_a_cycle_gets_its_arguments_and_returns_its_result():
    assert quiet_at_shutdown(lambda event: event * 2)(21) == 42


# --- lookup_pose: the newest transform, never an old one ----------------------------------------

def _buffer_with(*transforms):
    import tf2_ros

    buffer = tf2_ros.Buffer(debug=False)
    for t in transforms:
        buffer.set_transform(t, "test")
    return buffer


def _transform(parent, child, stamp, x=0.0, y=0.0, yaw=0.0):
    import math

    from geometry_msgs.msg import TransformStamped

    t = TransformStamped()
    t.header.stamp = rospy.Time.from_sec(stamp)
    t.header.frame_id, t.child_frame_id = parent, child
    t.transform.translation.x, t.transform.translation.y = x, y
    t.transform.rotation.z, t.transform.rotation.w = math.sin(yaw / 2.0), math.cos(yaw / 2.0)
    return t


def test_lookup_pose_takes_the_newest_transform_through_the_chain():
    import math

    buffer = _buffer_with(_transform("map", "r/odom", 10.0, x=1.0), _transform("map", "r/odom", 10.1, x=1.0),
                          _transform("r/odom", "r/base_link", 10.0, y=2.0, yaw=0.5),
                          _transform("r/odom", "r/base_link", 10.05, y=2.0, yaw=0.5))
    pose, stamp = fleet_io.lookup_pose(buffer, "map", "r/base_link", rospy.Time.from_sec(10.1), 0.1)
    assert math.isclose(pose.x, 1.0) and math.isclose(pose.y, 2.0) and math.isclose(pose.theta, 0.5)
    assert math.isclose(stamp.to_sec(), 10.05)   # the newest time both links know


def test_lookup_pose_refuses_an_old_transform_and_an_unknown_frame():
    buffer = _buffer_with(_transform("map", "r/base_link", 10.0))
    with pytest.raises(fleet_io.StalePose, match=r"map -> r/base_link: newest transform is 0.15 s old \(limit 0.10"):
        fleet_io.lookup_pose(buffer, "map", "r/base_link", rospy.Time.from_sec(10.15), 0.1)
    with pytest.raises(fleet_io.StalePose, match="map -> q/base_link"):
        fleet_io.lookup_pose(buffer, "map", "q/base_link", rospy.Time.from_sec(10.0), 0.1)


class FakeWallClock(object):
    """A wall clock that moves only when the code under test sleeps; `at` runs a callback once
    the clock has passed a time (a message on its way)."""

    def __init__(self):
        self.now = 0.0
        self.pending = []

    def __call__(self):
        return self.now

    def at(self, t, callback):
        self.pending.append((t, callback))

    def sleep(self, seconds):
        self.now += seconds
        for item in [p for p in self.pending if p[0] <= self.now]:
            self.pending.remove(item)
            item[1]()


def test_lookup_pose_polls_in_wall_time_for_a_transform_on_its_way():
    buffer = _buffer_with(_transform("map", "r/base_link", 10.0))
    clock = FakeWallClock()
    clock.at(0.1, lambda: buffer.set_transform(_transform("map", "r/base_link", 10.2, x=3.0), "test"))
    pose, stamp = fleet_io.lookup_pose(buffer, "map", "r/base_link", rospy.Time.from_sec(10.2), 0.1, wall_wait=2.0,
                                       clock=clock, sleep=clock.sleep)
    assert pose.x == 3.0 and abs(stamp.to_sec() - 10.2) < 1e-6
    assert 0.1 <= clock.now < 0.11          # it returned at the first poll after the transform came
    clock = FakeWallClock()
    with pytest.raises(fleet_io.StalePose):   # nothing new comes: refused once the wait is over
        fleet_io.lookup_pose(buffer, "map", "r/base_link", rospy.Time.from_sec(11.0), 0.1, wall_wait=0.05,
                             clock=clock, sleep=clock.sleep)
    assert 0.05 <= clock.now < 0.06


def test_stale_scan_is_the_one_rule_of_the_follower_and_the_coordinator():
    assert fleet_io.stale_scan(10.0, 10.29, 0.3) is None
    assert fleet_io.stale_scan(10.0, 10.35, 0.3) == "newest scan is 0.35 s old (limit ~max_scan_age 0.30 s)"
    assert fleet_io.stale_scan(None, 10.0, 0.3) == "no scan yet"
    # listening since 9.9: no scan yet is not stale until max_age has passed since then
    assert fleet_io.stale_scan(None, 10.1, 0.3, since=9.9) is None
    assert fleet_io.stale_scan(None, 10.25, 0.3, since=9.9) == "no scan yet"


def test_the_follower_holds_still_and_counts_a_failure_on_an_old_pose(monkeypatch):
    """follower_node's cycle with only a 0.3 s old transform: no command but zero, state no_pose."""
    from mbot_follower import follower_node
    from mbot_follower.fleet_io import Assignment

    f = follower_node.FollowerController.__new__(follower_node.FollowerController)
    f._init_state()
    f.robot, f.fleet_state, f.paused = "follower_1", "NAVIGATING", False
    f.params.update({"max_pose_age": 0.1, "pose_wait": 0.0, "param_refresh": 1e9})
    f._last_param_read = rospy.Time.from_sec(10.0)
    f.assignment = Assignment("leader", "line", 1.5, {"leader": (0.0, 0.0), "follower_1": (0.0, -1.5)}, {})
    f.tf_buffer = _buffer_with(_transform("map", "leader/base_link", 10.0),
                               _transform("map", "follower_1/base_link", 10.0, y=-1.5))
    f.lookups = f.lookup_failures = 0
    sent, states = [], []
    f._send = sent.append
    f.filter = follower_node.CommandFilter(follower_node.ControllerConfig())
    f._publish_state = lambda now, mode, *args, **kwargs: states.append(mode)
    monkeypatch.setattr(rospy.Time, "now", staticmethod(lambda: rospy.Time.from_sec(10.3)))
    f._cycle(None)
    assert states == ["no_pose"] and (f.lookups, f.lookup_failures) == (1, 1)
    assert sent and all((c.vx, c.vy, c.wz) == (0.0, 0.0, 0.0) for c in sent)


# --- RobotTfListener: the poses of the robots a node needs, from the fleet tf relay -------------

class _Subscriptions(object):
    """rospy.Subscriber stand-in: which topics are subscribed now."""

    def __init__(self):
        self.topics = {}

    def __call__(self, topic, msg_class, callback, *args, **kwargs):
        sub = self

        class Sub(object):
            def unregister(self):
                del sub.topics[topic]
        self.topics[topic] = callback
        return Sub()


def test_the_robot_tf_listener_subscribes_only_the_robots_it_follows_and_lookups_see_them(monkeypatch):
    import tf2_ros
    from tf2_msgs.msg import TFMessage

    subs = _Subscriptions()
    monkeypatch.setattr(rospy, "Subscriber", subs)
    monkeypatch.setattr(rospy, "get_time", lambda: 10.0)
    buffer = tf2_ros.Buffer(debug=False)
    listener = fleet_io.RobotTfListener(buffer)
    listener.follow({"leader", "follower_1"})
    assert set(subs.topics) == {"/tf_static", "/leader/tf_pose", "/follower_1/tf_pose"}
    listener.follow({"leader", "follower_2"})      # a new assignment: follower_1 is no longer needed
    assert set(subs.topics) == {"/tf_static", "/leader/tf_pose", "/follower_2/tf_pose"}
    assert listener.robots() == {"leader", "follower_2"}

    subs.topics["/leader/tf_pose"](TFMessage([_transform("map", "leader/odom", 10.0, x=1.0),
                                              _transform("leader/odom", "leader/base_footprint", 10.0, x=2.0)]))
    subs.topics["/tf_static"](TFMessage([_transform("leader/base_footprint", "leader/base_link", 0.0)]))
    pose, stamp = fleet_io.lookup_pose(buffer, "map", "leader/base_link", rospy.Time.from_sec(10.05), 0.1)
    assert pose.x == pytest.approx(3.0) and stamp.to_sec() == pytest.approx(10.0)


def test_a_robot_followed_only_now_is_not_looked_up_until_its_poses_have_come_in_for_a_while(monkeypatch):
    import tf2_ros
    from tf2_msgs.msg import TFMessage

    subs = _Subscriptions()
    monkeypatch.setattr(rospy, "Subscriber", subs)
    clock = [10.0]
    monkeypatch.setattr(rospy, "get_time", lambda: clock[0])
    listener = fleet_io.RobotTfListener(tf2_ros.Buffer(debug=False))
    listener.follow({"leader"})
    assert not listener.warm({"leader"}, 10.0, 0.2)          # nothing came in yet
    subs.topics["/leader/tf_pose"](TFMessage([_transform("leader/odom", "leader/base_footprint", 10.0)]), "leader")
    clock[0] = 10.1
    assert not listener.warm({"leader"}, 10.1, 0.2)          # 0.1 s of poses: a post-dated map -> odom may lack
    assert listener.warm({"leader"}, 10.25, 0.2)
    listener.follow({"follower_1"})                          # dropped and followed again later: cold again
    listener.follow({"leader"})
    assert not listener.warm({"leader"}, 10.5, 0.2)


def test_the_robot_tf_listener_refuses_an_unknown_source():
    with pytest.raises(ValueError, match="expected relay or tf"):
        fleet_io.RobotTfListener(None, source="all")


def test_twist_between_two_odometry_poses_is_the_twist_in_the_robots_frame():
    from mbot_follower.fleet_io import twist_between

    # heading 90 deg, 0.01 m along +y in 0.02 s: 0.5 m/s forward
    assert twist_between((1.0, 2.0, math.pi / 2, 10.0), (1.0, 2.01, math.pi / 2, 10.02)) == pytest.approx(
        (0.5, 0.0, 0.0), abs=1e-9)
    # an omni robot facing +x moving along +y: sideways
    assert twist_between((0.0, 0.0, 0.0, 0.0), (0.0, 0.01, 0.0, 0.02)) == pytest.approx((0.0, 0.5, 0.0), abs=1e-9)
    # an arc: 1 rad/s at 0.5 m/s for 0.02 s (chord along the mean heading)
    w, v, dt = 1.0, 0.5, 0.02
    end = ((v / w) * math.sin(w * dt), (v / w) * (1.0 - math.cos(w * dt)), w * dt, dt)
    vx, vy, wz = twist_between((0.0, 0.0, 0.0, 0.0), end)
    assert wz == pytest.approx(1.0, abs=1e-9)
    assert math.hypot(vx, vy) == pytest.approx(v, rel=1e-4) and abs(vy) < 1e-6
    # across +-pi
    assert twist_between((0.0, 0.0, math.pi - 0.01, 0.0), (0.0, 0.0, -math.pi + 0.01, 0.02))[2] == pytest.approx(1.0)
    assert twist_between((0.0, 0.0, 0.0, 1.0), (1.0, 0.0, 0.0, 1.0)) is None   # same stamp
