#!/usr/bin/env python3
"""rostest: robot_0 (west end) and robot_1 (east end) swap sides through the 1.5 m corridor at the
same time; both must arrive, with no contact reported on /contacts for either robot."""
import math
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus

from nav_test_tools import Contacts, Track, action_client, make_goal, state_name

GOALS = {"robot_0": (12.5, 1.0, 0.0), "robot_1": (-12.5, -1.0, math.pi)}
TIMEOUT = 150.0  # [sim s] 25 m at 0.5 m/s is 50 s


class CorridorCrossing(unittest.TestCase):
    def test_both_arrive_without_contact(self):
        contacts = Contacts(GOALS.keys())
        tracks = {name: Track(name) for name in GOALS}
        clients = {name: action_client(name) for name in GOALS}
        for track in tracks.values():
            track.wait()
        start = rospy.Time.now()
        for name, (x, y, yaw) in GOALS.items():
            clients[name].send_goal(make_goal(x, y, yaw))
        closest = float("inf")
        deadline = start + rospy.Duration(TIMEOUT)
        while rospy.Time.now() < deadline and not rospy.is_shutdown():
            a, b = tracks["robot_0"].pose, tracks["robot_1"].pose
            closest = min(closest, math.hypot(a[0] - b[0], a[1] - b[1]))
            if all(c.get_state() not in (GoalStatus.PENDING, GoalStatus.ACTIVE) for c in clients.values()):
                break
            rospy.sleep(0.05)
        seconds = (rospy.Time.now() - start).to_sec()
        summary = "after %.1f sim s: %s; closest centre distance %.2f m" % (seconds, ", ".join(
            "%s %s (%s) at (%.2f, %.2f)" % (n, state_name(c.get_state()), c.get_goal_status_text(),
                                            tracks[n].pose[0], tracks[n].pose[1]) for n, c in clients.items()), closest)
        rospy.loginfo("nav_corridor: %s", summary)
        for name, client in clients.items():
            self.assertEqual(client.get_state(), GoalStatus.SUCCEEDED, summary)
            x, y, _ = GOALS[name]
            self.assertLess(math.hypot(tracks[name].pose[0] - x, tracks[name].pose[1] - y), 0.15, summary)
        self.assertEqual(contacts.events, [], "contacts: %s; %s" % (contacts.events, summary))
        self.assertGreater(closest, 0.3, summary)  # two radii of 0.15 m


if __name__ == "__main__":
    rospy.init_node("nav_corridor_test")
    rostest.rosrun("mbot_navigation", "nav_corridor_crossing", CorridorCrossing)
