#!/usr/bin/python3
"""rostest of one scenario (mbot_bringup scenarios/NAME.yaml): plays its timeline on the fleet the
.test file launches (fleet.launch with the scenario's settings, lockstep at real_time_factor 0)
with the scenario runner's ScenarioPlayer, then judges its pass criteria from the metrics
collector's files, exactly as scripts/scenario does, and fails naming every criterion that failed.

Parameters: ~scenario (a name), ~run_dir (fleet.launch's run_dir). The .test file repeats the
scenario's fleet settings (roslaunch cannot read them from the file); the check fails when they
differ from the scenario's.
"""
import os
import shutil
import sys
import time
import unittest

import rospy
import rostest

from mbot_bringup.scenario import check_against_world, load_scenario, summary_lines
from mbot_bringup.scenario_runner import ScenarioPlayer, judge, scenario_path, write_criteria
from mbot_common.world import load_world
from mbot_follower.metrics import RunFileError, load_run, run_span


def wait_for_metrics(metrics_dir, until, wall_timeout=60.0):
    """Wait until the metrics collector's files cover sim time `until` [s] (it writes every second)."""
    end = time.time() + wall_timeout
    while time.time() < end:
        try:
            if run_span(load_run(metrics_dir))[1] >= until:
                return
        except RunFileError:
            pass
        time.sleep(0.5)
    raise AssertionError("%s: the metrics do not reach %.1f s sim after %.0f s wall"
                         % (metrics_dir, until, wall_timeout))


class ScenarioCheck(unittest.TestCase):
    def test_scenario_passes_its_criteria(self):
        rospy.init_node("scenario_check")
        scenario = load_scenario(scenario_path(rospy.get_param("~scenario")))
        run_dir = rospy.get_param("~run_dir")
        robots = [r.name for r in load_world(os.path.join(run_dir, "world.yaml")).robots]
        check_against_world(scenario, robots)
        self.assertLaunchedAsTheScenarioSays(scenario, robots)

        player = ScenarioPlayer(scenario, robots, run_dir, show_status=False)
        player.wait_ready()
        facts = player.play()
        player.write_log(os.path.join(run_dir, "timeline.json"))
        wait_for_metrics(os.path.join(run_dir, "metrics"), player.t0 + facts["end_s"])
        results, summary = judge(scenario, os.path.join(run_dir, "metrics"), facts)
        write_criteria(os.path.join(run_dir, "criteria.json"), scenario, results, facts)
        lines = summary_lines(scenario.name, results)
        print("\n".join(lines + ["facts: %s" % facts]))   # in the test output (rostest --text)
        self.assertEqual([c["name"] for c in results if not c["passed"]], [],
                         "\n".join(lines + ["facts: %s" % facts, "steps: %s" % player.log, "run dir: %s" % run_dir]))
        shutil.rmtree(run_dir, ignore_errors=True)   # kept only when the check fails

    def assertLaunchedAsTheScenarioSays(self, scenario, robots):
        if scenario.robots is not None:
            self.assertEqual(len(robots), scenario.robots, "robots:=%d in the .test file" % scenario.robots)
        if scenario.mode == "formation":
            launched = {k: rospy.get_param("/coordinator/" + k) for k in ("formation", "spacing", "topology", "leader")}
            expected = {"formation": scenario.formation, "spacing": scenario.spacing, "topology": scenario.topology,
                        "leader": scenario.leader}
            self.assertEqual(launched, expected,
                             "the .test file's fleet.launch arguments differ from %s" % scenario.path)
        else:
            self.assertTrue(rospy.has_param("/dispatcher/world"), "the .test file must launch mode:=dispatch")


if __name__ == "__main__":
    rostest.rosrun("mbot_bringup", "scenario_check", ScenarioCheck, sys.argv)
