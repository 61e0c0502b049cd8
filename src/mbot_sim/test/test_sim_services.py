#!/usr/bin/python3
"""rostest (sim_services.test): the run-time API of stage_node - spawn, remove, teleport,
cmd_pose, set_fault, reset, pause - does what it says, and bad requests return errors."""
import math
import sys
import time
import unittest

import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import Pose, Pose2D, Twist
from mbot_common.geometry import quaternion_from_yaw, yaw_of
from mbot_msgs.srv import RemoveRobot, SetFault, SetFaultRequest, SpawnRobot, TeleportRobot
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import (keep_pace, Recorder, drive_until, publish_for, wait_for_connection,  # noqa: E402
                            wait_until)
from mbot_common.waits import wait_for_wall  # noqa: E402


def pose2d(x, y, theta):
    p = Pose2D()
    p.x, p.y, p.theta = x, y, theta
    return p


def pose3d(x, y, z, yaw, roll=0.0, scale=1.0):
    """A geometry_msgs/Pose at (x, y, z) turned by yaw, then roll about the turned x axis; the
    quaternion is multiplied by scale (a yaw reader must not need a unit quaternion)."""
    p = Pose()
    p.position.x, p.position.y, p.position.z = x, y, z
    _, _, qz, qw = quaternion_from_yaw(yaw)
    cr, sr = math.cos(0.5 * roll), math.sin(0.5 * roll)
    # q_yaw * q_roll (Hamilton product of (0, 0, qz, qw) and (sr, 0, 0, cr))
    p.orientation.x = scale * qw * sr
    p.orientation.y = scale * qz * sr
    p.orientation.z = scale * qz * cr
    p.orientation.w = scale * qw * cr
    return p


def fault(robot, **fields):
    req = SetFaultRequest()
    req.robot = robot
    for key, value in fields.items():
        setattr(req, key, value)
    return req


