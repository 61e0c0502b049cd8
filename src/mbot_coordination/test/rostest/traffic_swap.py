#!/usr/bin/env python3
"""rostest: robot_0 (x = -9) and robot_1 (x = 9) exchange the ends of the 1.5 m corridor head-on
through /fleet/goals. Bad goal sets first: each is aborted with its problem named. Then both robots
arrive at their goals, the simulator reports no contact involving them, their timed plans are
published, and the delay over driving alone (the robot's own shortest path at the planner's
nominal speed) stays within the issue's 15 s. Last, robot_1 is removed from the simulator on its
way to a new goal: the result reports it killed and robot_0 still arrives."""
import math
import unittest

import actionlib
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import Pose2D
from mbot_msgs.msg import Contact, FleetGoalsAction, FleetGoalsGoal, RobotStates
from mbot_msgs.srv import RemoveRobot
from move_base_msgs.msg import MoveBaseAction
from nav_msgs.msg import Path
from visualization_msgs.msg import MarkerArray

GOALS = {"robot_0": (9.0, 0.0, 0.0), "robot_1": (-9.0, 0.0, math.pi)}
TIMEOUT = 250.0  # [sim s] 18 m at the plan's 0.3 m/s is 60 s


class Fleet(object):
    def __init__(self):
        self.poses = {}
        self.closest = float("inf")
        self.contacts = []
        rospy.Subscriber("/stage/ground_truth", RobotStates, self._on_truth, queue_size=5)
        rospy.Subscriber("/contacts", Contact, self._on_contact, queue_size=100)

    def _on_truth(self, msg):
        for r in msg.robots:
            self.poses[r.name] = (r.pose.x, r.pose.y)
        if "robot_0" in self.poses and "robot_1" in self.poses:
            a, b = self.poses["robot_0"], self.poses["robot_1"]
            self.closest = min(self.closest, math.hypot(a[0] - b[0], a[1] - b[1]))

    def _on_contact(self, msg):
        if msg.body_a in GOALS or msg.body_b in GOALS:
            self.contacts.append("%s-%s at (%.2f, %.2f), t = %.2f" % (
                msg.body_a, msg.body_b, msg.position.x, msg.position.y, msg.header.stamp.to_sec()))


def goal_set(pairs):
    goal = FleetGoalsGoal()
    for name, (x, y, yaw) in pairs:
        goal.robots.append(name)
        goal.goals.append(Pose2D(x=x, y=y, theta=yaw))
    return goal


