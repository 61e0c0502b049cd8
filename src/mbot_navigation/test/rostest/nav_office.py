#!/usr/bin/env python3
"""rostest: one robot in the office reaches three goals in sequence, each through doors, via the
move_base action; the path it drove (ground truth) is at most max_length_ratio times the A*
optimum on the static map (8-connected, for the robot's radius; grid_paths.py)."""
import math
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus

from mbot_navigation.grid_paths import clearance, path_lengths_from, world_to_cell
from nav_test_tools import Contacts, Track, action_client, angle_diff, make_goal, run_goal, state_name, wait_for_map

ROBOT_RADIUS = 0.15  # [m] mbot's footprint (mbot_description/urdf/mbot.urdf)
# From the south-east room (3, -4): to the north-east room (2 doors), to the north-west rooms'
# east room (2 doors, via the north corridor), to the south-west hall (2 doors).
GOALS = [(8.0, 3.0, math.pi / 2), (-3.0, 7.5, math.pi), (-5.0, -5.0, 0.0)]


class OfficeNavigation(unittest.TestCase):
    def test_three_goals_through_doors(self):
        robot = rospy.get_param("~robot")
        max_ratio = rospy.get_param("~max_length_ratio")
        track = Track(robot)
        contacts = Contacts([robot])
        grid = wait_for_map()
        free = clearance(grid) >= ROBOT_RADIUS
        client = action_client(robot)
        track.wait()
        report = []
        for x, y, yaw in GOALS:
            start = track.pose
            optimum = path_lengths_from(free, grid.resolution, world_to_cell(grid, start[0], start[1]))[
                world_to_cell(grid, x, y)]
            self.assertTrue(math.isfinite(optimum), "goal (%.1f, %.1f) unreachable on the map" % (x, y))
            track.reset()
            state, text, seconds = run_goal(client, make_goal(x, y, yaw), timeout=150.0)
            pose = track.pose
            ratio = track.length / optimum
            report.append("(%.1f, %.1f): %s in %.1f sim s, drove %.2f m, optimum %.2f m, ratio %.3f" % (
                x, y, state_name(state), seconds, track.length, optimum, ratio))
            rospy.loginfo("nav_office: %s", report[-1])
            self.assertEqual(state, GoalStatus.SUCCEEDED, "goal (%.1f, %.1f): %s: %s" % (x, y, state_name(state), text))
            self.assertLess(math.hypot(pose[0] - x, pose[1] - y), 0.15, "stopped at %s" % (pose,))
            self.assertLess(angle_diff(pose[2], yaw), 0.15, "stopped at %s" % (pose,))
            self.assertLessEqual(ratio, max_ratio, report[-1])
            self.assertGreater(ratio, 0.9, report[-1])  # sanity: the track and the optimum agree
        self.assertEqual(contacts.events, [], "contacts: %s" % contacts.events)
        print("\n".join(report))


if __name__ == "__main__":
    rospy.init_node("nav_office_test")
    rostest.rosrun("mbot_navigation", "nav_office_three_goals", OfficeNavigation)
