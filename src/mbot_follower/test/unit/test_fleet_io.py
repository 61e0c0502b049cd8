"""The ROS-side helpers the nodes share (fleet_io.py) that run without a master."""
import pytest
import rospy

from mbot_follower.fleet_io import quiet_at_shutdown


def closed_topic():
    raise rospy.ROSException("publish() to a closed topic")


def test_a_cycle_that_publishes_as_the_node_shuts_down_ends_quietly(monkeypatch):
    monkeypatch.setattr(rospy, "is_shutdown", lambda: True)
    assert quiet_at_shutdown(closed_topic)() is None


def test_the_same_error_while_the_node_runs_is_raised(monkeypatch):
    monkeypatch.setattr(rospy, "is_shutdown", lambda: False)
    with pytest.raises(rospy.ROSException, match="closed topic"):
        quiet_at_shutdown(closed_topic)()


def test_a_cycle_gets_its_arguments_and_returns_its_result():
    assert quiet_at_shutdown(lambda event: event * 2)(21) == 42
