"""The coordinator node's wait for overdue robots under lockstep (no master needed: the node is
built without its ROS connections, and the poses come from a stand-in for tf)."""
import threading
import time

import rospy

from mbot_follower.coordinator import FleetCoordinator
from mbot_follower.coordinator_node import NODE_PARAMS, CoordinatorNode, _age

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
    n._look_up_poses = lambda now_ros: {}
    return n


def timed_wait(n):
    started = time.time()
    n._wait_for_overdue(rospy.Time.from_sec(NOW), "robot_0", {})
    return time.time() - started


def deliver_later(n, robot, delay):
    def late():
        time.sleep(delay)
        n.last_heard_controller[robot] = NOW

    thread = threading.Thread(target=late)
    thread.start()
    return thread


def test_a_late_message_that_arrives_within_the_wait_ends_it_and_the_robot_is_not_overdue():
    n = node()
    thread = deliver_later(n, "robot_1", 0.15)
    elapsed = timed_wait(n)
    thread.join()
    assert 0.15 <= elapsed < WAIT - 0.1
    assert n._overdue(NOW, "robot_0") == set()


def test_a_silent_robot_is_waited_for_once_and_again_after_it_was_heard():
    n = node()
    assert timed_wait(n) >= WAIT                    # silent: the whole wait
    assert n._overdue(NOW, "robot_0") == {"robot_1"}   # still overdue: the loss follows
    assert timed_wait(n) < 0.05                     # the next cycles do not wait for it again
    n.last_heard_controller["robot_1"] = NOW        # heard again ...
    assert timed_wait(n) < 0.05
    n.last_heard_controller["robot_1"] = NOW - 1.5  # ... and silent again: a new wait
    assert timed_wait(n) >= WAIT


def test_no_wait_without_lockstep_or_before_the_start():
    assert timed_wait(node(lockstep=False)) < 0.05   # sim time would run on: waiting helps nothing
    n = node()
    n._startup_done = False                          # robots still coming up are not late
    assert timed_wait(n) < 0.05


def test_a_lost_robot_is_not_waited_for():
    n = node()
    n.core.members.remove("robot_1")
    n.core.lost.append("robot_1")
    assert timed_wait(n) < 0.05


def test_the_loss_log_gives_no_negative_ages():
    # a pose stamped after the cycle read its clock is current, not -0.25 s old
    assert (_age(100.25, 100.0), _age(98.9, 100.0), _age(None, 100.0)) == (0.0, 100.0 - 98.9, float("inf"))
