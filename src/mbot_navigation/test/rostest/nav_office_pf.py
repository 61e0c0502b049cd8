#!/usr/bin/env python3
"""rostest: the particle filter (pf_localization) in the real simulator. robot_0 drives a route
of four goals through the office (test/fixtures/worlds/nav_office_pf.world.yaml: noisy laser and
odometry, the crate and the walking person, which the map does not have) through its move_base
action, localized by the filter alone (fleet_navigation.launch localization:=pf). The test
compares the filter with the simulator's ground truth:

- /robot_0/amcl_pose against /robot_0/base_pose_ground_truth at the same stamp (the scan's):
  position error p95 and max, heading error p95 (bounds from the .test file);
- tf map -> robot_0/base_footprint looked up at the ground truth's stamps (10 Hz) while driving:
  the share of lookups that succeed within LOOKUP_WAIT sim s of their stamp, and how far they land
  from the truth (p95, max);
- the filter keeps updating: between two estimates the robot drove at most 3 x update_min_d plus
  one scan period at the nav node's top speed (two updates lost in a row, or a stalled filter);
- the route was driven: every goal SUCCEEDED with the ground truth within GOAL_RADIUS of it, each
  leg at least 0.9 x its A* optimum on the static map, no contact; and the filter's last estimate
  is nearer the truth than odometry alone at the end.
"""
import bisect
import math
import threading
import unittest
from collections import deque

import numpy as np
import rospy
import rostest
import tf2_ros
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseWithCovarianceStamped
from nav_msgs.msg import Odometry

from mbot_common.geometry import angle_diff as signed_angle_diff, yaw_of
from mbot_navigation.grid_paths import clearance, path_lengths_from, world_to_cell
from nav_test_tools import (Contacts, Track, action_client, angle_diff, make_goal, run_goal, state_name,
                            wait_for_map, wait_until)

ROBOT_RADIUS = 0.15  # [m] mbot's footprint (mbot_description/urdf/mbot.urdf)
# From the south-east room (3, -4): to the north-east room (its door, the corridor, the room's
# door), to the north-west rooms' east room (via the north corridor), to the south-west hall where
# the person walks (corridor, hall door), and back to the south-east room through the hall's door.
GOALS = [(8.0, 3.0, math.pi / 2), (-3.0, 7.5, math.pi), (-5.0, -5.0, 0.0), (3.0, -7.0, 0.0)]
GOAL_TIMEOUT = 150.0  # [s sim] per goal
# [m] ground truth to goal when the goal succeeds: the nav node judges its goal (xy_goal_tolerance
# 0.1 m) on the filter's estimate, so the filter's error there adds to it
GOAL_RADIUS = 0.25
TF_EVERY = 5          # look tf up at every 5th ground-truth sample (10 Hz)
LOOKUP_WAIT = 1.0     # [s sim] a lookup that cannot be made this long after its stamp fails
SCAN_PERIOD = 0.1     # [s] the laser's (mbot_sim README: 10 Hz)
TRUTH_RATE = 50.0     # [Hz] the simulator's ground truth (mbot_sim README)
MAX_HOLE = 0.1        # [s] longest gap in the ground truth to interpolate across


def compose(a, b):
    """Planar pose a * b."""
    c, s = math.cos(a[2]), math.sin(a[2])
    return (a[0] + c * b[0] - s * b[1], a[1] + s * b[0] + c * b[1], a[2] + b[2])


def errors(estimate, truth):
    """(position error [m], heading error [rad]) of an (x, y, yaw) against the truth."""
    return math.hypot(estimate[0] - truth[0], estimate[1] - truth[1]), angle_diff(estimate[2], truth[2])


def truth_at(history, stamps, stamp):
    """The ground truth (x, y, yaw, distance driven) at `stamp` [ns]: the sample with that stamp,
    else interpolated between the two around it when they are at most MAX_HOLE apart (this
    process may have missed a sample on a busy machine); None without them."""
    if stamp in history:
        return history[stamp]
    i = bisect.bisect(stamps, stamp)
    if i == 0 or i == len(stamps) or stamps[i] - stamps[i - 1] > MAX_HOLE * 1e9:
        return None
    a, b = history[stamps[i - 1]], history[stamps[i]]
    f = (stamp - stamps[i - 1]) / float(stamps[i] - stamps[i - 1])
    return (a[0] + f * (b[0] - a[0]), a[1] + f * (b[1] - a[1]), a[2] + f * signed_angle_diff(b[2], a[2]),
            a[3] + f * (b[3] - a[3]))


