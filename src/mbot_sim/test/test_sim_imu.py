#!/usr/bin/python3
"""rostest (sim_imu.test): stage_node's IMU topic.

robot_0 (mbot) stands still: its /robot_0/imu runs at 200 Hz in sim time (stamps on the 5 ms
grid, none missing), in frame robot_0/imu_link, which /tf_static places at the URDF's mount; no
orientation (covariance[0] -1), covariance diagonals density^2 * rate from the world file; the
mean specific force is (0, 0, g) and the mean rate 0, within the start bias and the noise.
robot_1 (mbot_omni, IMU 0.05 m ahead of the centre) turns in place: each IMU sample stamped with
a ground-truth sample reads its turn rate within the noise, and at a steady rate the
accelerometer reads the centripetal -w^2 * 0.05 along x.
"""
import math
import os
import sys
import unittest

import rospy
import rostest
import tf2_ros
import yaml
from geometry_msgs.msg import Twist
from nav_msgs.msg import Odometry
from sensor_msgs.msg import Imu

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from sim_test_tools import Recorder, drive_until, wait_for_connection, wait_until  # noqa: E402

G = 9.80665


def mean(values):
    return sum(values) / float(len(values))


class SimImu(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_imu")
        with open(rospy.get_param("/stage_node/world")) as f:
            cls.imu_config = yaml.safe_load(f)["noise"]["imu"]
        cls.imu0 = Recorder("/robot_0/imu", Imu)
        cls.imu1 = Recorder("/robot_1/imu", Imu)
        cls.truth1 = Recorder("/robot_1/base_pose_ground_truth", Odometry)
        cls.imu0.wait_for_first()
        cls.imu1.wait_for_first()

    def wait_sim(self, seconds):
        end = rospy.get_time() + seconds
        wait_until(lambda: rospy.get_time() >= end, seconds + 30.0, "sim time %.1f" % end)

    def test_rate_frame_and_covariance(self):
        start = self.imu0.latest().header.stamp.to_sec()
        wait_until(lambda: self.imu0.latest().header.stamp.to_sec() >= start + 4.0, 60.0, "4 s of IMU")
        stamps = [m.header.stamp.to_sec() for m in self.imu0.stamped_after(start)]
        window = [t for t in stamps if t <= start + 4.0 + 1e-6]
        self.assertEqual(len(window), 800, "200 Hz sim time over 4 s")
        for a, b in zip(window, window[1:]):
            self.assertAlmostEqual(b - a, 0.005, delta=1e-6)
        self.assertAlmostEqual(window[0] / 0.005, round(window[0] / 0.005), delta=1e-4)
        msg = self.imu0.latest()
        self.assertEqual(msg.header.frame_id, "robot_0/imu_link")
        self.assertEqual(msg.orientation_covariance[0], -1.0)
        c = self.imu_config
        for i in (0, 4, 8):
            self.assertAlmostEqual(msg.angular_velocity_covariance[i], c["gyro_noise_density"] ** 2 * c["rate"])
            self.assertAlmostEqual(msg.linear_acceleration_covariance[i], c["accel_noise_density"] ** 2 * c["rate"])
        self.assertEqual(msg.angular_velocity_covariance[1], 0.0)
        buffer = tf2_ros.Buffer()
        tf2_ros.TransformListener(buffer)
        tf = buffer.lookup_transform("robot_0/base_footprint", "robot_0/imu_link", rospy.Time(0),
                                     rospy.Duration(20.0)).transform.translation
        self.assertEqual((round(tf.x, 6), round(tf.y, 6), round(tf.z, 6)), (-0.03, 0.02, 0.1))  # mbot.urdf

    def test_at_rest_reads_gravity(self):
        t0 = rospy.get_time()
        self.wait_sim(2.0)
        msgs = [m for m in self.imu0.stamped_after(t0)][:400]
        self.assertGreaterEqual(len(msgs), 380)
        c = self.imu_config
        n = math.sqrt(len(msgs))
        gyro_bound = 4 * c["gyro_bias_init"] + 4 * c["gyro_noise_density"] * math.sqrt(c["rate"]) / n
        accel_bound = 4 * c["accel_bias_init"] + 4 * c["accel_noise_density"] * math.sqrt(c["rate"]) / n
        for axis in "xyz":
            self.assertAlmostEqual(mean([getattr(m.angular_velocity, axis) for m in msgs]), 0.0, delta=gyro_bound)
        self.assertAlmostEqual(mean([m.linear_acceleration.x for m in msgs]), 0.0, delta=accel_bound)
        self.assertAlmostEqual(mean([m.linear_acceleration.y for m in msgs]), 0.0, delta=accel_bound)
        self.assertAlmostEqual(mean([m.linear_acceleration.z for m in msgs]), G, delta=accel_bound)
        # the noise is there: a white sample's sd is density * sqrt(rate) (within 20 % for 400)
        z = [m.linear_acceleration.z for m in msgs]
        sd = math.sqrt(sum((v - mean(z)) ** 2 for v in z) / (len(z) - 1))
        self.assertAlmostEqual(sd / (c["accel_noise_density"] * math.sqrt(c["rate"])), 1.0, delta=0.2)

    def test_turning_in_place(self):
        pub = rospy.Publisher("/robot_1/cmd_vel", Twist, queue_size=10)
        wait_for_connection(pub, 30.0)
        cmd = Twist()
        cmd.angular.z = 1.0
        t0 = rospy.get_time()
        drive_until(pub, cmd, lambda: rospy.get_time() > t0 + 4.0, 10.0)
        truth = {round(m.header.stamp.to_sec(), 3): m.twist.twist.angular.z for m in self.truth1.stamped_after(t0)}
        imu = self.imu1.stamped_after(t0)
        c = self.imu_config
        bound = 4 * c["gyro_bias_init"] + 4 * c["gyro_noise_density"] * math.sqrt(c["rate"]) + c["gyro_quantization"]
        matched, steady = 0, []
        for m in imu:
            t = round(m.header.stamp.to_sec(), 3)
            if t not in truth:
                continue
            matched += 1
            self.assertAlmostEqual(m.angular_velocity.z, truth[t], delta=bound)
            before = truth.get(round(t - 0.02, 3))
            if truth[t] > 0.9 and before is not None and abs(before - truth[t]) < 1e-9:
                steady.append((truth[t], m.linear_acceleration.x))
        self.assertGreater(matched, 100)
        self.assertGreater(len(steady), 50, "the robot turned at a steady rate > 0.9 rad/s")
        expected = mean([-w * w * 0.05 for w, _ in steady])  # mbot_omni.urdf: imu_link at x = 0.05
        accel_bound = 4 * c["accel_bias_init"] + 4 * c["accel_noise_density"] * math.sqrt(c["rate"] / len(steady))
        self.assertAlmostEqual(mean([a for _, a in steady]), expected, delta=accel_bound)
        self.assertLess(expected, -0.04)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_imu", SimImu)
