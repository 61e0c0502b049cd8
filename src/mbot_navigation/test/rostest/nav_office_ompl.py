#!/usr/bin/env python3
"""rostest: nav_office.py with the OMPL global planner. One robot in the office reaches three
goals in sequence, each through doors, via the move_base action; the nav node must be running
base_global_planner 'ompl'; the path it drove (ground truth) is at most max_length_ratio times the
A* optimum on the static map (a sampling planner's path is a little longer than A*'s)."""
import time

import rospy
import rostest

from nav_office import OfficeNavigation


class OfficeNavigationOmpl(OfficeNavigation):
    def setUp(self):
        robot = rospy.get_param("~robot")
        # fleet_navigation starts the nav node (and sets its parameters) a few wall seconds in.
        key = "/%s/move_base/base_global_planner" % robot
        deadline = time.time() + 60.0
        while not rospy.has_param(key) and time.time() < deadline and not rospy.is_shutdown():
            time.sleep(0.1)
        self.assertEqual(rospy.get_param(key, None), "ompl", "the nav node must use the OMPL planner")


if __name__ == "__main__":
    rospy.init_node("nav_office_ompl_test")
    rostest.rosrun("mbot_navigation", "nav_office_ompl_three_goals", OfficeNavigationOmpl)
