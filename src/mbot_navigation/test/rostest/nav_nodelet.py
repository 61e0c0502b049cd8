#!/usr/bin/env python3
"""rostest: robot_0's and robot_1's nav nodes run as nodelets in /nav_manager (nav_nodelet.test).
The manager publishes both robots' move_base topics and alone subscribes /tf; then both robots
cross the corridor as in nav_corridor.py (its test, run here against the nodelets); last,
`rosnode kill` of robot_1's loader unloads robot_1's node only."""
import time

import rosgraph
import rosnode
import rospy
import rostest
from geometry_msgs.msg import PoseStamped
from nav_msgs.srv import GetPlan

from nav_corridor import CorridorCrossing
from nav_test_tools import action_client, make_goal

MANAGER = "/nav_manager"


class NodeletCorridorCrossing(CorridorCrossing):
    def test_0_one_manager_serves_both(self):
        for robot in ("robot_0", "robot_1"):
            action_client(robot)  # both servers up
        publishers, subscribers, services = rosgraph.Master("/nav_nodelet_test").getSystemState()
        published = {topic for topic, nodes in publishers if MANAGER in nodes}
        subscribed = {topic: nodes for topic, nodes in subscribers}
        for robot in ("robot_0", "robot_1"):
            for topic in ("/%s/cmd_vel" % robot, "/%s/move_base/status" % robot, "/%s/move_base/global_plan" % robot):
                self.assertIn(topic, published)
            # The loader process (named /<robot>/move_base) holds no subscription of its own.
            self.assertNotIn("/%s/move_base" % robot, subscribed["/tf"])
        self.assertIn(MANAGER, subscribed["/tf"])
        served = {name for name, nodes in services if MANAGER in nodes}
        self.assertIn("/robot_0/move_base/make_plan", served)
        self.assertIn("/robot_1/move_base/clear_costmaps", served)

    def test_z_killed_loader_unloads_only_its_robot(self):
        killed, failed = rosnode.kill_nodes(["/robot_1/move_base"])
        self.assertEqual((killed, failed), (["/robot_1/move_base"], []))
        master = rosgraph.Master("/nav_nodelet_test")
        deadline = time.time() + 30.0  # wall: the manager unloads when the loader's bond breaks
        while True:
            publishers, _, services = master.getSystemState()
            served = {name for name, nodes in services if MANAGER in nodes}
            published = {topic for topic, nodes in publishers if MANAGER in nodes}
            if "/robot_1/move_base/make_plan" not in served and "/robot_1/move_base/status" not in published:
                break
            self.assertLess(time.time(), deadline, "robot_1's node still in the manager: %s" % sorted(served))
            time.sleep(0.2)
        # robot_0's node is still there and plans from its robot's pose.
        self.assertIn("/robot_0/move_base/make_plan", served)
        self.assertIn("/robot_0/move_base/status", published)
        make_plan = rospy.ServiceProxy("/robot_0/move_base/make_plan", GetPlan)
        plan = make_plan(start=PoseStamped(), goal=make_goal(-10.0, 0.0).target_pose, tolerance=0.0).plan
        self.assertGreater(len(plan.poses), 5)
        self.assertIn(MANAGER, rosnode.get_node_names())


if __name__ == "__main__":
    rospy.init_node("nav_nodelet_test")
    rostest.rosrun("mbot_navigation", "nav_nodelet", NodeletCorridorCrossing)
