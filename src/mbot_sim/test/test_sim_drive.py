#!/usr/bin/python3
"""rostest (sim_drive.test): a 0.5 m/s command in force for 2 s of sim time drives robot_0 1.0 m
(within 3%): 0.5 s ramp up + 1.5 s at 0.5 m/s + 0.5 s ramp down at 1 m/s^2.

The 2 s are timed by the simulator, not by this process: sim_drive.test sets stage_node's
~base_watchdog_timeout to 2.0 s and the test sends ONE command, which the watchdog ends after
exactly 2 s of sim time. (Streaming commands for 2 s and then a stop from a test process makes
the distance depend on how promptly that process runs on a busy machine: a 0.2 s stall is 0.1 m.)
"""
import math
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import keep_pace, Recorder, wait_for_connection, wait_until  # noqa: E402


class SimDrive(unittest.TestCase):
    def test_command_for_two_seconds_drives_one_meter(self):
        rospy.init_node("test_sim_drive")
        self.pacer = keep_pace()
        self.assertEqual(rospy.get_param("/stage_node/base_watchdog_timeout"), 2.0)
        truth = Recorder("/robot_0/base_pose_ground_truth", Odometry)
        odom = Recorder("/robot_0/odom", Odometry)
        pub = rospy.Publisher("/robot_0/cmd_vel", Twist, queue_size=1, latch=True)
        truth.wait_for_first()
        odom.wait_for_first()
        wait_for_connection(pub)
        p0 = truth.latest().pose.pose.position

        cmd = Twist()
        cmd.linear.x = 0.5
        pub.publish(cmd)
        speed = lambda: truth.latest().twist.twist.linear.x  # noqa: E731
        wait_until(lambda: speed() > 0.4, 5.0, "robot_0 to start")
        wait_until(lambda: abs(speed()) < 1e-9, 10.0, "robot_0 to stop")
        rospy.sleep(0.5)

        p1 = truth.latest().pose.pose.position
        distance = math.hypot(p1.x - p0.x, p1.y - p0.y)
        print("drove %.4f m" % distance)
        self.assertAlmostEqual(distance, 1.0, delta=0.03, msg="drove %.3f m" % distance)
        # how long it cruised at full speed: 2 s command - 0.5 s ramp up = 1.5 s
        cruise = [m.header.stamp.to_sec() for m in truth.stamped_after(0.0) if m.twist.twist.linear.x > 0.5 - 1e-9]
        self.assertAlmostEqual(cruise[-1] - cruise[0], 1.5, delta=0.03)
        # odometry saw the same motion (this world has no odometry noise)
        o = odom.latest().pose.pose.position
        self.assertAlmostEqual(math.hypot(o.x, o.y), distance, delta=0.005)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_drive", SimDrive, sys.argv)
