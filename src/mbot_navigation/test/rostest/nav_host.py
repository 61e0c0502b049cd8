#!/usr/bin/env python3
"""rostest: robot_0's and robot_1's nav nodes and fake localizations are nodelets that one
fleet_host process loaded itself (nav_host.test). The host publishes both robots' move_base
topics and map -> odom, no process per robot runs; then both robots cross the corridor as in
nav_corridor.py (its test, run here against the host); last, a host given a nodelet that does not
exist exits with status 1 and an error naming it."""
import subprocess

import rosgraph
import rosnode
import rospy
import rostest
from geometry_msgs.msg import PoseWithCovarianceStamped

from nav_corridor import CorridorCrossing
from nav_test_tools import action_client

HOST = "/nav_host"


class HostCorridorCrossing(CorridorCrossing):
    def test_0_one_process_serves_both(self):
        for robot in ("robot_0", "robot_1"):
            action_client(robot)  # both servers up
            pose = rospy.wait_for_message("/%s/amcl_pose" % robot, PoseWithCovarianceStamped, timeout=60.0)
            self.assertEqual(pose.header.frame_id, "map")
        publishers, _, services = rosgraph.Master("/nav_host_test").getSystemState()
        published = {topic for topic, nodes in publishers if HOST in nodes}
        for robot in ("robot_0", "robot_1"):
            for topic in ("/%s/cmd_vel" % robot, "/%s/move_base/status" % robot, "/%s/amcl_pose" % robot):
                self.assertIn(topic, published)
        served = {name for name, nodes in services if HOST in nodes}
        self.assertIn("/robot_0/move_base/make_plan", served)
        self.assertIn("/nav_host/load_nodelet", served)  # a nodelet manager's services, for robots added later
        names = rosnode.get_node_names()
        for node in ("/robot_0/move_base", "/robot_1/move_base", "/robot_0/fake_localization"):
            self.assertNotIn(node, names)  # no process (and no loader) per robot

    def test_z_a_nodelet_that_does_not_load_stops_the_host_with_its_name(self):
        def run_host(nodelets):
            rospy.set_param("/bad_host/nodelets", nodelets)
            return subprocess.run(["rosrun", "mbot_navigation", "fleet_host", "__name:=bad_host"],
                                  stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=60,
                                  universal_newlines=True)

        run = run_host([{"name": "/robot_9/move_base", "type": "no_such_pkg/NoSuchNodelet"}])
        self.assertEqual(run.returncode, 1, run.stdout)
        self.assertIn("could not load /robot_9/move_base (no_such_pkg/NoSuchNodelet)", run.stdout)
        run = run_host([{"name": "robot_9/move_base", "type": "mbot_navigation/NavNodelet"}])
        self.assertEqual(run.returncode, 1, run.stdout)
        self.assertIn("must be a full name such as /robot_0/move_base", run.stdout)
        run = run_host("robot_9/move_base")
        self.assertEqual(run.returncode, 1, run.stdout)
        self.assertIn("/bad_host/nodelets: expected a list", run.stdout)


if __name__ == "__main__":
    rospy.init_node("nav_host_test")
    rostest.rosrun("mbot_navigation", "nav_host", HostCorridorCrossing)
