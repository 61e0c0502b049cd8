#!/usr/bin/env python3
"""rostest (actionlib_client_race.test): the ERROR "Got a transition callback on a goal handle
that we're not tracking" comes from actionlib's SimpleActionClient itself, not from a server.

SimpleActionClient.send_goal() stores the new goal handle (self.gh) only when
ActionClient.send_goal() returns, after the goal is published. A status (or result) message of
the new goal that the client's subscriber thread handles in between finds self.gh not yet set:
the client logs that error and drops the transition. Here the server is actionlib's plain
SimpleActionServer (plain_action_server.py, no navigation), which succeeds each goal at once.

- test_1 makes the race certain (send_goal returns 0.5 s late, as when the machine deschedules
  the thread): the error is logged and the client misses the DONE transition, so
  wait_for_result() does not return although the server succeeded the goal.
- test_2 sends the same goal in the tutorial's way, with no delay: the error may or may not
  come (on this 2-core machine about 1 goal in 10 under load; see the README); the goal always
  succeeds, which is what nav_tutorial_client.test can require of our move_base.
"""
import logging
import sys
import time
import unittest

import actionlib
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from move_base_msgs.msg import MoveBaseAction, MoveBaseGoal

from nav_test_tools import ErrorLog

RACE = "Got a transition callback on a goal handle that we're not tracking"
SERVER = "plain/move_base"


def goal():
    g = MoveBaseGoal()
    g.target_pose.header.frame_id = "map"
    g.target_pose.pose.orientation.w = 1.0
    return g


class ClientRace(unittest.TestCase):
    def setUp(self):
        self.errors = ErrorLog()
        logging.getLogger("rosout").addHandler(self.errors)

    def tearDown(self):
        logging.getLogger("rosout").removeHandler(self.errors)

    def client(self):
        client = actionlib.SimpleActionClient(SERVER, MoveBaseAction)
        self.assertTrue(client.wait_for_server(rospy.Duration(30.0)), "no server on " + SERVER)
        return client

    def test_1_a_status_before_send_goal_returns_is_dropped_by_the_client(self):
        client = self.client()
        publish_and_return = client.action_client.send_goal

        def late(*args, **kwargs):
            handle = publish_and_return(*args, **kwargs)  # the goal is out: the server answers
            time.sleep(0.5)  # ... before SimpleActionClient has stored the handle
            return handle

        client.action_client.send_goal = late
        client.send_goal(goal())
        finished = client.wait_for_result(rospy.Duration(3.0))
        self.assertIn(RACE, self.errors.records)
        self.assertFalse(finished, "the client saw the result although it dropped the transitions")
        # the server did succeed the goal: the handle, stored late, holds its terminal state
        self.assertEqual(client.get_state(), GoalStatus.SUCCEEDED)

    def test_2_without_the_delay_every_goal_succeeds(self):
        for _ in range(20):
            client = self.client()  # as the tutorial's function: a new client per goal
            client.send_goal(goal())
            self.assertTrue(client.wait_for_result(rospy.Duration(10.0)))
            self.assertEqual(client.get_state(), GoalStatus.SUCCEEDED)
        self.assertEqual([e for e in self.errors.records if e != RACE], [])
        sys.stderr.write("actionlib_client_race: %d of 20 goals logged the client's race\n"
                         % self.errors.records.count(RACE))


if __name__ == "__main__":
    rospy.init_node("actionlib_client_race")
    rostest.rosrun("mbot_navigation", "actionlib_client_race", ClientRace)
