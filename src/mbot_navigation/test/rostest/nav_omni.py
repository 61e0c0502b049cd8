#!/usr/bin/env python3
"""rostest: robot_0 is an mbot_omni (test/fixtures/worlds/nav_omni.world.yaml). A goal 1 m to its left with
the same heading is reached, partly driving sideways: the ground truth shows a lateral velocity,
which a differential robot never has. (How far it turns on the way is logged, not asserted: the
DWA turns the omni robot well away from its heading, up to 2.3 rad, on the way to this goal.)"""
import math
import threading
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from nav_msgs.msg import Odometry

from mbot_common.geometry import yaw_of
from nav_test_tools import Track, action_client, angle_diff, make_goal, run_goal, state_name

ROBOT = "robot_0"
START = (3.0, -4.0, 0.0)  # the world file's
GOAL = (3.0, -3.0, 0.0)   # 1 m to the robot's left, same heading


class Motion(object):
    """The robot's ground-truth yaw and body-frame velocity, every sample."""

    def __init__(self):
        self._lock = threading.Lock()
        self.samples = []  # (stamp [s], yaw [rad], vx, vy [m/s])
        rospy.Subscriber("/%s/base_pose_ground_truth" % ROBOT, Odometry, self._on_odom, queue_size=100)

    def _on_odom(self, msg):
        q, v = msg.pose.pose.orientation, msg.twist.twist.linear
        yaw = yaw_of(q)
        with self._lock:
            self.samples.append((msg.header.stamp.to_sec(), yaw, v.x, v.y))

    def since(self, t):
        with self._lock:
            return [s for s in self.samples if s[0] >= t]


class NavOmni(unittest.TestCase):
    def test_sideways_goal(self):
        track = Track(ROBOT)
        motion = Motion()
        client = action_client(ROBOT)
        x0, y0, yaw0 = track.wait()
        self.assertLess(math.hypot(x0 - START[0], y0 - START[1]), 0.05, (x0, y0))
        start = rospy.get_time()
        state, text, seconds = run_goal(client, make_goal(*GOAL), 60.0)
        self.assertEqual(state, GoalStatus.SUCCEEDED, "%s: %s" % (state_name(state), text))
        x, y, yaw = track.pose
        self.assertLess(math.hypot(x - GOAL[0], y - GOAL[1]), 0.15, track.pose)
        self.assertLess(angle_diff(yaw, GOAL[2]), 0.15, track.pose)
        samples = motion.since(start)
        worst_turn = max(angle_diff(s[1], yaw0) for s in samples)
        most_sideways = max(s[3] for s in samples)
        rospy.loginfo("nav_omni: %.1f sim s, lateral speed up to %.2f m/s, heading off the start by up to %.2f rad",
                      seconds, most_sideways, worst_turn)
        # The goal is to the left: sideways at a good part of max_vel_y (0.4 m/s).
        self.assertGreater(most_sideways, 0.2)


if __name__ == "__main__":
    rospy.init_node("nav_omni_test")
    rostest.rosrun("mbot_navigation", "nav_omni", NavOmni)
