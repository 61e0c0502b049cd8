#!/usr/bin/env python3
"""rostest: live tuning. While robot_0 drives a long way, setting
/robot_0/move_base/DWAPlannerROS max_vel_x to 0.3 lowers its speed limit: from shortly after the
call (one control cycle and the braking at acc_lim_x) the robot's speed stays under 0.3 m/s.
Then `rosrun dynamic_reconfigure dynparam set` changes the global costmap's inflation radius
live too. The speed limit goes through dynamic_reconfigure's Python client (the service dynparam
calls), connected before the robot sets off: starting a dynparam process took up to 48 sim s on
a loaded machine, and the robot had arrived before its new limit."""
import math
import subprocess
import threading
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from nav_msgs.msg import OccupancyGrid, Odometry

from nav_test_tools import action_client, make_goal, state_name, wait_until

ROBOT = "robot_0"
NEW_MAX = 0.3      # [m/s]
SETTLE = 0.6       # [s] sim: a control cycle, braking 0.5 -> 0.3 m/s at 1 m/s^2 (0.2 s), margin
MIN_DRIVE = 8.0    # [s] sim: driving under the new limit that the test needs to see


class Speeds(object):
    def __init__(self):
        self._lock = threading.Lock()
        self.samples = []  # (sim time, speed [m/s]) from the ground truth
        rospy.Subscriber("/%s/base_pose_ground_truth" % ROBOT, Odometry, self._on_odom, queue_size=100)

    def _on_odom(self, msg):
        v = math.hypot(msg.twist.twist.linear.x, msg.twist.twist.linear.y)
        with self._lock:
            self.samples.append((msg.header.stamp.to_sec(), v))

    def max_between(self, t0, t1):
        with self._lock:
            return max([v for t, v in self.samples if t0 <= t <= t1] or [0.0])

    def latest(self):
        with self._lock:
            return self.samples[-1][1] if self.samples else 0.0


def dynparam(*args):
    out = subprocess.run(["rosrun", "dynamic_reconfigure", "dynparam"] + list(args), stdout=subprocess.PIPE,
                         stderr=subprocess.STDOUT, universal_newlines=True, timeout=240)
    if out.returncode != 0:
        raise AssertionError("dynparam %s: exit %d: %s" % (" ".join(args), out.returncode, out.stdout))
    return out.stdout


class Reconfigure(unittest.TestCase):
    def setUp(self):
        self.client = action_client(ROBOT)  # waits (wall time) until the nav node is up

    def test_max_vel_x_takes_effect_while_driving(self):
        from dynamic_reconfigure.client import Client

        speeds = Speeds()
        client = self.client
        dwa = Client("/%s/move_base/DWAPlannerROS" % ROBOT, timeout=60.0)
        # Across the office: long straight stretches in the corridors.
        client.send_goal(make_goal(-5.0, 7.5, 0.0))
        wait_until(lambda: speeds.latest() > 0.4, 60.0, "the robot to drive faster than 0.4 m/s")
        before_max = speeds.max_between(0.0, rospy.Time.now().to_sec())
        applied = dwa.update_configuration({"max_vel_x": NEW_MAX})
        changed = rospy.Time.now().to_sec()  # the call has returned: the server has applied it
        self.assertAlmostEqual(applied["max_vel_x"], NEW_MAX)
        self.assertAlmostEqual(rospy.get_param("/%s/move_base/DWAPlannerROS/max_vel_x" % ROBOT), NEW_MAX)
        wait_until(lambda: rospy.Time.now().to_sec() > changed + 20.0 or client.get_state() not in
                   (GoalStatus.PENDING, GoalStatus.ACTIVE), 30.0, "20 sim s of driving")
        # On a loaded machine the robot may reach 0.4 m/s late on its way and arrive before 20 s
        # have passed: enough when it drove MIN_DRIVE s under the new limit.
        driven = rospy.Time.now().to_sec() - changed
        self.assertTrue(client.get_state() == GoalStatus.ACTIVE or
                        (client.get_state() == GoalStatus.SUCCEEDED and driven >= MIN_DRIVE),
                        "the goal ended %.1f s after the change: %s: %s"
                        % (driven, state_name(client.get_state()), client.get_goal_status_text()))
        after_max = speeds.max_between(changed + SETTLE, rospy.Time.now().to_sec())
        rospy.loginfo("max speed %.3f m/s before the change, %.3f m/s from %.1f s after it (%.1f s)", before_max,
                      after_max, SETTLE, driven)
        self.assertGreater(before_max, NEW_MAX + 0.05, "the robot never drove faster than the new limit")
        self.assertLess(after_max, NEW_MAX + 0.02, "%.3f m/s after the limit became %.2f m/s" % (after_max, NEW_MAX))
        self.assertGreater(after_max, NEW_MAX - 0.1, "the robot hardly moved after the change")
        client.cancel_goal()
        client.wait_for_result(rospy.Duration(5.0))

    def test_inflation_radius_takes_effect(self):
        grids = []
        rospy.Subscriber("/%s/move_base/global_costmap/costmap" % ROBOT, OccupancyGrid,
                         lambda m: grids.append(m), queue_size=1)
        wait_until(lambda: grids, 60.0, "a global costmap")
        inflated = lambda g: sum(1 for v in g.data if 0 < v < 99)  # noqa: E731
        before = inflated(grids[-1])
        layer = "/%s/move_base/global_costmap/inflation_layer" % ROBOT
        dynparam("set", layer, "inflation_radius", "0.3")
        # The other test drives on this costmap afterwards: give it back the shipped 0.6 m (a
        # plan made with 0.3 m hugs walls that the local costmap still inflates by 0.6 m).
        self.addCleanup(dynparam, "set", layer, "inflation_radius", "0.6")
        n = len(grids)
        wait_until(lambda: len(grids) >= n + 2, 10.0, "two more global costmaps")
        after = inflated(grids[-1])
        rospy.loginfo("inflated cells: %d before, %d after inflation_radius 0.3", before, after)
        self.assertLess(after, 0.8 * before, "inflated cells %d -> %d with inflation_radius 0.6 -> 0.3"
                        % (before, after))


if __name__ == "__main__":
    rospy.init_node("nav_reconfigure_test")
    rostest.rosrun("mbot_navigation", "nav_reconfigure", Reconfigure)
