#!/usr/bin/python3
"""rostest (sim_obstacles.test): /spawn_obstacle and /remove_obstacle called as a client would.

robot_0 stands at (2, 2) facing +x in the room fixture; straight ahead its laser sees the wall
block at x = 7.0. A box spawned in between shows in the first scan measured after the spawn and
is gone from the first scan measured after its removal. The sim time of each change is the stamp
of the /stage/markers array stage_node publishes with it. Refused requests change nothing.
"""
import sys
import unittest

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Pose2D
from mbot_common.geometry import yaw_of
from mbot_msgs.srv import RemoveObstacle, SpawnObstacle
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan
from visualization_msgs.msg import Marker, MarkerArray

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import keep_pace, Recorder, load_pgm_map, map_range, wait_until  # noqa: E402

BOX_X, BOX_Y = 3.5, 2.0              # [m] the box's centre, in front of robot_0
BOX_LENGTH, BOX_WIDTH = 0.4, 0.6     # [m] its near face is at x = 3.3


def pose2d(x, y, theta=0.0):
    p = Pose2D()
    p.x, p.y, p.theta = x, y, theta
    return p


def obstacle_markers(array):
    return {m.text: m for m in array.markers if m.ns == "obstacles"}


def stamp_of(array):
    """The sim time an array was published at (every marker but DELETEALL carries it)."""
    return max(m.header.stamp.to_sec() for m in array.markers if m.action == Marker.ADD)


