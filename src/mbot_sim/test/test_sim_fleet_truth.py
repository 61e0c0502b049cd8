#!/usr/bin/python3
"""rostest (sim_fleet_truth.test): stage_node's /stage/ground_truth (mbot_msgs/RobotStates) holds,
for each step that took ground truth, every robot's pose and twist, equal to what the robot's own
/<robot>/base_pose_ground_truth carries at that stamp, while robot_0 drives a curve; one message
per step (50 Hz), stamped with the step. Lockstep with this node as its pacer: on a busy machine
the simulator would otherwise run ahead of it and its publishers drop what this node has not read."""
import math
import sys
import unittest

import rospy
import rostest
from geometry_msgs.msg import Twist
from mbot_msgs.msg import RobotStates
from nav_msgs.msg import Odometry

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import keep_pace, Recorder, wait_for_connection, wait_until  # noqa: E402

ROBOTS = ["robot_0", "robot_1", "robot_2"]


def yaw(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class FleetTruth(unittest.TestCase):
    def test_one_message_per_step_with_every_robots_ground_truth(self):
        rospy.init_node("test_sim_fleet_truth")
        keep_pace()
        fleet = Recorder("/stage/ground_truth", RobotStates)
        own = {r: Recorder("/%s/base_pose_ground_truth" % r, Odometry) for r in ROBOTS}
        cmd = rospy.Publisher("/robot_0/cmd_vel", Twist, queue_size=1)
        wait_for_connection(cmd)
        t0 = rospy.get_time()
        drive = Twist()
        drive.linear.x, drive.angular.z = 0.4, 0.5
        while rospy.get_time() < t0 + 2.0 and not rospy.is_shutdown():
            cmd.publish(drive)
            rospy.sleep(0.05)
        wait_until(lambda: len(fleet.since(t0 + 0.5)) >= 50, 10.0, "50 /stage/ground_truth messages")
        messages = [m for m in fleet.since(t0 + 0.5)]
        stamps = [m.header.stamp.to_sec() for m in messages]
        gaps = [b - a for a, b in zip(stamps, stamps[1:])]
        self.assertTrue(all(abs(g - 0.02) < 1e-6 for g in gaps), "not one message per 0.02 s step: %s" % gaps[:10])
        by_stamp = {r: {m.header.stamp.to_sec(): m for m in own[r].since(t0)} for r in ROBOTS}
        compared = 0
        for m in messages:
            self.assertEqual(m.header.frame_id, "map")
            self.assertEqual(sorted(s.name for s in m.robots), ROBOTS)
            for s in m.robots:
                self.assertEqual(s.stamp, m.header.stamp)
                o = by_stamp[s.name].get(s.stamp.to_sec())
                if o is None:
                    continue
                p = o.pose.pose
                self.assertAlmostEqual(s.pose.x, p.position.x, places=9)
                self.assertAlmostEqual(s.pose.y, p.position.y, places=9)
                self.assertAlmostEqual(math.cos(s.pose.theta - yaw(p.orientation)), 1.0, places=9)
                self.assertEqual((s.twist.linear.x, s.twist.linear.y, s.twist.angular.z),
                                 (o.twist.twist.linear.x, o.twist.twist.linear.y, o.twist.twist.angular.z))
                compared += 1
        self.assertGreater(compared, 100)
        moving = [s for m in messages for s in m.robots if s.name == "robot_0" and s.twist.linear.x > 0.3]
        self.assertTrue(moving, "robot_0 never showed its drive in the fleet's ground truth")


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_fleet_truth", FleetTruth)
