#!/usr/bin/env python3
"""rostest: a user's move_base launch file (test/fixtures/move_base_config/move_base.launch, tutorial-style
parameter files for another robot, with navfn/NavfnROS and dwa_local_planner/DWAPlannerROS)
runs our `move_base` executable after one change, pkg="mbot_navigation"; robot_0 reaches a goal
through a door of the office."""
import math
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from nav_msgs.msg import Odometry

from nav_test_tools import Track, action_client, angle_diff, make_goal, run_goal, state_name

GOAL = (8.0, 3.0, math.pi / 2)


class MoveBaseDropIn(unittest.TestCase):
    def test_reaches_a_goal(self):
        track = Track("robot_0")
        speeds = []
        rospy.Subscriber("/robot_0/base_pose_ground_truth", Odometry,
                         lambda m: speeds.append(math.hypot(m.twist.twist.linear.x, m.twist.twist.linear.y)))
        client = action_client("robot_0")
        track.wait()
        state, text, seconds = run_goal(client, make_goal(*GOAL), timeout=150.0)
        self.assertEqual(state, GoalStatus.SUCCEEDED, "%s: %s" % (state_name(state), text))
        # The user's DWAPlannerROS/max_vel_x (0.45 m/s) is in force: the model alone allows 0.5.
        self.assertLess(max(speeds), 0.45 + 0.02, "drove at %.3f m/s" % max(speeds))
        self.assertGreater(max(speeds), 0.3, "drove at %.3f m/s at most" % max(speeds))
        x, y, yaw = track.pose
        # the user's xy_goal_tolerance / yaw_goal_tolerance: 0.15
        self.assertLess(math.hypot(x - GOAL[0], y - GOAL[1]), 0.15 + 0.02, track.pose)
        self.assertLess(angle_diff(yaw, GOAL[2]), 0.15 + 0.02, track.pose)


if __name__ == "__main__":
    rospy.init_node("nav_move_base_dropin_test")
    rostest.rosrun("mbot_navigation", "nav_move_base_dropin", MoveBaseDropIn)
