#!/usr/bin/env python3
"""rostest checker for fleet scenarios (tests/rostest/fleet_*.test): while goal_tour sends every
robot its goals, record the run with the demo recorder (in this process), then check it:

- every robot's move_base finished each of its goals with SUCCEEDED, in order, within ~timeout
  sim seconds of the first goal, and the robot ended within GOAL_RADIUS of its last goal;
- the simulator reported no contact;
- the report (mbot_bringup.report) renders from the recording, with one row per goal.

Parameters: ~goals_file and ~world (as goal_tour's), ~timeout [s sim time].
"""
import math
import os
import shutil
import tempfile
import unittest

import rospy
import rostest
from mbot_common.paths import resolve_world
from mbot_msgs.msg import Contact

from mbot_bringup.goal_tour import load_goals
from mbot_bringup.recorder_node import Recorder
from mbot_bringup.recording import Recording
from mbot_bringup.report import write_report

GOAL_RADIUS = 0.3  # [m] the nav node's xy_goal_tolerance is smaller; this only catches a wrong place


class FleetScenario(unittest.TestCase):
    def test_every_goal_reached_without_contact(self):
        world = rospy.get_param("~world")
        goals = load_goals(rospy.get_param("~goals_file"), world)
        timeout = rospy.get_param("~timeout", 240.0)
        recorder = Recorder(Recording(world=world))
        rospy.Subscriber("/contacts", Contact, recorder.on_contact)

        # The clock starts with the first goal: before that the nodes start up in wall time, while
        # the simulator may already run far ahead (rostest's time-limit covers a start that hangs).
        deadline = None
        while not rospy.is_shutdown():
            recorder.attach_new_robots()
            now = rospy.Time.now()
            with recorder.lock:
                if deadline is None and recorder.rec.goals:
                    deadline = now + rospy.Duration(timeout)
                done = {r: [n for n in recorder.rec.nav_results if n["robot"] == r] for r in goals}
            if all(len(done[r]) >= len(goals[r]) for r in goals):
                break
            if deadline is not None and now > deadline:
                break
            rospy.sleep(0.2)
        recorder.close()
        rec = recorder.rec

        lines = "\n".join(rec.summary_lines())
        rospy.loginfo("fleet scenario %s:\n%s", world, lines)
        for robot, robot_goals in goals.items():
            states = [n["status"] for n in done[robot]]
            self.assertEqual(states, ["SUCCEEDED"] * len(robot_goals),
                             "%s: goal results %s after %.0f sim s\n%s" % (robot, done[robot], timeout, lines))
            track = rec.robots[robot]
            x, y = robot_goals[-1][0], robot_goals[-1][1]
            self.assertLess(math.hypot(track.x[-1] - x, track.y[-1] - y), GOAL_RADIUS, lines)
        self.assertEqual(rec.contacts, [], lines)

        out_dir = tempfile.mkdtemp(prefix="fleet_scenario_")
        try:
            recording = os.path.join(out_dir, "recording.json")
            rec.save(recording)
            with open(write_report(recording, resolve_world(world), out_dir)) as f:
                page = f.read()
            self.assertEqual(page.count("<td>SUCCEEDED</td>"), sum(len(g) for g in goals.values()))
            self.assertTrue(os.path.getsize(os.path.join(out_dir, "trajectories.png")) > 0)
        finally:
            shutil.rmtree(out_dir)


if __name__ == "__main__":
    rospy.init_node("fleet_scenario")
    rostest.rosrun("mbot_bringup", "fleet_scenario", FleetScenario)
