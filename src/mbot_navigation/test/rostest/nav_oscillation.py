#!/usr/bin/env python3
"""rostest: the nav node's oscillation timeout (oscillation_timeout 10 s, oscillation_distance
0.2 m in config/nav_move_base.yaml). robot_0's drive is frozen by the simulator (set_fault
drive_frozen): the nav node plans and commands, the robot does not move. Each oscillation_timeout
without progress starts the next recovery; after the last the goal is aborted, saying why.
Once the drive works again, a goal is reached (the node is not stuck)."""
import math
import threading
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import Twist
from mbot_msgs.srv import SetFault, SetFaultRequest

from nav_test_tools import Track, action_client, make_goal, run_goal, state_name

ROBOT = "robot_0"
GOAL = (4.5, -4.0, 0.0)  # 1.5 m east of the start (3, -4), same room
TIMEOUT = 10.0           # [s] oscillation_timeout
RECOVERIES = 3           # clear costmaps, rotate, back up


class Commands(object):
    """Sim times of the nav node's non-zero cmd_vel."""

    def __init__(self):
        self._lock = threading.Lock()
        self.times = []
        rospy.Subscriber("/%s/cmd_vel" % ROBOT, Twist, self._on_cmd, queue_size=100)

    def _on_cmd(self, msg):
        if abs(msg.linear.x) + abs(msg.linear.y) + abs(msg.angular.z) > 1e-3:
            with self._lock:
                self.times.append(rospy.get_time())


def frozen(value):
    req = SetFaultRequest()
    req.robot = ROBOT
    req.drive_frozen = value
    return req


class NavOscillation(unittest.TestCase):
    def test_frozen_drive_is_aborted_as_oscillating(self):
        track = Track(ROBOT)
        commands = Commands()
        client = action_client(ROBOT)
        rospy.wait_for_service("/set_fault", 30.0)
        set_fault = rospy.ServiceProxy("/set_fault", SetFault)
        x0, y0, _ = track.wait()
        self.assertTrue(set_fault(frozen(True)).success)
        start = rospy.get_time()
        state, text, seconds = run_goal(client, make_goal(*GOAL), 120.0)
        rospy.loginfo("nav_oscillation: %s after %.1f sim s: %s", state_name(state), seconds, text)
        self.assertEqual(state, GoalStatus.ABORTED, "%s: %s" % (state_name(state), text))
        self.assertTrue(text.startswith("the robot moved less than 0.20 m in 10.0 s (oscillating)"), text)
        self.assertIn("recoveries tried", text)
        # One oscillation_timeout before the first recovery and one after each.
        self.assertGreater(seconds, (RECOVERIES + 1) * TIMEOUT, text)
        moved = math.hypot(track.pose[0] - x0, track.pose[1] - y0)
        self.assertLess(moved, 0.01, "the frozen robot moved %.3f m" % moved)
        # The node commanded motion all along (it was not the planner or the controller giving up).
        driving = [t for t in commands.times if t >= start]
        self.assertTrue(driving and driving[0] - start < 2.0, "no motion commanded in the first 2 sim s")
        self.assertGreater(driving[-1] - driving[0], RECOVERIES * TIMEOUT)

        # Repaired, the robot gets there.
        self.assertTrue(set_fault(frozen(False)).success)
        state, text, _ = run_goal(client, make_goal(*GOAL), 60.0)
        self.assertEqual(state, GoalStatus.SUCCEEDED, "%s: %s" % (state_name(state), text))
        self.assertLess(math.hypot(track.pose[0] - GOAL[0], track.pose[1] - GOAL[1]), 0.15, track.pose)


if __name__ == "__main__":
    rospy.init_node("nav_oscillation_test")
    rostest.rosrun("mbot_navigation", "nav_oscillation", NavOscillation)