class Latest(object):
    """Every message of a pose topic as (stamp [ns], x, y, yaw), in arrival order."""

    def __init__(self, topic, msg_type):
        self._lock = threading.Lock()
        self.samples = []
        rospy.Subscriber(topic, msg_type, self._on_msg, queue_size=100)

    def _on_msg(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        with self._lock:
            self.samples.append((msg.header.stamp.to_nsec(), p.x, p.y, yaw_of(q)))

    def copy(self):
        with self._lock:
            return list(self.samples)


class TfProbe(object):
    """While started, looks up tf map -> <robot>/base_footprint at every TF_EVERY-th ground-truth
    stamp, as soon as the transform is there (a sim-time timer retries), and compares it with that
    ground truth. A lookup still impossible LOOKUP_WAIT sim s after its stamp counts as failed."""

    def __init__(self, robot):
        self.base = robot + "/base_footprint"
        self.buffer = tf2_ros.Buffer(cache_time=rospy.Duration(60.0))
        self.listener = tf2_ros.TransformListener(self.buffer)
        self._lock = threading.Lock()
        self.pending = deque()  # (stamp, (x, y, yaw)) not looked up yet
        self.errors = []        # (position error, heading error) of each lookup
        self.failed = []        # stamps [s] of the lookups that failed
        self.since = None  # rospy.Time: look up the samples stamped from then on (start())
        self.wait = rospy.Duration(LOOKUP_WAIT)
        self._count = 0
        rospy.Subscriber("/%s/base_pose_ground_truth" % robot, Odometry, self._on_truth, queue_size=2000)
        self._timer = rospy.Timer(rospy.Duration(0.05), self._tick)

    def _on_truth(self, msg):
        self._count += 1
        if self.since is not None and msg.header.stamp >= self.since and self._count % TF_EVERY == 0:
            p = msg.pose.pose.position
            with self._lock:
                self.pending.append((msg.header.stamp, (p.x, p.y, yaw_of(msg.pose.pose.orientation))))

    def _tick(self, _event):
        now = rospy.Time.now()
        with self._lock:
            while self.pending:
                stamp, truth = self.pending[0]
                if self.buffer.can_transform("map", self.base, stamp):
                    t = self.buffer.lookup_transform("map", self.base, stamp).transform
                    self.errors.append(errors((t.translation.x, t.translation.y, yaw_of(t.rotation)), truth))
                elif now - stamp > self.wait:
                    self.failed.append(stamp.to_sec())
                else:
                    break  # not yet: the next tick tries again
                self.pending.popleft()

    def start(self):
        self.since = rospy.Time.now()

    def stop(self):
        self.since = None
        self._timer.shutdown()


def stats(values):
    """p50, p95 and max of a list of numbers."""
    return np.percentile(values, 50), np.percentile(values, 95), max(values)


class PfOffice(unittest.TestCase):
    def test_route_localized_by_the_particle_filter(self):
        robot = rospy.get_param("~robot")
        bounds = {k: rospy.get_param("~" + k) for k in (
            "position_error_p95", "position_error_max", "heading_error_p95", "tf_error_p95", "tf_error_max",
            "tf_success_rate")}
        track = Track(robot, history=True)
        contacts = Contacts([robot])
        estimates = Latest("/%s/amcl_pose" % robot, PoseWithCovarianceStamped)
        probe = TfProbe(robot)
        grid = wait_for_map()
        free = clearance(grid) >= ROBOT_RADIUS
        client = action_client(robot)
        # (their parameters are set by now) the filter updates at the first scan after update_min_d
        # of travel (on odometry), so an estimate comes every update_min_d + one scan at top speed.
        # Now and then one or two in a row go missing (10 runs: up to 0.47 m between estimates with
        # update_min_d 0.2 m; cause not pinned down): the bound catches a filter that stops updating.
        update_min_d = rospy.get_param("/%s/pf_localization/update_min_d" % robot)
        max_speed = rospy.get_param("/%s/move_base/DWAPlannerROS/max_vel_x" % robot)
        max_gap = 3.0 * update_min_d + max_speed * SCAN_PERIOD
        start = track.wait()
        wait_until(lambda: estimates.copy(), 30.0, "the filter's first estimate on /%s/amcl_pose" % robot)
        first_estimate = len(estimates.copy())
        # start with a filter that keeps up (its start-up in wall time is not measured)
        wait_until(lambda: probe.buffer.can_transform("map", probe.base, rospy.Time.now() - probe.wait),
                   30.0, "tf map -> %s within %.1f sim s of now" % (probe.base, LOOKUP_WAIT))

        probe.start()
        route_start = rospy.get_time()
        report = []
        for x, y, yaw in GOALS:
            here = track.pose
            optimum = path_lengths_from(free, grid.resolution, world_to_cell(grid, here[0], here[1]))[
                world_to_cell(grid, x, y)]
            self.assertTrue(math.isfinite(optimum), "goal (%.1f, %.1f) unreachable on the map" % (x, y))
            track.reset()
            state, text, seconds = run_goal(client, make_goal(x, y, yaw), timeout=GOAL_TIMEOUT)
            pose = track.pose
            report.append("goal (%.1f, %.1f): %s in %.1f sim s, drove %.2f m (optimum %.2f m), truly %.3f m off" % (
                x, y, state_name(state), seconds, track.length, optimum, math.hypot(pose[0] - x, pose[1] - y)))
            rospy.loginfo("nav_office_pf: %s", report[-1])
            self.assertEqual(state, GoalStatus.SUCCEEDED, "goal (%.1f, %.1f): %s: %s\n%s" % (
                x, y, state_name(state), text, "\n".join(report)))
            self.assertLess(math.hypot(pose[0] - x, pose[1] - y), GOAL_RADIUS, report[-1])
            self.assertGreater(track.length, 0.9 * optimum, report[-1])  # the robot drove the leg
        probe.stop()
        route_seconds = rospy.get_time() - route_start

        # the filter's estimates, each against the ground truth at its stamp (the scan's)
        history = dict(track.history)
        stamps = sorted(history)
        route = estimates.copy()[first_estimate - 1:]  # from the last estimate before the first goal
        # ... unless that one came before this test recorded any ground truth (the robot stood
        # still then; a slow start of the test's subscriber is no gap in the filter's estimates)
        route = [e for e in route if stamps and e[0] >= stamps[0]]
        # ... and the same at the end: an estimate newer than the last ground truth this test
        # recorded came after it stopped listening (the run of 9d4f972 failed on one at 300.3 s)
        route = [e for e in route if e[0] <= stamps[-1]]
        truths = [truth_at(history, stamps, e[0]) for e in route]
        unmatched = [e[0] * 1e-9 for e, t in zip(route, truths) if t is None]
        matched = [(errors(e[1:], t[:3]), t[3]) for e, t in zip(route, truths) if t is not None]
        position = [m[0][0] for m in matched]
        heading = [m[0][1] for m in matched]
        driven = [m[1] for m in matched]
        gaps = np.diff(driven)
        # odometry alone at the end: the odom frame starts where the robot starts
        end = stamps[-1]
        odom = probe.buffer.lookup_transform(robot + "/odom", probe.base, rospy.Time(0, end),
                                             rospy.Duration(LOOKUP_WAIT)).transform
        odom_error = errors(compose(start, (odom.translation.x, odom.translation.y, yaw_of(odom.rotation))),
                            history[end][:3])
        tf_position = [e[0] for e in probe.errors]
        tf_heading = [e[1] for e in probe.errors]

        lines = report + [
            "estimates: %d over %.1f m driven, %d without a ground truth at their stamp" % (
                len(route), driven[-1] - driven[0], len(unmatched)),
            "position error [m]: p50 %.3f p95 %.3f max %.3f" % stats(position),
            "heading error [rad]: p50 %.4f p95 %.4f max %.4f" % stats(heading),
            "driven between estimates [m]: max %.3f (bound %.3f)" % (gaps.max(), max_gap),
            "route: %.1f sim s" % route_seconds,
            "tf map -> base: %d lookups, %d failed; position error p50 %.3f p95 %.3f max %.3f m, "
            "heading p95 %.4f rad" % ((len(probe.errors), len(probe.failed)) + stats(tf_position) + (
                np.percentile(tf_heading, 95),)),
            "odometry alone at the end: %.2f m, %.3f rad off" % odom_error]
        summary = "\n".join(lines)
        rospy.loginfo("nav_office_pf:\n%s", summary)
        print(summary)

        self.assertEqual(unmatched, [], summary)
        self.assertLessEqual(np.percentile(position, 95), bounds["position_error_p95"], summary)
        self.assertLessEqual(max(position), bounds["position_error_max"], summary)
        self.assertLessEqual(np.percentile(heading, 95), bounds["heading_error_p95"], summary)
        self.assertLessEqual(gaps.max(), max_gap, summary)
        success = len(probe.errors) / float(len(probe.errors) + len(probe.failed))
        self.assertGreaterEqual(success, bounds["tf_success_rate"], summary)
        # (the probe saw the whole route: the last samples may still be pending)
        self.assertGreater(len(probe.errors), 0.9 * route_seconds * TRUTH_RATE / TF_EVERY, summary)
        self.assertLessEqual(np.percentile(tf_position, 95), bounds["tf_error_p95"], summary)
        self.assertLessEqual(max(tf_position), bounds["tf_error_max"], summary)
        self.assertLessEqual(np.percentile(tf_heading, 95), bounds["heading_error_p95"], summary)
        # the filter ends nearer the truth than odometry alone (odometry's drift depends on the
        # route: a fixed bound failed on a correct run whose odometry ended 0.068 m off)
        self.assertGreater(odom_error[0], position[-1], summary)
        self.assertEqual(contacts.events, [], "contacts: %s\n%s" % (contacts.events, summary))


if __name__ == "__main__":
    rospy.init_node("nav_office_pf_test")
    rostest.rosrun("mbot_navigation", "nav_office_pf", PfOffice)
