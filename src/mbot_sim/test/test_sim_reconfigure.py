#!/usr/bin/python3
"""rostest (sim_reconfigure.test): live tuning of stage_node with dynamic_reconfigure.

- The server starts with the values the node runs with: ~real_time_factor (4, not the world file's
  5 nor the .cfg default 1) and the world file's noise.
- real_time_factor 10 -> 1: sim time runs several times slower over wall time, and it goes on at
  once after the change (the pacing is re-anchored, so it neither waits for the fast factor's lead
  to pass nor catches up).
- laser_range 0 -> 0.05 -> 0: the spread of one beam of a robot standing still goes from 0 to about
  0.05 m and back; the other noise keys stay as they were.
- Out-of-range values are clamped by dynamic_reconfigure, a NaN is refused by the node, and the
  simulator keeps running.
"""
import math
import sys
import time
import unittest

import rospy
import rostest
from dynamic_reconfigure.client import Client
from sensor_msgs.msg import LaserScan

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import Recorder, wait_until  # noqa: E402

BEAM = 0           # -pi: backwards, at the wall 1.9 m behind robot_0
SCANS = 20         # scans per spread (2 s sim at 10 Hz)
RATE_WINDOW = 3.0  # [s wall] a rate measurement


def spread(values):
    mean = sum(values) / len(values)
    return math.sqrt(sum((v - mean) ** 2 for v in values) / len(values))


def sim_rate(window):
    """Sim seconds per wall second over `window` wall seconds: a measurement over wall time,
    not a wait for something to happen."""
    wall0, sim0 = time.time(), rospy.get_time()
    time.sleep(window)
    return (rospy.get_time() - sim0) / (time.time() - wall0)


class SimReconfigure(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_reconfigure")
        cls.client = Client("/stage_node", timeout=30.0)
        cls.scans = Recorder("/robot_0/scan", LaserScan)
        cls.scans.wait_for_first()

    def set(self, **changes):
        """Set through the server; the reply is the configuration in force (after clamping)."""
        return self.client.update_configuration(changes)

    def beam_spread(self, margin=0.5):
        """Spread of BEAM over SCANS scans measured from `margin` sim seconds after now on (the
        test's clock may be a little behind the simulator's)."""
        t = rospy.get_time() + margin
        wait_until(lambda: len(self.scans.stamped_after(t)) >= SCANS, 30.0, "%d scans after t = %.2f" % (SCANS, t))
        ranges = [s.ranges[BEAM] for s in self.scans.stamped_after(t)[:SCANS]]
        self.assertTrue(all(math.isfinite(r) for r in ranges), ranges)
        return spread(ranges)

    def test_1_starts_with_the_values_in_force(self):
        config = self.client.get_configuration(timeout=30.0)
        self.assertEqual(config["real_time_factor"], 4.0)  # ~real_time_factor, not the world file's
        self.assertEqual(config["laser_range"], 0.0)
        self.assertEqual(config["odom_linear"], 0.02)      # the world file's noise
        self.assertEqual(config["odom_angular"], 0.01)
        self.assertEqual(rospy.get_param("/stage_node/real_time_factor"), 4.0)

    def test_2_real_time_factor(self):
        self.assertEqual(self.set(real_time_factor=10.0)["real_time_factor"], 10.0)
        fast = sim_rate(RATE_WINDOW)
        self.assertEqual(self.set(real_time_factor=1.0)["real_time_factor"], 1.0)
        slow = sim_rate(RATE_WINDOW)  # without re-anchoring, sim time would stand still here for ~27 s
        rospy.loginfo("sim rate at real_time_factor 10: %.2f, at 1: %.2f", fast, slow)
        self.assertGreater(fast / max(slow, 1e-6), 2.0, "fast %.2f, slow %.2f" % (fast, slow))
        self.assertGreater(slow, 0.3, "sim time must go on at once after the factor drops")
        self.assertLess(slow, 2.0, "at factor 1 sim time must not race (a catch-up burst)")

    def test_3_laser_noise(self):
        self.set(real_time_factor=2.0)
        self.assertLess(self.beam_spread(), 1e-6, "no laser noise at start")
        config = self.set(laser_range=0.05)
        self.assertEqual(config["laser_range"], 0.05)
        self.assertEqual(config["odom_linear"], 0.02)  # the others stay
        self.assertEqual(config["odom_angular"], 0.01)
        noisy = self.beam_spread()
        rospy.loginfo("beam spread with laser_range 0.05: %.4f m", noisy)
        self.assertGreater(noisy, 0.02)
        self.assertLess(noisy, 0.1)
        self.assertEqual(self.set(laser_range=0.0)["laser_range"], 0.0)
        self.assertLess(self.beam_spread(), 1e-6, "laser noise off again")

    def test_4_out_of_range_is_clamped_or_refused(self):
        self.assertEqual(self.set(real_time_factor=1e6)["real_time_factor"], 100.0)  # the .cfg's maximum
        self.assertEqual(self.set(laser_range=-1.0)["laser_range"], 0.0)
        # NaN passes dynamic_reconfigure's clamping; the node refuses it and reports what runs
        self.assertEqual(self.set(real_time_factor=float("nan"))["real_time_factor"], 100.0)
        self.assertEqual(self.set(odom_linear=float("nan"))["odom_linear"], 0.02)
        self.assertEqual(self.set(real_time_factor=2.0)["real_time_factor"], 2.0)
        t = rospy.get_time()
        wait_until(lambda: rospy.get_time() > t + 1.0, 10.0, "sim time going on after bad values")


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_reconfigure", SimReconfigure)
