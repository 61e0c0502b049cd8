#!/usr/bin/python3
"""rostest (sim_basics.test): three robots in the room fixture (fixtures/three_robots.world.yaml).

Every robot's rates (from the message stamps); robot_0 is stopped by the watchdog, robot_1
stands and looks at the walls, robot_2 drives into the wall block at x = 7.0. All waiting and
measuring in sim time. The 1 m drive is test_sim_drive.py; pause is
test_sim_services.py.
"""
import math
import sys
import unittest

import rosgraph
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Twist
from mbot_common.geometry import yaw_of
from mbot_msgs.msg import Contact
from nav_msgs.msg import Odometry
from sensor_msgs.msg import JointState, LaserScan
from tf2_msgs.msg import TFMessage
from visualization_msgs.msg import Marker, MarkerArray

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import (keep_pace, Recorder, drive_until, load_pgm_map, map_range,  # noqa: E402
                            publish_for, wait_for_connection, wait_until)

RADIUS = 0.15  # [m] mbot's footprint radius (urdf/mbot.urdf)


def twist(vx=0.0, wz=0.0):
    msg = Twist()
    msg.linear.x = vx
    msg.angular.z = wz
    return msg


class SimBasics(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_basics")
        cls.pacer = keep_pace()
        cls.truth = {n: Recorder("/%s/base_pose_ground_truth" % n, Odometry) for n in ("robot_0", "robot_1", "robot_2")}
        cls.scan1 = Recorder("/robot_1/scan", LaserScan)
        cls.contacts = Recorder("/contacts", Contact)
        cls.cmd = {n: rospy.Publisher("/%s/cmd_vel" % n, Twist, queue_size=10) for n in ("robot_0", "robot_2")}
        for rec in list(cls.truth.values()) + [cls.scan1]:
            rec.wait_for_first()
        for pub in cls.cmd.values():
            wait_for_connection(pub)
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)

    def test_1_every_robot_publishes_at_its_rates_in_sim_time(self):
        names = ("robot_0", "robot_1", "robot_2")
        odom = {n: Recorder("/%s/odom" % n, Odometry) for n in names}
        scans = {n: Recorder("/%s/scan" % n, LaserScan) for n in names}
        for rec in list(odom.values()) + list(scans.values()):
            rec.wait_for_first()  # connected: from now on every message arrives
        t0 = rospy.get_time() + 0.1
        t1 = t0 + 4.0  # count what was measured in [t0, t1): 4 s of sim time
        for rec in list(odom.values()) + list(scans.values()) + list(self.truth.values()):
            rec.first_stamped_after(t1, sim_timeout=10.0)  # all of the window has arrived
        for n in names:
            for rec, hz in ((odom[n], 50.0), (scans[n], 10.0), (self.truth[n], 50.0)):
                stamps = sorted(m.header.stamp.to_sec() for m in rec.stamped_after(t0 - 1e-6)
                                if m.header.stamp.to_sec() < t1)
                self.assertAlmostEqual(len(stamps), 4.0 * hz, delta=1,
                                       msg="%s: %d messages in 4 s" % (rec.sub.name, len(stamps)))
                gaps = [b - a for a, b in zip(stamps, stamps[1:])]
                self.assertAlmostEqual(max(gaps), 1.0 / hz, delta=1e-6, msg=rec.sub.name)
                self.assertAlmostEqual(min(gaps), 1.0 / hz, delta=1e-6, msg=rec.sub.name)
        for rec in list(odom.values()) + list(scans.values()):
            rec.sub.unregister()

    def test_2_watchdog_stops_the_robot(self):
        pub = self.cmd["robot_0"]
        truth = self.truth["robot_0"]
        speed = lambda: truth.latest().twist.twist.linear.x  # noqa: E731
        drive_until(pub, twist(0.3), lambda: speed() > 0.3 - 1e-6, 10.0, stop=False)
        self.assertGreater(speed(), 0.3 - 1e-6)
        # The last command also turns, so the ground truth shows when the simulator took it (this
        # process's clock may lag the simulator's, so the send time cannot tell).
        sent_at = rospy.get_time()
        pub.publish(twist(0.3, 0.5))
        wait_until(lambda: [m for m in truth.stamped_after(sent_at) if abs(m.twist.twist.angular.z) > 0.01]
                   and abs(speed()) < 1e-6, 10.0, "robot_0 to turn and then stop")
        stopped_at = truth.latest().header.stamp.to_sec()
        truth.first_stamped_after(stopped_at + 1.5, sim_timeout=10.0)  # and watch it stand
        samples = [(m.header.stamp.to_sec(), m.twist.twist.linear.x, m.twist.twist.angular.z)
                   for m in truth.stamped_after(sent_at - 1.0)]
        turn_from = next(t for (t, v, w) in samples if abs(w) > 0.01)
        stopped_at = next(t for (t, v, w) in samples if t > turn_from and abs(v) < 1e-6)
        braking_from = max(t for (t, v, w) in samples if t < stopped_at and v > 0.3 - 1e-6)
        # The turn shows in the first ground truth (50 Hz) after the physics step (0.01 s) that
        # took the command: 0.01 to 0.02 s after it arrived.
        arrived = turn_from - 0.015
        rospy.loginfo("watchdog: full speed until %.3f s, stopped %.3f s after the last command arrived",
                      braking_from - arrived, stopped_at - arrived)
        # 0.2 s watchdog timeout at full speed, then braking from 0.3 m/s at 1 m/s^2 for 0.3 s
        # (ground truth comes at 50 Hz: +-0.02 s, and the arrival is known to +-0.005 s)
        self.assertAlmostEqual(braking_from - arrived, 0.2, delta=0.03)
        self.assertAlmostEqual(stopped_at - arrived, 0.5, delta=0.04)
        for (t, v, w) in samples:
            if t > stopped_at:
                self.assertLess(abs(v), 1e-6, "moved again at t = %.2f" % t)

    def test_3_drive_into_wall_stops_at_the_wall_with_one_contact(self):
        t0 = rospy.get_time()
        wall_x = 7.0
        at_wall = lambda: self.truth["robot_2"].latest().pose.pose.position.x > wall_x - RADIUS - 0.03  # noqa: E731
        drive_until(self.cmd["robot_2"], twist(0.5), at_wall, 20.0)  # 0.85 m to the wall
        publish_for(self.cmd["robot_2"], twist(0.5), 1.0)  # and push against it for 1 s
        self.cmd["robot_2"].publish(twist(0.0))
        speed = lambda: abs(self.truth["robot_2"].latest().twist.twist.linear.x)  # noqa: E731
        wait_until(lambda: speed() < 1e-6, 5.0, "robot_2 to stand still")
        xs = [m.pose.pose.position.x for m in self.truth["robot_2"].since(t0)]
        self.assertGreater(len(xs), 100)
        self.assertLessEqual(max(xs) + RADIUS, wall_x + 0.002, "the footprint entered the wall")
        self.assertAlmostEqual(xs[-1], wall_x - RADIUS, delta=0.02)
        mine = [c for c in self.contacts.since(t0) if {c.body_a, c.body_b} == {"robot_2", "map"}]
        self.assertEqual(len(mine), 1, "contacts: %s" % [(c.body_a, c.body_b, c.header.stamp.to_sec()) for c in mine])
        self.assertAlmostEqual(mine[0].position.x, wall_x, delta=0.02)
        self.assertEqual(mine[0].header.frame_id, "map")
        self.assertGreater(mine[0].header.stamp.to_sec(), t0)

    def test_4_laser_sees_the_wall_where_the_map_has_it(self):
        scan = self.scan1.latest()
        self.assertEqual(scan.header.frame_id, "robot_1/base_laser")
        self.assertEqual(len(scan.ranges), 360)
        self.assertAlmostEqual(scan.angle_increment, 2 * math.pi / 360, places=6)
        self.assertAlmostEqual(scan.range_min, 0.12, places=6)
        self.assertAlmostEqual(scan.range_max, 8.0, places=6)
        # where the laser is: ground truth of the base + the URDF mount from tf
        mount = self.tf_buffer.lookup_transform("robot_1/base_footprint", "robot_1/base_laser", rospy.Time(0),
                                                rospy.Duration(150.0)).transform.translation
        base = self.truth["robot_1"].latest().pose.pose
        yaw = yaw_of(base.orientation)
        lx = base.position.x + math.cos(yaw) * mount.x - math.sin(yaw) * mount.y
        ly = base.position.y + math.sin(yaw) * mount.x + math.cos(yaw) * mount.y
        occupied, res, ox, oy, _, _ = load_pgm_map("room.yaml")
        # west (-pi), east (0), north (+pi/2); south would see robot_0, 2 m away at the start
        for index in (0, 180, 270):
            angle = yaw + scan.angle_min + index * scan.angle_increment
            expected = map_range(occupied, res, ox, oy, lx, ly, angle, scan.range_max)
            self.assertTrue(math.isfinite(expected))
            self.assertAlmostEqual(scan.ranges[index], expected, delta=res,
                                   msg="beam %d: %.3f m, the map says %.3f m" % (index, scan.ranges[index], expected))

    def test_5_tf_from_odom_to_laser_resolves(self):
        # (150 s of sim time = 30 s of wall time at 5x: robot_state_publisher may start slowly)
        t = self.tf_buffer.lookup_transform("robot_1/odom", "robot_1/base_laser", rospy.Time(0), rospy.Duration(150.0))
        # robot_1 never moved: odom = base_footprint, so this is the laser mount (0.05, 0, 0.16)
        self.assertAlmostEqual(t.transform.translation.x, 0.05, delta=1e-3)
        self.assertAlmostEqual(t.transform.translation.y, 0.0, delta=1e-3)
        self.assertAlmostEqual(t.transform.translation.z, 0.16, delta=1e-3)

    def test_6_markers_show_every_robot_where_it_is(self):
        array = rospy.wait_for_message("/stage/markers", MarkerArray, timeout=30.0)
        stamp = max(m.header.stamp for m in array.markers)
        discs = {m.id: m for m in array.markers if m.ns == "robots"}
        names = sorted(m.text for m in array.markers if m.ns == "robot_names")
        self.assertEqual(array.markers[0].action, Marker.DELETEALL)
        self.assertEqual(names, ["robot_0", "robot_1", "robot_2"])
        self.assertEqual(len(discs), 3)
        # robot_1 never moves: its disc is where its ground truth is, footprint-sized
        truth = self.truth["robot_1"].latest().pose.pose.position
        disc = [m for m in discs.values()
                if abs(m.pose.position.x - truth.x) < 0.01 and abs(m.pose.position.y - truth.y) < 0.01]
        self.assertEqual(len(disc), 1,
                         "no disc at robot_1's pose (%.2f, %.2f) at t=%.2f" % (truth.x, truth.y, stamp.to_sec()))
        self.assertAlmostEqual(disc[0].scale.x, 2 * RADIUS, delta=1e-6)

    def test_7_the_simulator_publishes_the_wheels_and_nobody_reads_joint_states(self):
        """stage_node puts <ns>/base_link -> <ns>/<wheel> on /tf at ~wheel_tf_rate (10 Hz), at the
        angle its joint_states give; the fixed joints are left, for one publisher of the fleet's."""
        left = []  # (stamp [s], publisher, parent, y, angle about +y)

        def on_tf(msg):
            for t in msg.transforms:
                if t.child_frame_id == "robot_0/left_wheel":
                    q = t.transform.rotation
                    left.append((t.header.stamp.to_sec(), msg._connection_header.get("callerid"), t.header.frame_id,
                                 t.transform.translation.y, 2.0 * math.atan2(q.y, q.w)))

        tf_sub = rospy.Subscriber("/tf", TFMessage, on_tf, queue_size=1000)
        joints = Recorder("/robot_0/joint_states", JointState)
        joints.wait_for_first()
        t0 = rospy.get_time() + 0.5
        publish_for(self.cmd["robot_0"], twist(0.0, 1.0), 3.0)  # in place: the left wheel turns backwards
        self.cmd["robot_0"].publish(twist(0.0))
        tf_sub.unregister()
        window = [w for w in left if t0 <= w[0] < t0 + 2.0]
        self.assertTrue(18 <= len(window) <= 22, "%d wheel transforms in 2 s of sim time, expected 10 Hz" % len(window))
        self.assertEqual({w[1] for w in window}, {"/stage_node"})
        self.assertEqual({w[2] for w in window}, {"robot_0/base_link"})
        for w in window:
            self.assertAlmostEqual(w[3], 0.11, delta=1e-9)  # the URDF's joint origin
        angles = {round(m.header.stamp.to_sec(), 6): m.position[0] for m in joints.since(0.0)}
        matched = 0
        for stamp, _, _, _, angle in window:
            if round(stamp, 6) in angles:
                diff = math.atan2(math.sin(angle - angles[round(stamp, 6)]), math.cos(angle - angles[round(stamp, 6)]))
                self.assertAlmostEqual(diff, 0.0, delta=1e-6)
                matched += 1
        self.assertGreater(matched, 10, "few wheel transforms had a joint_states message of the same stamp")
        turned = sum(math.atan2(math.sin(b[4] - a[4]), math.cos(b[4] - a[4])) for a, b in zip(window, window[1:]))
        # wz = 1 rad/s: the left wheel (y = +0.11 m, r = 0.04 m) rolls at -2.75 rad/s, ~ -5.5 rad in 2 s
        self.assertLess(turned, -3.0, "the left wheel turned %.2f rad while the robot turned left" % turned)
        # the fixed frames (test_5 resolves the laser) come from one node for the fleet, which
        # reads no joint_states: no robot_state_publisher process per robot
        publishers, subscribers, _ = rosgraph.Master("/test_sim_basics").getSystemState()
        readers = [n for n in dict(subscribers).get("/robot_0/joint_states", []) if n != rospy.get_name()]
        self.assertEqual(readers, [])
        self.assertEqual(dict(publishers).get("/tf_static"), ["/robot_state_publishers"])


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_basics", SimBasics, sys.argv)
