#!/usr/bin/env python3
"""rostest for pf_localization: this node plays the map server and the simulator.

A 10 m x 8 m room (walls, an interior wall, a shelf, a box, a pillar) is published on /map; a
robot drives a route in it with drifting odometry (tf <robot>/odom -> <robot>/base_footprint),
a laser mounted on it (static tf to <robot>/base_laser) and scans ray-cast from the true pose.
Checks: amcl_pose converges to the truth from the launch file's initial pose, tf map -> odom is
post-dated by transform_tolerance, and a /<robot>/initialpose re-initializes the filter, which
then converges again.
"""
import math
import re
import time
import unittest

import numpy as np
import rosgraph
import rospy
import rostest
import tf2_ros
from geometry_msgs.msg import PoseArray, PoseWithCovarianceStamped, TransformStamped
from nav_msgs.msg import OccupancyGrid
from rosgraph_msgs.msg import Clock, Log
from sensor_msgs.msg import LaserScan
from tf2_msgs.msg import TFMessage

from mbot_common.geometry import angle_diff, normalize_angle, quaternion_from_yaw, yaw_of
from mbot_common.waits import wait_for_wall as wait_for  # these tests publish /clock themselves

PKG = "mbot_localization"
RESOLUTION = 0.05  # [m/cell]
ORIGIN = (-0.5, -0.25)  # [m]
WIDTH, HEIGHT = 200, 160  # [cells]
STEP = 0.1  # [s] sim time per step (10 Hz laser)
BEAMS = 180
RANGE_MAX = 8.0  # [m]
MOUNT = (0.1, 0.0)  # laser in base_footprint [m]
WAYPOINTS = [(2.0, 4.5), (5.0, 4.2), (5.0, 1.0), (8.5, 1.0), (8.5, 3.8), (5.0, 4.2), (2.0, 4.5),
             (1.0, 1.0)]


def make_room():
    """Occupancy (bool, [row y][column x]) of the room; same layout as the gtest's room."""
    xs = ORIGIN[0] + (np.arange(WIDTH) + 0.5) * RESOLUTION
    ys = ORIGIN[1] + (np.arange(HEIGHT) + 0.5) * RESOLUTION
    cx, cy = np.meshgrid(xs, ys)
    occupied = np.zeros((HEIGHT, WIDTH), dtype=bool)
    x_max, y_max = ORIGIN[0] + WIDTH * RESOLUTION, ORIGIN[1] + HEIGHT * RESOLUTION
    boxes = [(ORIGIN[0], ORIGIN[1], x_max, ORIGIN[1] + 0.1), (ORIGIN[0], y_max - 0.1, x_max, y_max),
             (ORIGIN[0], ORIGIN[1], ORIGIN[0] + 0.1, y_max), (x_max - 0.1, ORIGIN[1], x_max, y_max),
             (3.5, -0.25, 3.6, 2.8), (6.0, 5.0, 9.5, 5.1), (6.5, 1.8, 7.5, 2.6), (2.0, 5.5, 2.4, 5.9)]
    for x0, y0, x1, y1 in boxes:
        occupied |= (cx >= x0) & (cx <= x1) & (cy >= y0) & (cy <= y1)
    return occupied


def ray_cast(occupied, x, y, yaw, rng):
    """Ranges of a full-circle laser at (x, y, yaw) [m, rad]: march in 1 cm steps; +Inf = none."""
    angles = yaw - math.pi + np.arange(BEAMS) * (2.0 * math.pi / BEAMS)
    r = np.arange(0.0, RANGE_MAX, 0.01)
    px = x + np.outer(np.cos(angles), r)
    py = y + np.outer(np.sin(angles), r)
    mx = np.floor((px - ORIGIN[0]) / RESOLUTION).astype(int)
    my = np.floor((py - ORIGIN[1]) / RESOLUTION).astype(int)
    inside = (mx >= 0) & (my >= 0) & (mx < WIDTH) & (my < HEIGHT)
    hit = ~inside
    hit[inside] = occupied[my[inside], mx[inside]]
    first = np.argmax(hit, axis=1)
    ranges = np.where(hit.any(axis=1), r[first] + rng.normal(0.0, 0.01, BEAMS), np.inf)
    return ranges.astype(np.float32)