class TrafficSwap(unittest.TestCase):
    def setUp(self):
        self.client = actionlib.SimpleActionClient("/fleet/goals", FleetGoalsAction)
        self.assertTrue(self.client.wait_for_server(rospy.Duration(120.0)), "no /fleet/goals")

    def refused(self, pairs):
        self.client.send_goal(goal_set(pairs))
        self.assertTrue(self.client.wait_for_result(rospy.Duration(60.0)))
        self.assertEqual(self.client.get_state(), GoalStatus.ABORTED)
        return self.client.get_result().message

    def test_1_bad_goal_sets_refused(self):
        rospy.wait_for_message("/stage/ground_truth", RobotStates, timeout=60.0)
        rospy.sleep(1.0)  # the planner has seen the map and the robots
        self.assertEqual(self.refused([("robot_7", (0.0, 0.0, 0.0))]),
                         "unknown robot 'robot_7' (known: robot_0, robot_1)")
        self.assertIn("robot_0: goal (0, 2, 0) is in a wall or too close to one", self.refused(
            [("robot_0", (0.0, 2.0, 0.0))]))
        self.assertEqual(self.refused([("robot_0", (0.0, 0.1, 0.0)), ("robot_1", (0.1, 0.2, 0.0))]),
                         "robot_0 and robot_1: two robots, one goal (the same planning cell of 0.5 m)")
        self.assertEqual(self.refused([("robot_0", (float("nan"), 0.0, 0.0))]),
                         "robot_0: goal (nan, 0, 0) is not a finite pose")
        self.assertIn("robot_1: goal (40, 0, 0) is outside the map", self.refused([("robot_1", (40.0, 0.0, 0.0))]))
        self.assertEqual(self.refused([("robot_0", (1.0, 0.0, 0.0)), ("robot_0", (2.0, 0.0, 0.0))]),
                         "robot_0: two goals for one robot")

    def test_2_swap(self):
        fleet = Fleet()
        plans = {}
        for name in GOALS:
            # the first plan (re-plans start where the robot is then)
            rospy.Subscriber("/%s/timed_plan" % name, Path, lambda msg, n=name: plans.setdefault(n, msg))
        markers = []
        rospy.Subscriber("/fleet/timed_plans", MarkerArray, markers.append)
        while len(fleet.poses) < 2 and not rospy.is_shutdown():
            rospy.sleep(0.1)
        for name in GOALS:  # the robots' navigation is up
            move_base = actionlib.SimpleActionClient("/%s/move_base" % name, MoveBaseAction)
            self.assertTrue(move_base.wait_for_server(rospy.Duration(120.0)), name)
        start = rospy.Time.now()
        self.client.send_goal(goal_set(sorted(GOALS.items())))
        finished = self.client.wait_for_result(rospy.Duration(TIMEOUT))
        result = self.client.get_result()
        summary = "after %.1f sim s: state %d, %s; closest centre distance %.2f m; poses %s" % (
            (rospy.Time.now() - start).to_sec(), self.client.get_state(), result, fleet.closest, fleet.poses)
        rospy.loginfo("traffic_swap: %s", summary)
        self.assertTrue(finished, summary)
        self.assertEqual(self.client.get_state(), GoalStatus.SUCCEEDED, summary)
        self.assertEqual(list(result.reached), [True, True], summary)
        for name, (x, y, _) in GOALS.items():
            self.assertLess(math.hypot(fleet.poses[name][0] - x, fleet.poses[name][1] - y), 0.15, summary)
        self.assertEqual(fleet.contacts, [], "contacts: %s; %s" % (fleet.contacts, summary))
        self.assertGreater(fleet.closest, 0.3, summary)  # two radii of 0.15 m
        # timed plans: from the start to the goal, stamps increasing
        for name, (x, y, _) in GOALS.items():
            self.assertIn(name, plans)
            poses = plans[name].poses
            stamps = [p.header.stamp.to_sec() for p in poses]
            self.assertTrue(all(b > a for a, b in zip(stamps, stamps[1:])), stamps)
            self.assertLess(math.hypot(poses[-1].pose.position.x - x, poses[-1].pose.position.y - y), 1e-6)
            self.assertLess(abs(poses[0].pose.position.x + x), 0.5)
        self.assertTrue(markers and len({m.ns for m in markers[-1].markers}) == 2, markers[-1:])
        for name, took, alone in zip(result.robots, result.durations, result.alone_durations):
            rospy.loginfo("traffic_swap: %s took %.1f s, alone %.1f s planned: added delay %.1f s",
                          name, took, alone, took - alone)
            self.assertLessEqual(took - alone, 15.0, summary)

    def test_3_killed_robot_reported(self):
        # after the swap: robot_0 near x = 9, robot_1 near x = -9; robot_1 is removed on its way
        fleet = Fleet()
        while len(fleet.poses) < 2 and not rospy.is_shutdown():
            rospy.sleep(0.1)
        goals = {"robot_0": (6.0, 0.0, math.pi), "robot_1": (-6.0, 0.0, 0.0)}
        self.client.send_goal(goal_set(sorted(goals.items())))
        rospy.sleep(3.0)
        rospy.wait_for_service("/remove_robot", timeout=30.0)
        self.assertTrue(rospy.ServiceProxy("/remove_robot", RemoveRobot)(name="robot_1").success)
        self.assertTrue(self.client.wait_for_result(rospy.Duration(TIMEOUT)))
        result = self.client.get_result()
        rospy.loginfo("traffic_swap: with robot_1 removed: state %d, %s", self.client.get_state(), result)
        self.assertEqual(self.client.get_state(), GoalStatus.ABORTED, result)
        self.assertEqual(list(result.robots), ["robot_0", "robot_1"])
        self.assertEqual(list(result.reached), [True, False], result)
        self.assertTrue(result.reasons[1].startswith("killed"), result)
        self.assertIn("robot_1: killed", result.message)
        x, y, _ = goals["robot_0"]
        self.assertLess(math.hypot(fleet.poses["robot_0"][0] - x, fleet.poses["robot_0"][1] - y), 0.15, result)


if __name__ == "__main__":
    rospy.init_node("traffic_swap_test")
    rostest.rosrun("mbot_coordination", "traffic_swap", TrafficSwap)
