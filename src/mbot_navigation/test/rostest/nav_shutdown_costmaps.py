#!/usr/bin/env python3
"""rostest: shutdown_costmaps (nav_shutdown_costmaps.test). robot_0's nav node subscribes none of
the streams that feed its costmaps while it has no goal, wakes for a goal, for make_plan and for
move_base_simple/goal, sees a crate that only its laser sees once woken, and sleeps again after."""
import math
import time
import unittest

import rosgraph
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from move_base_msgs.msg import MoveBaseActionResult
from nav_msgs.msg import OccupancyGrid
from nav_msgs.srv import GetPlan

from nav_test_tools import Contacts, Track, action_client, make_goal, state_name, wait_until

ROBOT = "robot_0"
NODE = "/robot_0/move_base"
# What a sleeping node leaves (the costmaps' and the controller's inputs), and what it keeps.
STREAMS = ("/tf", "/tf_static", "/robot_0/scan", "/robot_0/odom", "/robot_1/base_pose_ground_truth")
KEPT = ("/robot_0/move_base/goal", "/robot_0/move_base/cancel", "/robot_0/move_base_simple/goal", "/map")
FIRST_GOAL = (8.6, -8.6, 0.0)       # the crate (7.5, -7.5) stands on the straight line to it
SECOND_GOAL = (3.0, -3.0, math.pi / 2)
WALL = (0.25, -3.0)                 # the wall west of the room (within 0.25 m)


def subscriptions(node):
    """The topics that `node` subscribes, as the master has them."""
    _, subscribers, _ = rosgraph.Master("/nav_shutdown_costmaps_test").getSystemState()
    return {topic for topic, nodes in subscribers if node in nodes}


def asleep():
    topics = subscriptions(NODE)
    return not topics.intersection(STREAMS) and topics.issuperset(KEPT)


def awake():
    return subscriptions(NODE).issuperset(STREAMS)


def wait_wall(predicate, timeout, what):
    """Wait in wall time: subscriptions change in wall time, whatever sim time does."""
    deadline = time.time() + timeout
    while not predicate():
        if rospy.is_shutdown() or time.time() > deadline:
            raise AssertionError("%s: not after %.0f s wall (subscriptions: %s)"
                                 % (what, timeout, sorted(subscriptions(NODE))))
        time.sleep(0.05)


class ShutdownCostmaps(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.track = Track(ROBOT)
        cls.contacts = Contacts([ROBOT])
        cls.client = action_client(ROBOT)
        cls.track.wait()

    def test_1_sleeps_while_idle(self):
        wait_wall(asleep, 30.0, "robot_0's nav node asleep")
        # robot_1's node, with the shipped settings, stays awake as move_base does (once up: its
        # process may start later than robot_0's on a busy machine).
        action_client("robot_1")
        mate = subscriptions("/robot_1/move_base")
        self.assertTrue(mate.issuperset(("/tf", "/robot_1/scan", "/robot_1/odom")), sorted(mate))
        # A sleeping node's costmap still goes to a new subscriber at once, with the map's walls.
        grid = rospy.wait_for_message(NODE + "/global_costmap/costmap", OccupancyGrid, timeout=10.0)
        col = int((WALL[0] - grid.info.origin.position.x) / grid.info.resolution)
        row = int((WALL[1] - grid.info.origin.position.y) / grid.info.resolution)
        around = [grid.data[r * grid.info.width + c] for r in range(row - 5, row + 6) for c in range(col - 5, col + 6)]
        self.assertEqual(max(around), 100)
        self.assertTrue(asleep())

    def test_2_make_plan_while_asleep(self):
        wait_wall(asleep, 30.0, "robot_0's nav node asleep")
        rospy.wait_for_service(NODE + "/make_plan", timeout=10.0)
        goal = make_goal(6.0, -2.0).target_pose
        make_plan = rospy.ServiceProxy(NODE + "/make_plan", GetPlan)
        plan = make_plan(start=PoseStamped(), goal=goal, tolerance=0.0).plan
        self.assertGreater(len(plan.poses), 10)
        x, y, _ = self.track.pose
        first, last = plan.poses[0].pose.position, plan.poses[-1].pose.position
        self.assertLess(math.hypot(first.x - x, first.y - y), 0.2, "plan starts at (%.2f, %.2f)" % (first.x, first.y))
        self.assertLess(math.hypot(last.x - 6.0, last.y + 2.0), 0.1)
        wait_wall(asleep, 10.0, "robot_0's nav node asleep again after make_plan")

    def test_3_goal_wakes_it_and_its_laser_counts(self):
        wait_wall(asleep, 30.0, "robot_0's nav node asleep")
        x, y, yaw = FIRST_GOAL
        start = rospy.Time.now()
        self.client.send_goal(make_goal(x, y, yaw))
        wait_until(lambda: self.client.get_state() == GoalStatus.ACTIVE, 5.0, "the goal accepted")
        rospy.loginfo("goal active %.2f sim s after it was sent", (rospy.Time.now() - start).to_sec())
        wait_wall(awake, 10.0, "robot_0's nav node awake with a goal")
        self.assertTrue(self.client.wait_for_result(rospy.Duration(150.0)), "no result in 150 sim s")
        self.assertEqual(self.client.get_state(), GoalStatus.SUCCEEDED,
                         "%s: %s" % (state_name(self.client.get_state()), self.client.get_goal_status_text()))
        pose = self.track.pose_since(rospy.Time.now().to_sec())
        self.assertLess(math.hypot(pose[0] - x, pose[1] - y), 0.15, "stopped at %s" % (pose,))
        # The crate is not in the map: without its laser the robot would have driven into it.
        self.assertEqual(self.contacts.events, [])
        wait_wall(asleep, 10.0, "robot_0's nav node asleep again after its goal")

    def test_4_simple_goal_wakes_it(self):
        wait_wall(asleep, 30.0, "robot_0's nav node asleep")
        results = []
        rospy.Subscriber(NODE + "/result", MoveBaseActionResult, results.append)
        pub = rospy.Publisher("/%s/move_base_simple/goal" % ROBOT, PoseStamped, queue_size=1)
        wait_wall(lambda: pub.get_num_connections() > 0, 10.0, "a connection to move_base_simple/goal")
        x, y, yaw = SECOND_GOAL
        pub.publish(make_goal(x, y, yaw).target_pose)
        wait_until(lambda: results, 150.0, "the simple goal's result")
        self.assertEqual(results[0].status.status, GoalStatus.SUCCEEDED, results[0].status.text)
        pose = self.track.pose_since(rospy.Time.now().to_sec())
        self.assertLess(math.hypot(pose[0] - x, pose[1] - y), 0.15, "stopped at %s" % (pose,))
        self.assertEqual(self.contacts.events, [])
        wait_wall(asleep, 10.0, "robot_0's nav node asleep again")


if __name__ == "__main__":
    rospy.init_node("nav_shutdown_costmaps_test")
    rostest.rosrun("mbot_navigation", "nav_shutdown_costmaps", ShutdownCostmaps)