def compose(a, b):
    """Planar pose a * b."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1],
            normalize_angle(a[2] + b[2]))


def set_yaw(q, yaw):
    q.x, q.y, q.z, q.w = quaternion_from_yaw(yaw)


def connected_to_all(topic):
    """True once a rospy Subscriber (Publisher) has a connection to every publisher (subscriber)
    of its topic that the master knows (rospy counts its own node's too)."""
    other_side = 0 if isinstance(topic, rospy.Subscriber) else 1
    nodes = dict(rosgraph.Master(rospy.get_name()).getSystemState()[other_side]).get(topic.resolved_name, [])
    return topic.get_num_connections() >= len(nodes)


def cloud_spread(cloud):
    """Standard deviation [m] of the x of a PoseArray's poses."""
    xs = [p.position.x for p in cloud.poses]
    mean = sum(xs) / len(xs)
    return math.sqrt(sum((x - mean) ** 2 for x in xs) / len(xs))


class PfLocalizationTest(unittest.TestCase):
    def setUp(self):
        self.robot = rospy.get_param("~robot")
        self.truth = (rospy.get_param("~start_x"), rospy.get_param("~start_y"),
                      rospy.get_param("~start_a"))
        self.odom = (0.0, 0.0, 0.0)
        self.now = rospy.Time(50)  # sim time [s]
        self.rng = np.random.RandomState(7)
        self.occupied = make_room()
        self.truth_at = {}  # scan stamp -> true pose
        self.waypoint = 0

        self.clock_pub = rospy.Publisher("/clock", Clock, queue_size=10)
        self.tf_pub = rospy.Publisher("/tf", TFMessage, queue_size=100)
        self.map_pub = rospy.Publisher("/map", OccupancyGrid, queue_size=1, latch=True)
        self.scan_pub = rospy.Publisher("/%s/scan" % self.robot, LaserScan, queue_size=10)
        self.initial_pub = rospy.Publisher("/%s/initialpose" % self.robot,
                                           PoseWithCovarianceStamped, queue_size=1)
        self.poses = []
        self.pose_sub = rospy.Subscriber("/%s/amcl_pose" % self.robot, PoseWithCovarianceStamped,
                                         self.poses.append)
        self.clouds = []
        self.cloud_sub = rospy.Subscriber("/%s/particlecloud" % self.robot, PoseArray,
                                          self.clouds.append)
        self.log = []  # what pf_localization said (/rosout): when it took the map or an initial pose
        self.log_sub = rospy.Subscriber("/rosout", Log, self.on_log)
        self.tolerance = rospy.Duration(rospy.get_param("/%s/pf_localization/transform_tolerance" % self.robot))
        self.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(600))
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.static_tf = tf2_ros.StaticTransformBroadcaster()

    def on_log(self, msg):
        if msg.name.endswith("pf_localization"):
            self.log.append(msg.msg)

    def said(self, pattern):
        """How many of pf_localization's log lines start with the regular expression `pattern`."""
        return sum(1 for line in list(self.log) if re.match(pattern, line))

    # ------------------------------------------------------------ the simulated world
    def publish_world(self):
        self.clock_pub.publish(Clock(clock=self.now))
        grid = OccupancyGrid()
        grid.header.frame_id = "map"
        grid.info.resolution = RESOLUTION
        grid.info.width, grid.info.height = WIDTH, HEIGHT
        grid.info.origin.position.x, grid.info.origin.position.y = ORIGIN
        grid.info.origin.orientation.w = 1.0
        grid.data = (self.occupied.astype(np.int8) * 100).ravel().tolist()
        self.map_pub.publish(grid)
        mount = TransformStamped()
        mount.header.frame_id = self.robot + "/base_footprint"
        mount.child_frame_id = self.robot + "/base_laser"
        mount.transform.translation.x, mount.transform.translation.y = MOUNT
        mount.transform.rotation.w = 1.0
        self.static_tf.sendTransform(mount)

    def drive(self):
        """One step of a turn-then-drive controller along WAYPOINTS; returns the motion."""
        goal = WAYPOINTS[self.waypoint % len(WAYPOINTS)]
        dx, dy = goal[0] - self.truth[0], goal[1] - self.truth[1]
        if math.hypot(dx, dy) < 0.15:
            self.waypoint += 1
            return (0.0, 0.0, 0.0)
        error = angle_diff(math.atan2(dy, dx), self.truth[2])
        return (0.05 if abs(error) < 0.3 else 0.005, 0.0, max(-0.15, min(0.15, error)))

    def step(self):
        """One scan of sim time; returns once the node took the scan (it re-sends map -> odom,
        post-dated by transform_tolerance, with every scan)."""
        self.now += rospy.Duration(STEP)
        motion = self.drive()
        self.truth = compose(self.truth, motion)
        measured = (motion[0] * (1.0 + self.rng.normal(0.0, 0.03)), 0.0,
                    motion[2] + self.rng.normal(0.0, 0.005))
        self.odom = compose(self.odom, measured)
        self.clock_pub.publish(Clock(clock=self.now))

        t = TransformStamped()
        t.header.stamp = self.now
        t.header.frame_id = self.robot + "/odom"
        t.child_frame_id = self.robot + "/base_footprint"
        t.transform.translation.x, t.transform.translation.y = self.odom[0], self.odom[1]
        set_yaw(t.transform.rotation, self.odom[2])
        self.tf_pub.publish(TFMessage(transforms=[t]))

        laser = compose(self.truth, (MOUNT[0], MOUNT[1], 0.0))
        scan = LaserScan()
        scan.header.stamp = self.now
        scan.header.frame_id = self.robot + "/base_laser"
        scan.angle_min, scan.angle_max = -math.pi, math.pi - 2.0 * math.pi / BEAMS
        scan.angle_increment = 2.0 * math.pi / BEAMS
        scan.range_min, scan.range_max = 0.1, RANGE_MAX
        scan.ranges = ray_cast(self.occupied, laser[0], laser[1], laser[2], self.rng).tolist()
        self.scan_pub.publish(scan)
        self.truth_at[self.now] = self.truth
        # Until then the clock ticks on by 1 ms every 0.1 s wall (at most half a step), as a
        # simulator's would: a node that waits for a transform in sim time sleeps until the
        # clock moves.
        odom_frame = self.robot + "/odom"
        clock = [self.now, time.time()]

        def taken():
            if self.buffer.can_transform("map", odom_frame, self.now + self.tolerance):
                return True
            if clock[0] < self.now + rospy.Duration(0.5 * STEP) and time.time() > clock[1] + 0.1:
                clock[0] += rospy.Duration(0.001)
                clock[1] = time.time()
                self.clock_pub.publish(Clock(clock=clock[0]))
            return False

        wait_for(taken, 10, "tf map -> odom for the scan at %.1f s" % self.now.to_sec())

    # ------------------------------------------------------------ checks
    def pose_error(self, msg):
        truth = self.truth_at[msg.header.stamp]
        p = msg.pose.pose
        return (math.hypot(p.position.x - truth[0], p.position.y - truth[1]),
                abs(angle_diff(yaw_of(p.orientation), truth[2])))

    def drive_and_check(self, steps, label):
        count = len(self.poses)
        for _ in range(steps):
            self.step()
        updates = self.poses[count:]
        self.assertGreater(len(updates), 15, "%s: too few filter updates" % label)
        last = updates[-1]
        distance, angle = self.pose_error(last)
        worst = max(self.pose_error(m)[0] for m in updates[10:])
        rospy.loginfo("%s: %d updates, final error %.3f m %.3f rad, worst after 10 updates "
                      "%.3f m, %d particles", label, len(updates), distance, angle, worst,
                      len(self.clouds[-1].poses))
        self.assertEqual(last.header.frame_id, "map")
        self.assertLess(distance, 0.1, label)
        self.assertLess(angle, 0.1, label)
        self.assertLess(worst, 0.15, label)
        return last

    def test_converges_from_initial_pose_and_after_initialpose(self):
        for sub in (self.pose_sub, self.cloud_sub):
            wait_for(lambda: sub.get_num_connections() > 0, 30, "a publisher on " + sub.name)
        for pub in (self.scan_pub, self.tf_pub, self.clock_pub, self.map_pub):
            wait_for(lambda: pub.get_num_connections() > 0, 30, "a subscriber on " + pub.name)
        wait_for(lambda: connected_to_all(self.log_sub), 30, "every publisher on /rosout")
        wait_for(lambda: connected_to_all(self.static_tf.pub_tf), 30, "every subscriber on /tf_static")
        self.publish_world()
        wait_for(lambda: self.said(r"pf_localization: map \d+ x \d+ at") > 0, 30, "pf_localization to take the map")

        # 1. from the launch file's initial pose (0.3 m, 0.2 rad off)
        self.drive_and_check(150, "initial pose from args")

        # map -> odom is re-sent with every scan, post-dated by transform_tolerance (0.1 s)
        latest = self.buffer.lookup_transform("map", self.robot + "/odom", rospy.Time(0))
        self.assertEqual(latest.header.stamp, self.now + self.tolerance)
        # and map -> odom -> base lands on the truth
        map_odom = (latest.transform.translation.x, latest.transform.translation.y,
                    yaw_of(latest.transform.rotation))
        base = compose(map_odom, self.odom)
        self.assertLess(math.hypot(base[0] - self.truth[0], base[1] - self.truth[1]), 0.1)
        settled_spread = cloud_spread(self.clouds[-1])

        # 2. rviz "2D Pose Estimate": 0.4 m and 0.25 rad off; the filter restarts there
        guess = PoseWithCovarianceStamped()
        guess.header.frame_id = "map"
        guess.header.stamp = self.now
        guess.pose.pose.position.x = self.truth[0] - 0.4
        guess.pose.pose.position.y = self.truth[1]
        set_yaw(guess.pose.pose.orientation, self.truth[2] - 0.25)
        guess.pose.covariance[0] = guess.pose.covariance[7] = 0.25
        guess.pose.covariance[35] = 0.0685
        wait_for(lambda: self.initial_pub.get_num_connections() > 0, 30, "initialpose subscriber")
        count = len(self.clouds)
        said = self.said(r"pf_localization: initial pose \(")
        self.initial_pub.publish(guess)
        wait_for(lambda: self.said(r"pf_localization: initial pose \(") > said, 10,
                 "pf_localization to take initialpose")
        self.step()  # the first scan after a new initial pose is an update without motion
        wait_for(lambda: len(self.clouds) > count, 10, "the update after initialpose")
        # the particles themselves: one scan already pins the weighted covariance (the beam
        # scores multiply), but the set is not resampled before the second update
        restarted = cloud_spread(self.clouds[count])
        rospy.loginfo("particle spread in x: settled %.4f m, right after initialpose %.4f m", settled_spread, restarted)
        self.assertGreater(restarted, 4.0 * settled_spread,
                           "the particles did not spread out again: initialpose was ignored")
        self.drive_and_check(150, "after initialpose")


if __name__ == "__main__":
    rospy.init_node("test_pf_localization")
    rostest.rosrun(PKG, "pf_localization_wiring", PfLocalizationTest)
