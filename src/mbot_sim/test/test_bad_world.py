#!/usr/bin/python3
"""rostest (bad_world.test): stage_node on a broken world file exits with code 1 and one
ROS_FATAL line naming the file, the key and the problem."""
import os
import subprocess
import sys
import unittest

import roslib.packages
import rospy
import rostest

# The simulator's own cases (models, robots against walls and each other) are here; the reader's
# are mbot_common's fixtures.
FIXTURES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures")
COMMON = os.path.join(roslib.packages.get_pkg_dir("mbot_common"), "test", "fixtures", "worlds")

CASES = [
    # (world parameter, expected part of the message)
    (os.path.join(COMMON, "invalid_pose_type.world.yaml"),
     'invalid_pose_type.world.yaml: robots[1].pose: expected a list of 3 numbers [x, y, yaw], got "1.0"'),
    (os.path.join(COMMON, "invalid_unknown_key.world.yaml"), "invalid_unknown_key.world.yaml: gravity: unknown key"),
    (os.path.join(FIXTURES, "invalid_robot_in_wall.world.yaml"),
     "robots[0].pose: robot robot_0 at (7.20, 1.00) overlaps a wall"),
    (os.path.join(FIXTURES, "invalid_robot_overlap.world.yaml"),
     "robots[1].pose: robot robot_1 at (2.20, 2.00) overlaps robot robot_0"),
    (os.path.join(COMMON, "invalid_duplicate_robot.world.yaml"), 'robots[1].name: duplicate name "robot_0"'),
    (os.path.join(COMMON, "invalid_missing_map.world.yaml"), "invalid_missing_map.world.yaml: map: "),
    (os.path.join(COMMON, "invalid_bad_map.world.yaml"), "invalid_header.pgm: bad PGM header"),
    (os.path.join(FIXTURES, "invalid_model.world.yaml"), 'robots[0].model: cannot load model "hovercraft"'),
    (os.path.join(COMMON, "invalid_fault_probability.world.yaml"),
     "faults[0].laser_dropout: expected a probability in [0, 1], got 1.5"),
    ("no_such_world", 'world "no_such_world": no world file of that name'),
    ("/nonexistent/dir/some.world.yaml", "/nonexistent/dir/some.world.yaml: cannot read the file"),
]


class BadWorld(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_bad_world")
        cls.stage_node = roslib.packages.find_node("mbot_sim", "stage_node")[0]

    def run_stage(self, *args):
        return subprocess.run([self.stage_node] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                              universal_newlines=True, timeout=60)

    def test_each_broken_world_gives_one_fatal_line_and_exit_code_1(self):
        for i, (world, expected) in enumerate(CASES):
            result = self.run_stage("__name:=bad_stage_%d" % i, "_world:=" + world)
            self.assertEqual(result.returncode, 1, "%s: exit code %d, stderr:\n%s" % (world, result.returncode,
                                                                                      result.stderr))
            fatal = [line for line in result.stderr.splitlines() if "FATAL" in line]
            self.assertEqual(len(fatal), 1, "%s: expected one FATAL line, got:\n%s" % (world, result.stderr))
            self.assertIn(expected, fatal[0])

    def test_missing_world_parameter(self):
        result = self.run_stage("__name:=bad_stage_noworld")
        self.assertEqual(result.returncode, 1)
        self.assertIn("/bad_stage_noworld/world: missing parameter", result.stderr)


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "bad_world", BadWorld, sys.argv)
