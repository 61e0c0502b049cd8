"""FleetProbe's samples pair the robots' ground truth of one instant (aligned), not each
robot's newest message: a loaded test process runs the callbacks late and in any order. Its
wait for the fleet subscribes again to a topic that stays silent."""
import collections

import rospy

from mbot_common.geometry import Pose2D
from mbot_follower.fleet_probe import SILENT_AFTER, aligned


def history(stamps, x0=0.0, speed=0.35):
    """A robot driving along x at `speed`: (t, pose, speed) at each stamp."""
    return collections.deque((t, Pose2D(x0 + speed * t, 0.0, 0.0), speed) for t in stamps)


def test_the_robots_are_taken_at_the_newest_instant_all_of_them_have():
    steps = [round(0.02 * k, 2) for k in range(60)]
    histories = {"leader": history(steps), "follower": history(steps[:35], x0=-1.5)}  # 0.5 s behind
    sample = aligned(histories)
    assert sample["leader"][0] == sample["follower"][0] == steps[34]
    # the distance the fleet really had, not the leader's newest pose against an old follower's
    assert abs(sample["leader"][1].x - sample["follower"][1].x - 1.5) < 1e-9


def test_a_gap_in_one_history_takes_its_newest_entry_before_that_instant():
    histories = {"a": history([0.0, 0.02, 0.04, 0.06]), "b": history([0.0, 0.06, 0.08])}
    assert aligned(histories)["a"][0] == 0.06
    histories = {"a": history([0.0, 0.02, 0.04, 0.08]), "b": history([0.0, 0.06])}
    assert aligned(histories)["a"][0] == 0.04


def test_a_silent_robot_keeps_its_last_pose_and_does_not_hold_the_others_back():
    live = [round(0.02 * k, 2) for k in range(100)]
    histories = {"a": history(live), "b": history(live), "removed": history([0.0, 0.02])}
    sample = aligned(histories)
    assert sample["a"][0] == sample["b"][0] == live[-1]
    assert sample["removed"][0] == 0.02 and live[-1] - 0.02 > SILENT_AFTER
    assert aligned({}) == {} and aligned({"a": collections.deque()}) == {}


class FakeRospy(object):
    """Subscribers that deliver one message as they are made, except the first `stuck[topic]`
    subscriptions to a topic (a connection that never formed)."""

    def __init__(self, stuck):
        self.stuck = stuck
        self.made = collections.Counter()

    def subscriber(self, topic, kind, callback, callback_args=None, queue_size=None, tcp_nodelay=False):
        from unittest import mock
        self.made[topic] += 1
        if self.made[topic] <= self.stuck.get(topic, 0):
            return mock.Mock()
        msg = kind()
        msg.header.stamp = rospy.Time(1.0)
        if hasattr(msg, "pose"):
            msg.pose.pose.orientation.w = 1.0
        if hasattr(msg, "robots"):   # the fleet's ground truth: robots a and b
            from mbot_msgs.msg import RobotState
            msg.robots = [RobotState(name=r, stamp=rospy.Time(1.0)) for r in ("a", "b")]
        if callback_args is None:
            callback(msg)
        else:
            callback(msg, callback_args)
        return mock.Mock()


def test_wait_for_fleet_subscribes_again_to_what_stays_silent(monkeypatch):
    from unittest import mock

    import mbot_follower.fleet_probe as fp
    import mbot_navigation.move_base_client as mbc

    # the fleet's ground truth, and b's controller state for the probe's and the wait's own subscriber
    fake = FakeRospy(stuck={"/stage/ground_truth": 1, "/b/follower_controller/state": 2})
    monkeypatch.setattr(rospy, "Subscriber", fake.subscriber)
    monkeypatch.setattr(rospy, "Publisher", mock.Mock())
    monkeypatch.setattr(rospy, "Timer", mock.Mock())
    monkeypatch.setattr(rospy, "is_shutdown", lambda: False)
    monkeypatch.setattr(mbc, "connect_move_base", lambda robot, timeout: None)
    monkeypatch.setattr(fp, "RESUBSCRIBE_AFTER", 0.2)
    probe = fp.FleetProbe(["a", "b"])
    assert sorted(probe.truth) == []
    probe.wait_for_fleet(wall_timeout=5.0)
    assert sorted(probe.truth) == ["a", "b"]
    assert fake.made["/stage/ground_truth"] == 2 and not fake.made["/a/base_pose_ground_truth"]
    assert fake.made["/b/follower_controller/state"] == 4 and fake.made["/a/follower_controller/state"] == 2
