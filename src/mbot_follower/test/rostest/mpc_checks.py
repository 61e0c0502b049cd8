#!/usr/bin/python3
"""The predictive law (controller mpc) on a formation fleet, measured from the simulator's
ground truth like formation_checks.py: the triangle drives east to (4, 0), then turns north to
(4, 5) and switches to a column on the way. Checks: the steady slot error while the leader
drives, the switch done, no two robots' centres closer than 2 radii + 0.05 m at any sample, no
contact; and that the law did run: every follower published its predicted path (sim-time
stamps one step apart) and its solve statistics.
"""
import json
import math
import unittest

import rospy
import rostest
from nav_msgs.msg import Path
from std_msgs.msg import String

from mbot_follower.fleet_probe import FleetProbe

RADIUS = 0.15          # [m] the mbot's
CLEARANCE = 2 * RADIUS + 0.05


class MpcChecks(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("mpc_checks")
        cls.robots = rospy.get_param("~robots")
        cls.paths, cls.stats = {}, {}
        for robot in cls.robots[1:]:
            rospy.Subscriber("/%s/predicted_path" % robot, Path, cls.on_path, robot, queue_size=1)
            rospy.Subscriber("/%s/follower_controller/mpc_stats" % robot, String, cls.on_stats, robot, queue_size=1)
        cls.probe = FleetProbe(cls.robots)
        cls.probe.wait_for_fleet()

    @classmethod
    def on_path(cls, msg, robot):
        cls.paths[robot] = msg

    @classmethod
    def on_stats(cls, msg, robot):
        cls.stats[robot] = json.loads(msg.data)

    def arrive(self, x, y, theta, timeout=240.0):
        p = self.probe
        p.send_target(x, y, theta)
        p.wait(lambda: p.state() in ("FORMING", "NAVIGATING"), 10.0, "the goal to be taken")
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), timeout, "ARRIVED")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)

    def moving_errors(self, since, until):
        """The followers' slot errors in the samples since..until while NAVIGATING with the
        leader at 0.1 m/s or more."""
        errors = []
        for (t, _, poses, speeds, a) in self.probe.samples_in(("NAVIGATING",), since):
            if t <= until and a is not None and speeds.get(a.leader, 0.0) >= 0.1:
                errors += self.probe.slot_errors(poses, a).values()
        return errors

    def test_mpc_formation(self):
        p = self.probe
        self.assertEqual(p.state(), "IDLE")
        self.arrive(4.0, 0.0, math.pi / 2)
        leg1 = rospy.get_time()
        set_off = [t for (t, _, _, speeds, a) in p.samples_in(("NAVIGATING",))
                   if a is not None and speeds.get(a.leader, 0.0) >= 0.1]
        self.assertTrue(set_off, "the leader never drove at 0.1 m/s or more")
        errors = self.moving_errors(set_off[0] + 3.0, leg1)
        self.assertGreater(len(errors), 20, "too few samples while the leader drove east")
        rms = math.sqrt(sum(e * e for e in errors) / len(errors))
        rospy.loginfo("mpc: steady slot RMS east %.3f m, max %.3f m", rms, max(errors))
        self.assertLess(rms, 0.15)

        # north, with a switch to a column on the way (the leader turns, the slots move)
        p.send_target(4.0, 5.0, math.pi / 2)
        p.wait(lambda: p.state() == "NAVIGATING" and p.truth[p.status.leader][1].y > 1.5, 120.0,
               "the leader on its way north")
        t_switch = rospy.get_time()
        p.formation_pub.publish(String("column"))
        p.wait(lambda: p.assignment.formation == "column", 5.0, "the column assignment")
        t_reached, _ = p.wait_switch_done("column", t_switch, 60.0)
        rospy.loginfo("mpc: column reached %.1f s after the switch", t_reached - t_switch)
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 240.0, "ARRIVED in the north")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        final = p.slot_errors({r: v[1] for r, v in p.truth.items()}, p.assignment)
        self.assertLess(max(final.values()), 0.3, "final slot errors %s" % final)

        # clearance: every pair of robots at every sample of the run
        closest = (float("inf"), None)
        for (t, _, poses, _, _) in p.samples_in(("IDLE", "FORMING", "NAVIGATING", "ARRIVED")):
            names = sorted(poses)
            for i, a in enumerate(names):
                for b in names[i + 1:]:
                    d = math.hypot(poses[a].x - poses[b].x, poses[a].y - poses[b].y)
                    if d < closest[0]:
                        closest = (d, "%s-%s at t=%.1f" % (a, b, t))
        rospy.loginfo("mpc: closest centres %.3f m (%s)", closest[0], closest[1])
        self.assertGreaterEqual(closest[0], CLEARANCE, "robots closer than 2 radii + 0.05 m: %s" % (closest,))
        self.assertEqual(p.contacts, [], "contacts: %d" % len(p.contacts))

        # the law ran: predicted paths in sim time, one step apart, and its statistics
        for robot in self.robots[1:]:
            self.assertIn(robot, self.paths, "%s published no predicted_path" % robot)
            path = self.paths[robot]
            stamps = [ps.header.stamp.to_sec() for ps in path.poses]
            self.assertEqual(path.header.frame_id, "map")
            self.assertGreaterEqual(len(stamps), 11, "%s: a horizon of %d poses" % (robot, len(stamps)))
            self.assertAlmostEqual(stamps[0], path.header.stamp.to_sec(), places=6)
            steps = [b - a for a, b in zip(stamps, stamps[1:])]
            self.assertAlmostEqual(min(steps), max(steps), places=6)
            self.assertGreater(steps[0], 0.0)
            self.assertLess(abs(stamps[0] - rospy.get_time()), 5.0, "%s: its path is not of sim time now" % robot)
            stats = self.stats.get(robot)
            self.assertIsNotNone(stats, "%s published no mpc_stats" % robot)
            rospy.loginfo("mpc: %s %s", robot, stats)
            self.assertGreater(stats["solves"], 200, "%s: %s" % (robot, stats))
            # the solver, not the fallback, commanded most periods (the budget here is 1 s wall)
            self.assertLess(stats["fallbacks"], 0.05 * stats["solves"], "%s: %s" % (robot, stats))


if __name__ == "__main__":
    rostest.rosrun("mbot_follower", "mpc_formation", MpcChecks)
