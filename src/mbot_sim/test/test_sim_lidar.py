#!/usr/bin/python3
"""rostest (sim_lidar.test): robot_0's 3D lidar (/robot_0/points, sensor_msgs/PointCloud2) standing
2.06 m before a wall: the points ahead lie on the wall plane within the range noise, the floor points
at z = 0 (0.26 m below the lidar), nothing above the 2.5 m walls; frame robot_0/lidar_link (at its
URDF mount on /tf_static), fields x, y, z, intensity, time (float32), point times in [0, 0.1 s),
one frame per 0.1 s of sim time; robot_1 (no lidar in the world file) has no points topic."""
import math
import sys
import unittest

import numpy as np
import rospy
import rostest
import tf2_ros
from sensor_msgs.msg import PointCloud2, PointField

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import Recorder, keep_pace  # noqa: E402
from sim_test_tools import wait_until  # noqa: E402

WALL_X = 7.0 - (5.0 - 0.06)  # [m] the wall ahead in the lidar frame
LIDAR_Z = 0.26  # [m] above the floor
NOISE = 0.02  # [m] the world file's range_noise
POINT = np.dtype([("x", "<f4"), ("y", "<f4"), ("z", "<f4"), ("intensity", "<f4"), ("time", "<f4")])


def points_of(msg):
    return np.frombuffer(bytes(msg.data), dtype=POINT, count=msg.width * msg.height)


class Lidar(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_lidar")
        cls.pacer = keep_pace()
        cls.clouds = Recorder("/robot_0/points", PointCloud2)
        cls.clouds.wait_for_first()
        t0 = rospy.get_time()
        wait_until(lambda: len(cls.clouds.since(t0)) >= 12, 30.0, "12 clouds on /robot_0/points")
        cls.frames = cls.clouds.since(t0)

    def test_1_header_fields_and_times(self):
        for msg in self.frames:
            self.assertEqual(msg.header.frame_id, "robot_0/lidar_link")
            self.assertEqual([f.name for f in msg.fields], ["x", "y", "z", "intensity", "time"])
            self.assertEqual([f.offset for f in msg.fields], [0, 4, 8, 12, 16])
            self.assertTrue(all(f.datatype == PointField.FLOAT32 and f.count == 1 for f in msg.fields))
            self.assertEqual((msg.point_step, msg.height, msg.is_bigendian), (20, 1, False))
            self.assertEqual(msg.row_step, 20 * msg.width)
            self.assertGreater(msg.width, 3000)  # of 5000 pattern points; upward ones over the walls are dropped
            self.assertLessEqual(msg.width, 5000)
            p = points_of(msg)
            self.assertTrue(np.all(p["time"] >= 0.0) and np.all(p["time"] < 0.1), (p["time"].min(), p["time"].max()))
            self.assertTrue(np.all(np.diff(p["time"]) >= 0.0), "point times not in order")
            self.assertTrue(np.all(np.isfinite(p["x"])))

    def test_2_frame_rate_in_sim_time(self):
        stamps = [m.header.stamp.to_sec() for m in self.frames]
        gaps = np.diff(stamps)
        self.assertTrue(np.all(np.abs(gaps - 0.1) < 1e-6), "frames not 0.1 s apart: %s" % gaps)
        # frames keep the phase of the lidar's start (sim time 0), also after nobody listened
        self.assertTrue(all(abs(s * 10.0 - round(s * 10.0)) < 1e-6 for s in stamps), stamps[:5])

    def test_3_wall_and_floor(self):
        p = np.concatenate([points_of(m) for m in self.frames])
        bearing = np.degrees(np.arctan2(p["y"], p["x"]))
        ahead = p[(np.abs(bearing) < 8.0) & (p["x"] > 0.5) & (p["z"] > -0.2)]
        self.assertGreater(len(ahead), 100)
        # on the wall plane x = 2.06 m: each within 5 sigma of the range noise, the mean within 1 cm
        worst = float(ahead["x"][np.argmax(np.abs(ahead["x"] - WALL_X))])
        self.assertLess(abs(worst - WALL_X), 5 * NOISE, worst)
        self.assertAlmostEqual(float(np.mean(ahead["x"])), WALL_X, delta=0.01)
        self.assertAlmostEqual(float(np.std(ahead["x"])), NOISE, delta=0.007)
        # the floor: everything well below the lidar and away from the walls (a ray 7 deg down meets
        # a wall closer than 2.1 m below the lidar's height) and from robot_1 (0.29 m tall, at
        # (2, 6)) is at z = -0.26; the range noise moves z by at most sin(7 deg) of it
        wx, wy = p["x"] + 5.0 - 0.06, p["y"] + 1.5  # the robot faces +x
        away = (wx > 0.4) & (wx < 6.7) & (wy > 0.4) & (wy < 7.6) & (np.hypot(wx - 2.0, wy - 6.0) > 0.5)
        floor = p[(p["z"] < -0.15) & away]
        self.assertTrue(np.any((p["z"] < -0.1) & (np.hypot(wx - 2.0, wy - 6.0) < 0.3)), "robot_1 not seen")
        self.assertGreater(len(floor), 100)
        self.assertLess(np.max(np.abs(floor["z"] + LIDAR_Z)), 5 * NOISE * math.sin(math.radians(7.0)) + 0.002)
        # behind the robot (the room's far wall is 4.8 m away) the floor is 2.1 m off at 7 deg down
        horizontal = np.hypot(floor["x"], floor["y"])
        self.assertAlmostEqual(float(np.min(horizontal)), LIDAR_Z / math.tan(math.radians(7.0)), delta=0.1)
        # nothing above the 2.5 m walls, and no point beyond the room
        self.assertLess(float(np.max(p["z"])), 2.5 - LIDAR_Z + 0.1)
        self.assertLess(float(np.max(np.hypot(p["x"], p["y"]))), math.hypot(10.0, 8.0))

    def test_4_mount_on_tf_and_no_topic_without_lidar(self):
        buf = tf2_ros.Buffer()
        tf2_ros.TransformListener(buf)
        t = buf.lookup_transform("robot_0/base_footprint", "robot_0/lidar_link", rospy.Time(0), rospy.Duration(10.0))
        v = t.transform.translation
        self.assertAlmostEqual(v.x, -0.06, places=6)
        self.assertAlmostEqual(v.z, LIDAR_Z, places=6)
        topics = [name for name, _ in rospy.get_published_topics()]
        self.assertIn("/robot_0/points", topics)
        self.assertNotIn("/robot_1/points", topics)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_lidar", Lidar)
