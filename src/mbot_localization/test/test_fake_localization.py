#!/usr/bin/env python3
"""rostest for fake_localization: this node plays the simulator.

It publishes /clock, /<robot>/base_pose_ground_truth and /<robot>/odom with equal stamps (in
both orders, and with the robot and its odometry drift moving every step, so that pairing the
wrong samples shows), then checks for every stamp t that tf map -> <robot>/odom at
t + transform_tolerance equals T_map_base(gt, t) * inverse(T_odom_base(odom, t)) within 1e-6,
and that amcl_pose is the ground truth. With ~tf_publish_rate > 0 the node publishes the
transform of every stamp at least 1/rate after the last one it published (on this 50 Hz grid at
10 Hz: every 5th), and amcl_pose still for every stamp.
"""
import unittest

import numpy as np
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from tf2_msgs.msg import TFMessage

from mbot_common.geometry import angle_diff, quaternion_from_yaw, yaw_of
from mbot_common.waits import wait_for_wall as wait_for  # these tests publish /clock themselves

PKG = "mbot_localization"
STEPS = 25
STEP_NS = 20 * 1000 * 1000  # 50 Hz
START_NS = 100 * 1000 * 1000 * 1000  # t = 100 s


def stamp(ns):
    return rospy.Time(ns // 10**9, ns % 10**9)


def homogeneous(x, y, z, q):
    """4x4 transform from a translation and a quaternion (x, y, z, w)."""
    qx, qy, qz, qw = q
    rotation = np.array([
        [1 - 2 * (qy * qy + qz * qz), 2 * (qx * qy - qz * qw), 2 * (qx * qz + qy * qw)],
        [2 * (qx * qy + qz * qw), 1 - 2 * (qx * qx + qz * qz), 2 * (qy * qz - qx * qw)],
        [2 * (qx * qz - qy * qw), 2 * (qy * qz + qx * qw), 1 - 2 * (qx * qx + qy * qy)]])
    m = np.eye(4)
    m[:3, :3] = rotation
    m[:3, 3] = (x, y, z)
    return m


def ground_truth(k):
    """The robot in the map: drives and turns across the +-pi seam."""
    return 2.0 + 0.05 * k, -1.0 + 0.002 * k * k, 2.8 + 0.05 * k


def odometry(k):
    """The robot in its odom frame: drifts away from the truth a little more every step."""
    return 0.06 * k, 0.01 * k, 0.3 + 0.045 * k


class FakeLocalizationTest(unittest.TestCase):
    def setUp(self):
        self.robot = rospy.get_param("~robot")
        self.tolerance_ns = int(round(rospy.get_param("~transform_tolerance") * 1e9))
        self.every = rospy.get_param("~every")   # the node publishes tf for every this many steps
        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.odom_pub = rospy.Publisher("/%s/odom" % self.robot, Odometry, queue_size=100)
        self.truth_pub = rospy.Publisher("/%s/base_pose_ground_truth" % self.robot, Odometry,
                                         queue_size=100)
        self.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(600))
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.poses = []
        self.pose_sub = rospy.Subscriber("/%s/amcl_pose" % self.robot, PoseWithCovarianceStamped,
                                         self.poses.append)
        self.tf_stamps = []
        self.tf_probe = rospy.Subscriber("/tf", TFMessage, self.on_tf)  # shares the listener's link

    def on_tf(self, msg):
        self.tf_stamps += [t.header.stamp for t in msg.transforms if t.child_frame_id == self.robot + "/odom"]

    def publish(self, publisher, k, frame, child, pose):
        msg = Odometry()
        msg.header.stamp = stamp(START_NS + k * STEP_NS)
        msg.header.frame_id = frame
        msg.child_frame_id = child
        msg.pose.pose.position.x, msg.pose.pose.position.y = pose[0], pose[1]
        q = quaternion_from_yaw(pose[2])
        o = msg.pose.pose.orientation
        o.x, o.y, o.z, o.w = q
        publisher.publish(msg)

    def test_tf_is_ground_truth_times_inverse_odometry(self):
        for pub in (self.odom_pub, self.truth_pub, self.clock_pub):
            wait_for(lambda: pub.get_num_connections() > 0, 30, "a subscriber on " + pub.name)
        wait_for(lambda: self.tf_probe.get_num_connections() > 0, 30, "the /tf publisher")
        wait_for(lambda: self.pose_sub.get_num_connections() > 0, 30, "the amcl_pose publisher")

        odom_frame = self.robot + "/odom"
        base_frame = self.robot + "/base_footprint"
        for k in range(STEPS):
            self.clock_pub.publish(Clock(clock=stamp(START_NS + k * STEP_NS)))
            # both arrival orders: odometry before its ground truth and after it
            if k % 2 == 0:
                self.publish(self.odom_pub, k, odom_frame, base_frame, odometry(k))
                self.publish(self.truth_pub, k, "map", base_frame, ground_truth(k))
            else:
                self.publish(self.truth_pub, k, "map", base_frame, ground_truth(k))
                self.publish(self.odom_pub, k, odom_frame, base_frame, odometry(k))
            # One step at a time, as a simulator in lockstep: the node's amcl_pose queue holds 2
            # messages (as amcl's), so a starved test process would lose some of a burst.
            wait_for(lambda: len(self.poses) > k, 30, "amcl_pose of step %d" % k)

        worst = 0.0
        published = [k for k in range(STEPS) if k % self.every == 0]
        expected_stamps = [stamp(START_NS + k * STEP_NS + self.tolerance_ns) for k in published]
        wait_for(lambda: len(self.tf_stamps) >= len(published), 30, "%d tf samples" % len(published))
        self.assertEqual(self.tf_stamps, expected_stamps)
        for k in published:
            when = stamp(START_NS + k * STEP_NS + self.tolerance_ns)
            wait_for(lambda: self.buffer.can_transform("map", odom_frame, when), 30,
                     "tf map -> %s at step %d" % (odom_frame, k))
            t = self.buffer.lookup_transform("map", odom_frame, when)
            self.assertEqual(t.header.stamp, when)  # a published sample, not an interpolation
            tr, rot = t.transform.translation, t.transform.rotation
            got = homogeneous(tr.x, tr.y, tr.z, (rot.x, rot.y, rot.z, rot.w))

            gx, gy, gyaw = ground_truth(k)
            ox, oy, oyaw = odometry(k)
            expected = homogeneous(gx, gy, 0.0, quaternion_from_yaw(gyaw)).dot(
                np.linalg.inv(homogeneous(ox, oy, 0.0, quaternion_from_yaw(oyaw))))
            error = np.abs(got - expected).max()
            worst = max(worst, error)
            self.assertLess(error, 1e-6, "step %d: got\n%s\nexpected\n%s" % (k, got, expected))
        rospy.loginfo("fake_localization: %d tf samples, worst matrix error %.2e", len(published), worst)

        wait_for(lambda: len(self.poses) >= STEPS, 30, "%d amcl_pose messages" % STEPS)
        self.assertEqual(len(self.poses), STEPS)
        for k, msg in enumerate(self.poses):
            gx, gy, gyaw = ground_truth(k)
            self.assertEqual(msg.header.stamp, stamp(START_NS + k * STEP_NS))
            self.assertEqual(msg.header.frame_id, "map")
            self.assertAlmostEqual(msg.pose.pose.position.x, gx, places=9)
            self.assertAlmostEqual(msg.pose.pose.position.y, gy, places=9)
            o = msg.pose.pose.orientation
            self.assertAlmostEqual(angle_diff(yaw_of(o), gyaw), 0.0, places=9)


if __name__ == "__main__":
    rospy.init_node("test_fake_localization")
    rostest.rosrun(PKG, rospy.get_param("~test_name", "fake_localization_tf"), FakeLocalizationTest)