class SimServices(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_services")
        cls.pacer = keep_pace()
        names = ["spawn_robot", "remove_robot", "teleport_robot", "set_fault", "reset", "reset_positions",
                 "pause_physics", "unpause_physics"]
        for name in names:
            rospy.wait_for_service("/" + name, timeout=30.0)
        cls.spawn = rospy.ServiceProxy("/spawn_robot", SpawnRobot)
        cls.remove = rospy.ServiceProxy("/remove_robot", RemoveRobot)
        cls.teleport = rospy.ServiceProxy("/teleport_robot", TeleportRobot)
        cls.set_fault = rospy.ServiceProxy("/set_fault", SetFault)
        cls.reset = rospy.ServiceProxy("/reset", Empty)
        cls.pause = rospy.ServiceProxy("/pause_physics", Empty)
        cls.unpause = rospy.ServiceProxy("/unpause_physics", Empty)
        cls.truth = {n: Recorder("/%s/base_pose_ground_truth" % n, Odometry) for n in ("robot_0", "robot_1", "robot_2")}
        cls.odom = {n: Recorder("/%s/odom" % n, Odometry) for n in ("robot_0", "robot_2")}
        cls.scan0 = Recorder("/robot_0/scan", LaserScan)
        for rec in list(cls.truth.values()) + list(cls.odom.values()) + [cls.scan0]:
            rec.wait_for_first()
        cls.tf_buffer = tf2_ros.Buffer()
        cls.tf_listener = tf2_ros.TransformListener(cls.tf_buffer)

    def pose_of(self, robot):
        p = self.truth[robot].latest().pose.pose
        return p.position.x, p.position.y, yaw_of(p.orientation)

    def wait_for_pose(self, robot, x, y, what):
        """Wait until the ground truth shows the robot within 1 cm of (x, y); return the pose.

        (Waiting on the pose, not on a time: the test's clock may lag the simulator's, so a
        message stamped after the test's "now" may still have been measured before the request.)
        """
        wait_until(lambda: math.hypot(self.pose_of(robot)[0] - x, self.pose_of(robot)[1] - y) < 0.01, 5.0, what)
        return self.pose_of(robot)

    # ---- spawn and remove -------------------------------------------------------------------
    def test_spawn_and_remove(self):
        res = self.spawn("robot_3", "mbot", pose2d(4.0, 6.0, 0.5))
        self.assertTrue(res.success, res.message)
        odom3 = Recorder("/robot_3/odom", Odometry)
        truth3 = Recorder("/robot_3/base_pose_ground_truth", Odometry)
        odom3.wait_for_first()
        p = truth3.wait_for_first().pose.pose
        self.assertAlmostEqual(p.position.x, 4.0, delta=1e-6)
        self.assertAlmostEqual(yaw_of(p.orientation), 0.5, delta=1e-6)
        self.assertIn({"name": "robot_3", "model": "mbot"}, rospy.get_param("/stage/robots"))
        # its robot_state_publisher comes up: the laser frame resolves from its odom frame
        t = self.tf_buffer.lookup_transform("robot_3/odom", "robot_3/base_laser", rospy.Time(0), rospy.Duration(150.0))
        self.assertAlmostEqual(t.transform.translation.x, 0.05, delta=1e-3)

        bad = [("robot_3", "mbot", (6.0, 6.0, 0.0), "duplicate name"),
               ("robot_4", "mbot", (7.2, 1.0, 0.0), "overlaps a wall"),
               ("robot_4", "mbot", (4.1, 6.0, 0.0), "overlaps robot robot_3"),
               ("robot_4", "mbot", (40.0, 6.0, 0.0), "outside the map"),
               ("robot_4", "hovercraft", (6.0, 6.0, 0.0), "hovercraft"),
               ("bad name", "mbot", (6.0, 6.0, 0.0), "expected a name")]
        for name, model, pose, expected in bad:
            res = self.spawn(name, model, pose2d(*pose))
            self.assertFalse(res.success, "spawn %s at %s should fail" % (name, pose))
            self.assertIn(expected, res.message)

        res = self.remove("robot_3")
        self.assertTrue(res.success, res.message)
        t_removed = rospy.get_time()
        self.truth["robot_0"].first_stamped_after(t_removed + 1.0)  # the simulator went on for 1 s
        # (0.2 s: the test's clock may lag the simulator's a little)
        self.assertEqual(len(odom3.stamped_after(t_removed + 0.2)), 0, "a removed robot must not publish")
        self.assertNotIn("robot_3", [r["name"] for r in rospy.get_param("/stage/robots")])
        res = self.remove("robot_3")
        self.assertFalse(res.success)
        self.assertIn("unknown robot", res.message)
        odom3.sub.unregister()
        truth3.sub.unregister()

    # ---- teleport -----------------------------------------------------------------------------
    def test_teleport_and_cmd_pose(self):
        res = self.teleport("robot_1", pose2d(5.0, 5.0, 1.0))
        self.assertTrue(res.success, res.message)
        x, y, yaw = self.wait_for_pose("robot_1", 5.0, 5.0, "robot_1 teleported")
        self.assertAlmostEqual(x, 5.0, delta=1e-6)
        self.assertAlmostEqual(y, 5.0, delta=1e-6)
        self.assertAlmostEqual(yaw, 1.0, delta=1e-6)

        res = self.teleport("robot_1", pose2d(7.25, 1.0, 0.0))  # inside the wall block
        self.assertFalse(res.success)
        self.assertIn("would overlap a wall", res.message)
        res = self.teleport("robot_9", pose2d(5.0, 6.0, 0.0))
        self.assertFalse(res.success)
        self.assertIn("unknown robot", res.message)
        # unchanged in a pose measured after the refused requests (the test's clock may lag)
        after = self.truth["robot_1"].first_stamped_after(rospy.get_time() + 0.2).pose.pose.position
        self.assertAlmostEqual(after.x, 5.0, delta=1e-6)
        self.assertAlmostEqual(after.y, 5.0, delta=1e-6)

        # cmd_pose is a geometry_msgs/Pose as in stage_ros: z, roll and pitch are ignored, the yaw
        # comes from the quaternion (here one with roll 0.3 and a non-unit length).
        pub = rospy.Publisher("/robot_1/cmd_pose", Pose, queue_size=1, latch=True)
        wait_for_connection(pub)
        pub.publish(pose3d(3.0, 6.5, 0.7, yaw=-1.0, roll=0.3, scale=2.0))
        x, y, yaw = self.wait_for_pose("robot_1", 3.0, 6.5, "robot_1 moved by cmd_pose")
        self.assertAlmostEqual(x, 3.0, delta=1e-6)
        self.assertAlmostEqual(y, 6.5, delta=1e-6)
        self.assertAlmostEqual(yaw, -1.0, delta=1e-6)

    # ---- faults -------------------------------------------------------------------------------
    def test_fault_laser_dropout(self):
        baseline = self.scan0.latest().ranges
        finite = [i for i, r in enumerate(baseline) if math.isfinite(r)]
        self.assertGreater(len(finite), 300)
        res = self.set_fault(fault("robot_0", laser_dropout=0.5))
        self.assertTrue(res.success, res.message)
        t0 = rospy.get_time() + 0.2  # measured after the fault was set (the test's clock may lag)
        self.scan0.first_stamped_after(t0 + 2.0)  # so every earlier scan has arrived (one topic: in order)
        scans = [m for m in self.scan0.stamped_after(t0) if m.header.stamp.to_sec() <= t0 + 2.0]
        self.assertGreaterEqual(len(scans), 19)
        # a dropped beam reads NaN (REP-117 invalid), not +Inf
        dropped = sum(1 for s in scans for i in finite if math.isnan(s.ranges[i]))
        self.assertEqual(sum(1 for s in scans for i in finite if math.isinf(s.ranges[i])), 0)
        fraction = dropped / float(len(scans) * len(finite))
        self.assertAlmostEqual(fraction, 0.5, delta=0.05)  # > 6 sigma for > 4500 beams

        res = self.set_fault(fault("robot_0"))  # clears
        self.assertTrue(res.success)
        t1 = rospy.get_time() + 0.2
        self.scan0.first_stamped_after(t1 + 0.5)
        cleared = self.scan0.stamped_after(t1)
        self.assertGreaterEqual(len(cleared), 5)
        for s in cleared:
            self.assertEqual(sum(1 for i in finite if not math.isfinite(s.ranges[i])), 0)

        for req, expected in [(fault("robot_0", laser_dropout=1.5), "laser_dropout"),
                              (fault("robot_0", laser_dropout=-0.1), "laser_dropout"),
                              (fault("robot_0", sensor_latency=-1.0), "sensor_latency"),
                              (fault("robot_9"), "unknown robot")]:
            res = self.set_fault(req)
            self.assertFalse(res.success)
            self.assertIn(expected, res.message)

    def test_fault_frozen_drive(self):
        pub = rospy.Publisher("/robot_2/cmd_vel", Twist, queue_size=10)
        wait_for_connection(pub)
        self.assertTrue(self.set_fault(fault("robot_2", drive_frozen=True)).success)
        x0 = self.pose_of("robot_2")[0]
        cmd = Twist()
        cmd.linear.x = -0.2
        publish_for(pub, cmd, 1.0)
        self.assertAlmostEqual(self.pose_of("robot_2")[0], x0, delta=1e-9)
        self.assertTrue(self.set_fault(fault("robot_2")).success)
        drive_until(pub, cmd, lambda: self.pose_of("robot_2")[0] < x0 - 0.1, 5.0)
        self.assertLess(self.pose_of("robot_2")[0], x0 - 0.1)  # backed up once repaired

    def test_fault_silenced_and_latency(self):
        # Silenced for at least 1 s of sim time (1.5 s by this process's clock, which may lag the
        # simulator's); measured from the stamps alone: a gap in odometry and scans, none in the
        # ground truth.
        silenced_at = rospy.get_time()
        self.assertTrue(self.set_fault(fault("robot_0", silenced=True)).success)
        self.truth["robot_0"].first_stamped_after(silenced_at + 1.5)
        resumed_at = rospy.get_time()
        self.assertTrue(self.set_fault(fault("robot_0")).success)  # speaks again
        # The first odometry and scan after that follow (on each topic, in order) all before.
        for rec in (self.odom["robot_0"], self.scan0, self.truth["robot_0"]):
            rec.first_stamped_after(resumed_at)

        def largest_gap(rec):
            stamps = sorted(m.header.stamp.to_sec() for m in rec.stamped_after(silenced_at - 1.0))
            return max(b - a for a, b in zip(stamps, stamps[1:]))

        self.assertGreater(largest_gap(self.odom["robot_0"]), 1.0)
        self.assertGreater(largest_gap(self.scan0), 1.0)
        self.assertAlmostEqual(largest_gap(self.truth["robot_0"]), 0.02, delta=1e-6)  # ground truth goes on

        self.assertTrue(self.set_fault(fault("robot_0", sensor_latency=0.5)).success)
        try:
            self.odom["robot_0"].first_stamped_after(rospy.get_time() + 1.0)
            period, truth_period = (self.period(rec) for rec in (self.odom["robot_0"], self.truth["robot_0"]))
            # Paused, no sample is released any more: the newest odometry that arrives is the last
            # one measured at least 0.5 s before the pause (within one odometry period), the newest
            # ground truth (never delayed) the last one measured before it (within its period).
            # Both stamps come from the simulator, no receive times: a slow test process cannot
            # shrink or stretch the measured delay.
            self.pause()
            try:
                self.wait_for_quiet([self.odom["robot_0"], self.truth["robot_0"]])
                lag = self.truth["robot_0"].latest().header.stamp.to_sec() - \
                    self.odom["robot_0"].latest().header.stamp.to_sec()
            finally:
                self.unpause()
            rospy.loginfo("latency 0.5 s: odometry %.3f s behind the ground truth at a pause", lag)
            self.assertGreater(lag, 0.5 - truth_period - 1e-6, "ground truth period %.3f s" % truth_period)
            self.assertLess(lag, 0.5 + period + 1e-6, "odometry period %.3f s" % period)
        finally:
            self.assertTrue(self.set_fault(fault("robot_0")).success)

    @staticmethod
    def period(recorder):
        """The median time between the stamps of a recorder's last second of messages [s]."""
        stamps = [m.header.stamp.to_sec() for m in recorder.stamped_after(rospy.get_time() - 1.0)]
        return sorted(b - a for a, b in zip(stamps, stamps[1:]))[len(stamps) // 2]

    @staticmethod
    def wait_for_quiet(recorders, quiet=0.5, timeout=10.0):
        """Wait (wall time) until none of the recorders got a message for `quiet` seconds."""
        counts, since = None, time.time()
        deadline = since + timeout
        while time.time() < deadline:
            now_counts = [len(r.messages) for r in recorders]
            if now_counts != counts:
                counts, since = now_counts, time.time()
            elif time.time() - since >= quiet:
                return
            time.sleep(0.05)
        raise AssertionError("messages still arriving %.0f s after the pause" % timeout)

    # ---- pause, reset -------------------------------------------------------------------------
    def test_pause_stops_sim_time(self):
        clock = []  # (wall receive time, sim time)
        sub = rospy.Subscriber("/clock", Clock, lambda m: clock.append((time.time(), m.clock.to_sec())))
        wait_for_wall(lambda: clock, 10.0, "/clock")
        self.pause()
        paused = time.time()
        # Only wall time passes while paused: watch the clock for 1 s of it. A /clock sent just
        # before the pause may still arrive (well within 0.2 s); nothing later.
        time.sleep(1.0)
        late = [(round(w - paused, 3), t) for (w, t) in clock if w > paused + 0.2]
        self.assertEqual(late, [], "sim time moved while paused: (wall s after the pause, sim time)")
        before = clock[-1][1]
        self.unpause()
        wait_for_wall(lambda: clock[-1][1] > before + 0.4, 10.0, "sim time to go on after unpause")
        sub.unregister()

    def test_zz_reset_puts_robots_back(self):
        pub = rospy.Publisher("/robot_2/cmd_vel", Twist, queue_size=10)
        wait_for_connection(pub)
        cmd = Twist()
        cmd.linear.x = -0.3
        cmd.angular.z = 0.5
        moved = lambda: math.hypot(self.pose_of("robot_2")[0] - 6.0, self.pose_of("robot_2")[1] - 1.5)  # noqa: E731
        drive_until(pub, cmd, lambda: moved() > 0.1, 5.0)
        self.assertGreater(moved(), 0.1)
        self.reset()
        x, y, yaw = self.wait_for_pose("robot_2", 6.0, 1.5, "robot_2 back at its world pose")
        self.assertAlmostEqual(x, 6.0, delta=1e-6)
        self.assertAlmostEqual(y, 1.5, delta=1e-6)
        self.assertAlmostEqual(yaw, 0.0, delta=1e-6)
        odom = self.odom["robot_2"]
        wait_until(lambda: abs(odom.latest().pose.pose.position.x) < 0.01, 5.0, "robot_2's odometry reset")
        o = odom.latest().pose.pose.position
        self.assertAlmostEqual(math.hypot(o.x, o.y), 0.0, delta=1e-6)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_services", SimServices, sys.argv)