class SimObstacles(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_obstacles")
        cls.pacer = keep_pace()
        for name in ("spawn_obstacle", "remove_obstacle"):
            rospy.wait_for_service("/" + name, timeout=30.0)
        cls.spawn = rospy.ServiceProxy("/spawn_obstacle", SpawnObstacle)
        cls.remove = rospy.ServiceProxy("/remove_obstacle", RemoveObstacle)
        cls.scan = Recorder("/robot_0/scan", LaserScan)
        cls.truth = Recorder("/robot_0/base_pose_ground_truth", Odometry)
        cls.markers = Recorder("/stage/markers", MarkerArray)
        for rec in (cls.scan, cls.truth, cls.markers):
            rec.wait_for_first()
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)

    def laser_position(self):
        """Where robot_0's laser is: ground truth of the base + the URDF mount from tf."""
        # (150 s of sim time = 30 s of wall time at 5x: robot_state_publisher may start slowly)
        mount = self.tf_buffer.lookup_transform("robot_0/base_footprint", "robot_0/base_laser", rospy.Time(0),
                                                rospy.Duration(150.0)).transform.translation
        base = self.truth.latest().pose.pose
        yaw = yaw_of(base.orientation)
        self.assertAlmostEqual(yaw, 0.0, delta=1e-6)  # facing +x: beam "ahead" is along +x
        return base.position.x + mount.x, base.position.y + mount.y

    def wait_for_markers(self, condition, what):
        """The first /stage/markers array received that satisfies condition (waits, sim time)."""
        found = []

        def check():
            found[:] = [a for a in self.markers.since(0.0) if condition(a)][:1]
            return bool(found)
        wait_until(check, 10.0, what)
        return found[0]

    def scans_around(self, t):
        """(the last scan measured at or before sim time t, the first one measured after it)."""
        after = self.scan.first_stamped_after(t)
        before = [m for m in self.scan.since(0.0) if m.header.stamp.to_sec() <= t]
        self.assertTrue(before, "no scan measured before t = %.2f" % t)
        return before[-1], after

    def test_spawn_refuse_and_remove_a_box_in_front_of_a_robot(self):
        lx, ly = self.laser_position()
        scan = self.scan.latest()
        ahead = int(round((0.0 - scan.angle_min) / scan.angle_increment))  # beam along +x
        occupied, res, ox, oy, _, _ = load_pgm_map("room.yaml")
        wall = map_range(occupied, res, ox, oy, lx, ly, scan.angle_min + ahead * scan.angle_increment, scan.range_max)
        box = (BOX_X - BOX_LENGTH / 2.0) - lx
        self.assertAlmostEqual(wall, 7.0 - lx, delta=res)  # the wall block
        self.assertAlmostEqual(scan.ranges[ahead], wall, delta=res)
        self.assertEqual(obstacle_markers(self.markers.latest()), {})

        # ---- spawn: seen from the first scan measured after it
        res_spawn = self.spawn(name="crate", shape="box", length=BOX_LENGTH, width=BOX_WIDTH, radius=0.0,
                               pose=pose2d(BOX_X, BOX_Y))
        self.assertTrue(res_spawn.success, res_spawn.message)
        spawned = self.wait_for_markers(lambda a: "crate" in obstacle_markers(a), "a marker of the crate")
        marker = obstacle_markers(spawned)["crate"]
        self.assertEqual(marker.type, Marker.CUBE)
        self.assertAlmostEqual(marker.pose.position.x, BOX_X, delta=1e-9)
        self.assertAlmostEqual(marker.pose.position.y, BOX_Y, delta=1e-9)
        self.assertAlmostEqual(marker.scale.x, BOX_LENGTH, delta=1e-9)
        self.assertAlmostEqual(marker.scale.y, BOX_WIDTH, delta=1e-9)
        t_spawn = marker.header.stamp.to_sec()
        before, after = self.scans_around(t_spawn)
        self.assertAlmostEqual(before.ranges[ahead], wall, delta=res)
        self.assertAlmostEqual(after.ranges[ahead], box, delta=res,
                               msg="first scan after the spawn: %.3f m, the box is at %.3f m"
                               % (after.ranges[ahead], box))

        # ---- refused spawns change nothing
        refused = [
            (dict(name="crate", shape="box", length=0.2, width=0.2, pose=pose2d(2.8, 2.0)),
             'duplicate name "crate"'),
            (dict(name="robot_1", shape="box", length=0.2, width=0.2, pose=pose2d(2.8, 2.0)),
             'duplicate name "robot_1"'),
            (dict(name="ball", shape="sphere", radius=0.2, pose=pose2d(2.8, 2.0)),
             'shape: expected box or cylinder, got "sphere"'),
            (dict(name="flat", shape="box", length=-0.2, width=0.2, pose=pose2d(2.8, 2.0)),
             "length: expected a number > 0 [m], got -0.2"),
            (dict(name="drum", shape="cylinder", radius=float("nan"), pose=pose2d(2.8, 2.0)),
             "radius: expected a number > 0 [m], got nan"),
            (dict(name="lost", shape="box", length=0.2, width=0.2, pose=pose2d(float("nan"), 2.0)),
             "the pose is not finite"),
            (dict(name="far", shape="box", length=0.2, width=0.2, pose=pose2d(40.0, 2.0)),
             "far at (40.00, 2.00) is outside the map"),
            (dict(name="on_robot", shape="box", length=0.4, width=0.4, pose=pose2d(2.3, 2.0)),
             "overlaps robot robot_0"),
            (dict(name="bad name", shape="box", length=0.2, width=0.2, pose=pose2d(2.8, 2.0)),
             "expected a name"),
        ]
        for request, expected in refused:
            res_bad = self.spawn(**request)
            self.assertFalse(res_bad.success, "spawn %s should fail" % request)
            self.assertIn(expected, res_bad.message)
        t_refused = rospy.get_time()
        last = self.scan.first_stamped_after(t_refused + 1.0)
        scans = [m for m in self.scan.stamped_after(t_spawn) if m.header.stamp.to_sec() <= last.header.stamp.to_sec()]
        self.assertGreaterEqual(len(scans), 10)
        for s in scans:
            self.assertAlmostEqual(s.ranges[ahead], box, delta=res, msg="t = %.2f" % s.header.stamp.to_sec())
        latest = self.wait_for_markers(lambda a: stamp_of(a) >= last.header.stamp.to_sec(),
                                       "markers after the refusals")
        self.assertEqual(sorted(obstacle_markers(latest)), ["crate"])

        # ---- remove: the wall again from the first scan measured after it
        res_remove = self.remove(name="crate")
        self.assertTrue(res_remove.success, res_remove.message)
        received = self.markers.since(0.0)
        last_with = max(i for i, a in enumerate(received) if "crate" in obstacle_markers(a))
        removed = self.wait_for_markers(
            lambda a: stamp_of(a) >= stamp_of(received[last_with]) and "crate" not in obstacle_markers(a),
            "markers without the crate")
        self.assertEqual(obstacle_markers(removed), {})
        t_remove = stamp_of(removed)
        before, after = self.scans_around(t_remove)
        self.assertAlmostEqual(before.ranges[ahead], box, delta=res)
        self.assertAlmostEqual(after.ranges[ahead], wall, delta=res,
                               msg="first scan after the removal: %.3f m, the wall is at %.3f m"
                               % (after.ranges[ahead], wall))

        for name, expected in (("crate", 'unknown obstacle "crate"'),
                               ("robot_1", '"robot_1" is a robot, not an obstacle'),
                               ("map", '"map" is the walls, not an obstacle')):
            res_bad = self.remove(name=name)
            self.assertFalse(res_bad.success, "remove %s should fail" % name)
            self.assertEqual(res_bad.message, expected)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_obstacles", SimObstacles, sys.argv)
