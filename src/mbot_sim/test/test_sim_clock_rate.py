#!/usr/bin/python3
"""rostest (sim_clock_rate.test): with ~clock_rate 20, stage_node publishes /clock 20 times per sim
second, each on a multiple of 0.05 s, while robot_0's odometry keeps its 50 Hz (stamps 0.02 s
apart) and sim time goes on as before. Lockstep with this node as its pacer: on a busy machine the
simulator would otherwise run ahead of it and its publishers drop what this node has not read."""
import sys
import threading
import unittest

import rospy
import rostest
from nav_msgs.msg import Odometry
from rosgraph_msgs.msg import Clock

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import keep_pace  # noqa: E402


class ClockRate(unittest.TestCase):
    def test_clock_at_its_rate_and_odometry_at_its_own(self):
        lock = threading.Lock()
        clocks, odoms = [], []

        def on_clock(msg):
            with lock:
                clocks.append(msg.clock.to_sec())

        def on_odom(msg):
            with lock:
                odoms.append(msg.header.stamp.to_sec())

        keep_pace()
        rospy.Subscriber("/clock", Clock, on_clock, queue_size=1000)
        rospy.Subscriber("/robot_0/odom", Odometry, on_odom, queue_size=1000)
        rospy.wait_for_message("/robot_0/odom", Odometry, timeout=60.0)
        t0 = rospy.get_time() + 0.5
        while rospy.get_time() < t0 + 2.6 and not rospy.is_shutdown():
            rospy.sleep(0.1)
        with lock:
            window = [t for t in clocks if t0 <= t < t0 + 2.0]
            odom = [t for t in odoms if t0 <= t < t0 + 2.0]
        self.assertTrue(39 <= len(window) <= 41, "%d /clock messages in 2 s sim, expected 40" % len(window))
        for t in window:
            self.assertAlmostEqual(t * 20.0, round(t * 20.0), delta=1e-6,
                                   msg="/clock %.4f is no multiple of 0.05 s" % t)
        self.assertTrue(95 <= len(odom) <= 105, "%d odometry messages in 2 s sim, expected 100 (50 Hz)" % len(odom))


if __name__ == "__main__":
    rospy.init_node("sim_clock_rate_test")
    rostest.rosrun("mbot_sim", "sim_clock_rate", ClockRate, sys.argv)
