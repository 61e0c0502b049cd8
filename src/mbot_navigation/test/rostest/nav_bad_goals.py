#!/usr/bin/env python3
"""rostest: bad goals are ABORTED at once with the reason, good goals around them still succeed,
goals in other frames are transformed, and preemption (new goal, cancel) works."""
import math
import unittest

import actionlib
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from move_base_msgs.msg import MoveBaseAction
from nav_msgs.msg import Odometry

from nav_test_tools import Track, action_client, angle_diff, make_goal, run_goal, state_name, wait_until

# [sim s] a rejected goal's result comes within this: well under planner_patience (5 s, then
# recoveries), which a goal that was tried would take; the rest is this process's latency while
# sim time runs on at 5x (an idle robot does not hold lockstep).
AT_ONCE = 2.5


class BadGoals(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.robot = rospy.get_param("~robot")
        cls.track = Track(cls.robot)
        cls.client = action_client(cls.robot)
        cls.track.wait()
        cls.speed = [0.0]
        rospy.Subscriber("/%s/odom" % cls.robot, Odometry,
                         lambda m: cls.speed.__setitem__(0, abs(m.twist.twist.linear.x) + abs(m.twist.twist.angular.z)))

    def driving(self, client):
        """The client's goal is active and the robot moves (it may still be moving from before)."""
        return client.get_state() == GoalStatus.ACTIVE and self.speed[0] > 0.05

    def assert_rejected(self, goal, text):
        start = self.track.pose
        state, status_text, seconds = run_goal(self.client, goal, timeout=10.0)
        self.assertEqual(state, GoalStatus.ABORTED, "%s: %s" % (state_name(state), status_text))
        self.assertEqual(status_text[:len(text)], text)
        self.assertLess(seconds, AT_ONCE)
        self.assertLess(math.hypot(self.track.pose[0] - start[0], self.track.pose[1] - start[1]), 0.02)
        return status_text

    def assert_reached(self, goal, x, y, yaw, timeout=90.0):
        state, text, seconds = run_goal(self.client, goal, timeout)
        self.assertEqual(state, GoalStatus.SUCCEEDED, "%s: %s" % (state_name(state), text))
        pose = self.track.pose
        self.assertLess(math.hypot(pose[0] - x, pose[1] - y), 0.15, "stopped at %s, goal (%.2f, %.2f)" % (pose, x, y))
        self.assertLess(angle_diff(pose[2], yaw), 0.15, "stopped at %s" % (pose,))

    def test_1_wall_then_good_goal(self):
        # (3, 1.07) is in the wall between the south-east room and the corridor.
        text = self.assert_rejected(make_goal(3.0, 1.07), "goal is in an obstacle")
        self.assertIn("(3.00, 1.07)", text)
        self.assert_reached(make_goal(4.0, -2.5, 1.0), 4.0, -2.5, 1.0)

    def test_2_nan_frame_outside_quaternion(self):
        self.assert_rejected(make_goal(float("nan"), 1.0), "goal has a NaN coordinate")
        nan_q = make_goal(2.0, -3.0)
        nan_q.target_pose.pose.orientation.w = float("nan")
        self.assert_rejected(nan_q, "goal has a NaN coordinate")
        self.assert_rejected(make_goal(1.0, 1.0, frame="foo"), "goal frame 'foo' is unknown to tf")
        self.assert_rejected(make_goal(12.0, 3.0), "goal (12.00, 3.00) is outside the map [-10, 10] x [-10, 10]")
        half = make_goal(2.0, -3.0)
        half.target_pose.pose.orientation.w = 0.5
        self.assert_rejected(half, "goal orientation is not a unit quaternion (norm 0.50)")
        # ... and the node still serves a good goal.
        self.assert_reached(make_goal(2.0, -5.0, -1.5), 2.0, -5.0, -1.5)

    def test_3_goal_in_the_robot_frame(self):
        # 1 m ahead of the robot, turned by 90 degrees: tf2 puts it into the map.
        x0, y0, yaw0 = self.track.pose
        goal = make_goal(1.0, 0.0, math.pi / 2, frame="%s/base_footprint" % self.robot)
        self.assert_reached(goal, x0 + math.cos(yaw0), y0 + math.sin(yaw0), yaw0 + math.pi / 2)

    def test_4_new_goal_preempts_and_cancel_stops(self):
        other = actionlib.SimpleActionClient(self.robot + "/move_base", MoveBaseAction)
        self.assertTrue(other.wait_for_server(rospy.Duration(30.0)))
        self.client.send_goal(make_goal(-5.0, -5.0))
        wait_until(lambda: self.driving(self.client), 10.0, "the robot to drive toward (-5, -5)")
        other.send_goal(make_goal(3.0, -3.0, 0.0))
        self.assertTrue(self.client.wait_for_result(rospy.Duration(5.0)))
        self.assertEqual(self.client.get_state(), GoalStatus.PREEMPTED, self.client.get_goal_status_text())
        self.assertTrue(other.wait_for_result(rospy.Duration(90.0)))
        self.assertEqual(other.get_state(), GoalStatus.SUCCEEDED, other.get_goal_status_text())

        self.client.send_goal(make_goal(-5.0, -5.0))
        wait_until(lambda: self.driving(self.client), 10.0, "the robot to drive toward (-5, -5) again")
        self.client.cancel_goal()
        self.assertTrue(self.client.wait_for_result(rospy.Duration(5.0)))
        self.assertEqual(self.client.get_state(), GoalStatus.PREEMPTED, self.client.get_goal_status_text())
        wait_until(lambda: self.speed[0] < 0.01, 2.0, "the robot to stop after the cancel")

        # a cancel right behind its goal, before the node's next cycle accepted it: the goal ends
        # without the robot driving (it drove to the cancelled goal when the node missed this)
        start = self.track.pose
        self.client.send_goal(make_goal(-5.0, -5.0))
        self.client.cancel_goal()
        self.assertTrue(self.client.wait_for_result(rospy.Duration(5.0)), "the cancelled goal did not end")
        # LOST: the node's status came before it had the goal (the goal and the cancel travel on
        # separate topics), and the client stops tracking it; whether the robot stays is what counts
        self.assertIn(self.client.get_state(), (GoalStatus.PREEMPTED, GoalStatus.RECALLED, GoalStatus.LOST),
                      "%s: %s" % (state_name(self.client.get_state()), self.client.get_goal_status_text()))
        rospy.sleep(2.0)   # [sim s] time enough to set off, had the goal been taken
        moved = math.hypot(self.track.pose[0] - start[0], self.track.pose[1] - start[1])
        self.assertLess(moved, 0.05, "the robot drove %.2f m after the cancel" % moved)


if __name__ == "__main__":
    rospy.init_node("nav_bad_goals_test")
    rostest.rosrun("mbot_navigation", "nav_bad_goals", BadGoals)
