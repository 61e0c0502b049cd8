#!/usr/bin/python3
"""rostest (sim_applied_commands.test): stage_node reports every robot's cmd_vel as the physics
used it on /stage/applied_commands (mbot_msgs/AppliedCommands), the metrics' end-to-end latency.

Paused at sim time T (the last /clock: without ~clock_rate one comes after every step), the test
sends robot_0 two commands and robot_1 one, waits until the simulator has them, and unpauses:
robot_0's second command and robot_1's are reported as received at T and applied at T (the first
step after T starts there), with their twists bit for bit; robot_0's first one, replaced before
any step, is not reported. A command sent while sim time runs is reported as received no earlier
than the /clock before it was sent and applied within one physics step of its arrival. Every
message's stamp moves on by 0.1 s of sim time, its `since` is the stamp before, and it covers the
commands in it: each was applied before the stamp and at or after `since`.
"""
import sys
import threading
import time
import unittest

import rospy
import rostest
import yaml
from geometry_msgs.msg import Twist
from mbot_msgs.msg import AppliedCommands
from rosgraph_msgs.msg import Clock
from std_srvs.srv import Empty

sys.path.insert(0, __import__("os").path.dirname(__import__("os").path.abspath(__file__)))
from sim_test_tools import Recorder, wait_for_connection, wait_until  # noqa: E402


def twist(vx, vy, wz):
    msg = Twist()
    msg.linear.x, msg.linear.y, msg.angular.z = vx, vy, wz
    return msg


def values(msg):
    return (msg.linear.x, msg.linear.y, msg.linear.z, msg.angular.x, msg.angular.y, msg.angular.z)


def wait_wall(condition, seconds, what):
    end = time.time() + seconds
    while not condition():
        if time.time() > end:
            raise AssertionError("timed out after %.0f s wall waiting for %s" % (seconds, what))
        time.sleep(0.01)


class ClockWatch(object):
    def __init__(self):
        self.lock = threading.Lock()
        self.latest, self.wall = None, 0.0
        self.sub = rospy.Subscriber("/clock", Clock, self._callback, queue_size=10, tcp_nodelay=True)

    def _callback(self, msg):
        with self.lock:
            self.latest, self.wall = msg.clock.to_sec(), time.time()

    def get(self):
        with self.lock:
            return self.latest, self.wall


class SimAppliedCommands(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_applied_commands")
        with open(rospy.get_param("/stage_node/world")) as f:
            cls.step = yaml.safe_load(f)["physics_step"]
        cls.clock = ClockWatch()
        cls.applied = Recorder("/stage/applied_commands", AppliedCommands)
        robots = ("robot_0", "robot_1", "robot_2")
        cls.pubs = {r: rospy.Publisher("/%s/cmd_vel" % r, Twist, queue_size=10) for r in robots}
        for pub in cls.pubs.values():
            wait_for_connection(pub, 30.0)
        cls.applied.wait_for_first()
        rospy.wait_for_service("/pause_physics", 30.0)
        cls.pause = rospy.ServiceProxy("/pause_physics", Empty)
        cls.unpause = rospy.ServiceProxy("/unpause_physics", Empty)

    def reported(self, robot):
        """[(received, applied, twist values, batch stamp)] of robot's reported commands so far."""
        out = []
        for _, batch in self.applied.received_since(0.0):
            for c in batch.commands:
                if c.robot == robot:
                    out.append((c.received.to_sec(), c.applied.to_sec(), values(c.cmd), batch.header.stamp.to_sec()))
        return out

    def newest_stamp(self):
        latest = self.applied.latest()
        return latest.header.stamp.to_sec() if latest is not None else -1.0

    def test_1_paused_commands_are_applied_at_the_next_step_exactly(self):
        self.pause()
        # paused once /clock has been silent for a while (rtf 5: a step every 2 ms wall)
        wait_wall(lambda: time.time() - self.clock.get()[1] > 0.5, 10.0, "/clock to stop after pause_physics")
        paused_at = self.clock.get()[0]
        replaced = twist(0.25, 0.0, 0.5)
        kept = twist(0.1 + 0.2, 0.0, -0.7123456789012345)   # 0.30000000000000004: bits must survive
        other = twist(0.123456789, 0.0, 1.0 / 3.0)
        self.pubs["robot_0"].publish(replaced)
        self.pubs["robot_0"].publish(kept)
        self.pubs["robot_1"].publish(other)
        time.sleep(1.0)   # the simulator serves its callbacks every 10 ms wall while paused
        self.unpause()
        wait_until(lambda: self.newest_stamp() > paused_at + 0.15, 10.0, "a report 0.15 s after the pause")
        robot_0 = [c for c in self.reported("robot_0") if c[0] >= paused_at - 1e-9]
        robot_1 = [c for c in self.reported("robot_1") if c[0] >= paused_at - 1e-9]
        print("paused at %.9f; robot_0 %s; robot_1 %s" % (paused_at, robot_0, robot_1))
        self.assertEqual(len(robot_0), 1, "robot_0: expected only the second command, got %s" % robot_0)
        self.assertEqual(robot_0[0][2], values(kept))
        self.assertEqual(len(robot_1), 1, robot_1)
        self.assertEqual(robot_1[0][2], values(other))
        for received, applied, _, _ in robot_0 + robot_1:
            self.assertAlmostEqual(received, paused_at, delta=1e-9)
            self.assertAlmostEqual(applied, paused_at, delta=1e-9)
        self.assertNotIn(values(replaced), [c[2] for c in self.reported("robot_0")])

    def test_2_running_command_is_applied_within_a_step(self):
        sent_after, _ = self.clock.get()
        cmd = twist(0.2, 0.0, 0.0987654321)
        self.pubs["robot_2"].publish(cmd)
        wait_until(lambda: any(c[2] == values(cmd) for c in self.reported("robot_2")), 10.0,
                   "robot_2's command in a report")
        received, applied, _, _ = next(c for c in self.reported("robot_2") if c[2] == values(cmd))
        print("sent after %.3f, received %.3f, applied %.3f" % (sent_after, received, applied))
        self.assertGreaterEqual(received, sent_after - 1e-9)
        self.assertGreaterEqual(applied, received - 1e-9)
        self.assertLessEqual(applied, received + self.step + 1e-9)

    def test_3_stamps_cover_their_commands(self):
        wait_until(lambda: self.newest_stamp() > 1.0, 10.0, "reports past 1 s sim")
        batches = [b for _, b in self.applied.received_since(0.0)]
        stamps = [b.header.stamp.to_sec() for b in batches]
        gaps = [b - a for a, b in zip(stamps, stamps[1:])]
        print("%d reports, stamp gaps %.4f .. %.4f s" % (len(stamps), min(gaps), max(gaps)))
        for gap in gaps:   # paused in test_1: no step, no report; one report per 0.1 s otherwise
            self.assertAlmostEqual(gap, 0.1, delta=self.step + 1e-9)
        commands = 0
        for before, batch in zip(stamps, batches[1:]):
            self.assertEqual(batch.since.to_sec(), before)   # the report never paused: it is complete
            for c in batch.commands:
                commands += 1
                self.assertGreaterEqual(c.applied.to_sec(), before - 1e-9)
                self.assertLess(c.applied.to_sec(), batch.header.stamp.to_sec())
        self.assertGreaterEqual(commands, 3)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_applied_commands", SimAppliedCommands, sys.argv)
