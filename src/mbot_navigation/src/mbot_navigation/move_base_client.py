"""Talking to a robot's move_base from a script, a demo or a test: goals and the connection."""
import time

import actionlib
import rospy
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

from mbot_common.geometry import quaternion_from_yaw


def make_goal(x, y, yaw=0.0, frame="map"):
    """A MoveBaseGoal at (x, y) [m] facing `yaw` [rad] in `frame`. The stamp stays zero: the nav
    node transforms a goal with the latest transform anyway."""
    goal = MoveBaseGoal()
    goal.target_pose.header.frame_id = frame
    goal.target_pose.pose.position.x = x
    goal.target_pose.pose.position.y = y
    o = goal.target_pose.pose.orientation
    o.x, o.y, o.z, o.w = quaternion_from_yaw(yaw)
    return goal


def connect_move_base(robot, wall_timeout=60.0):
    """A SimpleActionClient for /<robot>/move_base, connected to its server.

    Waits up to `wall_timeout` seconds of wall time, not sim time: the nodes start up in wall
    time, while the simulator may already run many times faster than that (real_time_factor 0),
    and a wait in sim time would then give up long before the nav node is there.
    @raise RuntimeError when no server appears in time (or ROS shuts down)
    """
    name = "/%s/move_base" % robot.strip("/")
    client = actionlib.SimpleActionClient(name, MoveBaseAction)
    deadline = time.time() + wall_timeout
    while not client.wait_for_server(rospy.Duration(0.1)):
        if rospy.is_shutdown():
            raise RuntimeError("shut down while waiting for the action server %s" % name)
        if time.time() > deadline:
            raise RuntimeError("no action server %s after %.0f s (is its nav node running?)" % (name, wall_timeout))
    return client
