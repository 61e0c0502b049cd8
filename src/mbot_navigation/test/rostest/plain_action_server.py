#!/usr/bin/env python3
"""A plain actionlib server, no navigation: actionlib's SimpleActionServer with MoveBaseAction
that succeeds each goal at once (actionlib_client_race.test)."""
import actionlib
import rospy
from move_base_msgs.msg import MoveBaseAction, MoveBaseResult


def main():
    rospy.init_node("plain_server")
    server = actionlib.SimpleActionServer("plain/move_base", MoveBaseAction, auto_start=False,
                                          execute_cb=lambda _goal: server.set_succeeded(MoveBaseResult()))
    server.start()
    rospy.spin()


if __name__ == "__main__":
    main()
