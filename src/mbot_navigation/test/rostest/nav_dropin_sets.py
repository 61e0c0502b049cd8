#!/usr/bin/env python3
"""rostest (nav_dropin_sets.test): two complete move_base configuration sets of the kind robot
packages ship load without a fatal line and without an unknown-key warning (every key in them is
a documented one), the standard keys this node ignores are named in info lines, and each robot
reaches a goal sent through actionlib (SUCCEEDED, the ground truth within its set's tolerance)."""
import math
import os
import threading
import unittest

import rospkg
import rospy
import rostest
from actionlib_msgs.msg import GoalStatus

from nav_test_tools import Track, action_client, make_goal, run_goal, state_name

# robot, its set, goal (x, y, yaw), its set's xy_goal_tolerance, info lines its start-up must show
CASES = [
    ("robot_0", "tb3_style", (6.5, -3.5, 0.0), 0.1,
     ["parameter /robot_0/move_base/DWAPlannerROS/publish_traj_pc: a dwa_local_planner key",
      "parameter /robot_0/move_base/TrajectoryPlannerROS/heading_scoring: a base_local_planner key",
      "parameter /robot_0/move_base/DWAPlannerROS/vy_samples: 0 is raised to 1"]),
    ("robot_1", "jackal_style", (6.0, -6.0, 0.0), 0.15,
     ["parameter /robot_1/move_base/DWAPlannerROS/sum_scores: a dwa_local_planner key",
      "parameter /robot_1/move_base/GlobalPlanner/publish_scale: a global_planner key",
      "parameter /robot_1/move_base/local_costmap/map_type: voxel is read as a 2-D obstacle layer",
      "parameter /robot_1/move_base/footprint: the footprint polygon is taken as its circumscribed circle",
      "parameter /robot_1/move_base/DWAPlannerROS/acc_lim_th: read as acc_lim_theta"]),
]


def rosout_lines(node):
    """(level, text) of every line `node` sent to rosout so far (rosout.log of this run)."""
    path = os.path.join(rospkg.get_log_dir(), rospy.get_param("/run_id"), "rosout.log")
    lines = []
    with open(path) as f:
        for line in f:
            fields = line.split(" ", 3)
            if len(fields) == 4 and fields[2] == node:
                lines.append((fields[1], fields[3].rstrip("\n")))
    return lines


class DropInSets(unittest.TestCase):
    def test_sets_load_cleanly_and_reach_their_goals(self):
        tracks = {robot: Track(robot) for robot, _, _, _, _ in CASES}
        clients = {robot: action_client(robot, timeout=120.0) for robot, _, _, _, _ in CASES}
        for track in tracks.values():
            track.wait()

        # Start-up: the lines are logged before the action server starts.
        for robot, name, _, _, infos in CASES:
            lines = rosout_lines("/%s/move_base" % robot)
            self.assertTrue(lines, "%s: nothing from /%s/move_base in rosout.log" % (name, robot))
            bad = [t for level, t in lines if level in ("ERROR", "FATAL") or "unknown parameter" in t]
            self.assertEqual(bad, [], "%s: %s" % (name, bad))
            for info in infos:
                self.assertTrue(any(level == "INFO" and info in t for level, t in lines),
                                "%s: no info line '%s' in %s" % (name, info, lines))
            # An implemented key is never called ignored (the costmaps' own transform_tolerance).
            for costmap in ("global_costmap", "local_costmap"):
                key = "/%s/move_base/%s/transform_tolerance:" % (robot, costmap)
                self.assertFalse([t for _, t in lines if key in t], "%s: %s noted" % (name, key))

        # Both goals at once, each through actionlib.
        results = {}

        def drive(robot, goal):
            results[robot] = run_goal(clients[robot], make_goal(*goal), timeout=240.0)

        threads = [threading.Thread(target=drive, args=(robot, goal)) for robot, _, goal, _, _ in CASES]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for robot, name, goal, tolerance, _ in CASES:
            state, text, seconds = results[robot]
            self.assertEqual(state, GoalStatus.SUCCEEDED, "%s: %s: %s" % (name, state_name(state), text))
            x, y, _ = tracks[robot].pose_since(rospy.Time.now().to_sec() - 1.0)
            self.assertLess(math.hypot(x - goal[0], y - goal[1]), tolerance + 0.05,
                            "%s ended at (%.2f, %.2f)" % (name, x, y))
            rospy.loginfo("%s: goal reached in %.1f sim s", name, seconds)


if __name__ == "__main__":
    rospy.init_node("nav_dropin_sets_test")
    rostest.rosrun("mbot_navigation", "nav_dropin_sets", DropInSets)
