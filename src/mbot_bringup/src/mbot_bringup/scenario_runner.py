"""Run a scenario (scenario.py) on a fleet and judge it: the ROS side.

    scripts/scenario office_route [--run-dir DIR] [--no-rviz] [--real-time] [--list]
    rosrun mbot_bringup scenario_runner triangle_trio --run-dir /tmp/run

The runner
1. reads the scenario and the run's world (robots placed as fleet.launch will place them) and
   checks the scenario against it, before anything starts;
2. starts `roslaunch mbot_bringup fleet.launch` with its own master on a free port (lockstep at
   real_time_factor 0 unless --real-time, rviz if there is a DISPLAY and not --no-rviz, a rosbag);
3. plays the timeline in sim time (ScenarioPlayer), showing one status line, and takes rviz
   screenshots at moments (forming, mid_route: halfway along the timeline's longest route,
   switch_<formation>, loss, arrival, and the timeline's own `screenshot` steps);
4. stops what it started (by PID: SIGINT to roslaunch, which stops its nodes; later signals only
   to its own process group) at the end, on a timeout or on Ctrl-C;
5. judges the criteria from the metrics collector's files (load_run / summarize), writes
   RUN_DIR/criteria.json and prints PASS/FAIL per criterion. Exit status 0: passed, 1: a
   criterion failed, 2: a bad scenario or command line, 3: the fleet did not come up.

Run dir: scenario.yaml (a copy), world.yaml, metrics/, run.bag, criteria.json, timeline.json (what
each step did and when), screenshots/*.png, launch.log, ros_logs/.

The parts, by role: scenario_player.py (ScenarioPlayer, the timeline), fleet_launch.py (fleet.launch
and stopping it), scenario_screenshots.py, scenario_judge.py (criteria.json), console.py (say).
Their names stay importable from here.
"""
import os
import shutil
import sys
import time

from mbot_bringup.console import say
from mbot_bringup.fleet_launch import (START_ROBOTS, START_WALL, START_WALL_PER_ROBOT, WALL_PER_SIM,  # noqa: F401
                                       FleetLaunch, prepare_run_dir, start_wall)
from mbot_bringup.scenario import check_against_world, load_scenario, summary_lines
from mbot_bringup.scenario_judge import judge, write_criteria
from mbot_common.net import free_port
from mbot_bringup.scenario_player import (STATE_EVENTS, STATUS_PERIOD, SUCCEEDED, TERMINAL,  # noqa: F401
                                          ScenarioPlayer, round_ended)
from mbot_bringup.scenario_screenshots import Screenshots, SimPause, view_drawn  # noqa: F401
from mbot_common.strict_yaml import ConfigError


# --- finding scenarios ----------------------------------------------------------------------

def scenarios_directory():
    """The package's scenarios/ folder (source or installed)."""
    import rospkg

    return os.path.join(rospkg.RosPack().get_path("mbot_bringup"), "scenarios")


def scenario_path(name_or_path):
    """A name means scenarios/NAME.yaml of the package; anything with a / or .yaml is a path."""
    if "/" in name_or_path or name_or_path.endswith(".yaml"):
        return os.path.abspath(name_or_path)
    path = os.path.join(scenarios_directory(), name_or_path + ".yaml")
    if not os.path.isfile(path):
        raise ConfigError('scenario "%s": no file %s (scenarios: %s)'
                          % (name_or_path, path, ", ".join(list_scenarios())))
    return path


def list_scenarios():
    return sorted(f[:-5] for f in os.listdir(scenarios_directory()) if f.endswith(".yaml"))


def world_argument(scenario):
    """The scenario's world for fleet.launch: a name as it is, a relative path from the scenario's folder."""
    world = scenario.world
    if ("/" in world or world.endswith(".yaml")) and not os.path.isabs(world):
        world = os.path.join(os.path.dirname(os.path.abspath(scenario.path)), world)
    return world


def run(args):
    """The whole run (module docstring); returns the exit status."""
    from mbot_bringup.fleet_world import run_world
    from mbot_common.paths import resolve_world

    try:
        scenario = load_scenario(scenario_path(args.scenario))
        robots = run_world(resolve_world(world_argument(scenario)), scenario.robots)[1]
        check_against_world(scenario, robots)
        run_dir = os.path.abspath(args.run_dir or os.path.join(os.path.expanduser("~/.ros/mbot_runs"), scenario.name))
        prepare_run_dir(run_dir)
    except ConfigError as error:
        say("error: %s" % error)
        return 2
    shutil.copyfile(scenario.path, os.path.join(run_dir, "scenario.yaml"))

    rviz = not args.no_rviz and bool(os.environ.get("DISPLAY"))
    if not args.no_rviz and not rviz:
        say("no DISPLAY: no rviz and no screenshots (scripts/scenario starts Xvfb)")
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port, ROS_LOG_DIR=os.path.join(run_dir, "ros_logs"))
    os.environ.update(ROS_MASTER_URI=env["ROS_MASTER_URI"], ROS_LOG_DIR=env["ROS_LOG_DIR"])
    launch_args = [("world", world_argument(scenario)), ("robots", "" if scenario.robots is None else scenario.robots),
                   ("mode", scenario.mode), ("localization", scenario.localization),
                   ("real_time_factor", 1 if args.real_time else 0),
                   ("lockstep", "false" if args.real_time else "true"),
                   ("rviz", "true" if rviz else "false"), ("record", "false" if args.no_record else "true"),
                   ("run_dir", run_dir)]
    if scenario.mode == "formation":
        launch_args += [("leader", scenario.leader), ("formation", scenario.formation), ("spacing", scenario.spacing),
                        ("topology", scenario.topology), ("controller", scenario.controller),
                        ("leader_max_vel", scenario.leader_max_vel)]
    say("scenario %s: %d robots in %s, %s; run dir %s (master on port %d)" % (
        scenario.name, len(robots), scenario.world,
        "%s %g m" % (scenario.formation, scenario.spacing) if scenario.mode == "formation" else "dispatch",
        run_dir, port))

    launch = FleetLaunch(port, launch_args, os.path.join(run_dir, "launch.log"), env)
    screenshots = None
    player = None
    status = 0
    try:
        import rosgraph
        import rospy

        end = time.time() + 60.0
        # rospy reads /use_sim_time once, in init_node: wait until roslaunch has set it, or the
        # runner would keep wall time while everything else runs on sim time.
        while not _sim_time_set(rosgraph):
            if not launch.alive() or time.time() > end:
                say("error: the fleet did not start; the end of %s:\n%s" % (launch.log_path, launch.tail()))
                return 3
            time.sleep(0.2)
        rospy.init_node("scenario_runner", disable_signals=True)
        if rviz:
            # lockstep runs far ahead of rviz: pause for each shot; real time needs no pause
            screenshots = Screenshots(os.environ["DISPLAY"], os.path.join(run_dir, "screenshots"),
                                      hold=None if args.real_time else SimPause())
        player = ScenarioPlayer(scenario, robots, run_dir, screenshots)
        try:
            player.wait_ready()
            if screenshots is not None and not screenshots.wait_drawn():
                say("rviz shows nothing after 90 s: the screenshots may be blank")
            player.t0 = rospy.get_time()   # the scenario's clock starts now
        except (RuntimeError, AssertionError) as error:
            say("error: the fleet did not come up: %s\nthe end of %s:\n%s" % (error, launch.log_path, launch.tail()))
            return 3
        say("fleet up; playing %d steps (time limit %g s sim)" % (len(scenario.timeline), scenario.time_limit))
        facts = player.play(alive=launch.alive)
        say("scenario over at %.1f s sim: stopping the fleet" % facts["end_s"])
        if screenshots is not None:
            screenshots.close()
    except KeyboardInterrupt:
        if player is not None:
            player.clear_status()
        say("interrupted: stopping everything this run started")
        status = 130
    finally:
        if "rospy" in sys.modules:
            sys.modules["rospy"].signal_shutdown("scenario over")
        launch.stop()
        if player is not None and player.t0 is not None:
            player.write_log(os.path.join(run_dir, "timeline.json"))
    if status:
        return status

    results, summary = judge(scenario, os.path.join(run_dir, "metrics"), facts)
    write_criteria(os.path.join(run_dir, "criteria.json"), scenario, results, facts)
    for line in summary_lines(scenario.name, results):
        print(line)
    if summary is not None:
        print("  %.1f s sim from the first step, %d steps (%d failed), %d/%d arrivals, %d goals reached, "
              "final state %s" % (facts["end_s"], len(player.log), facts["failed_steps"], facts["arrivals"],
                                  facts["targets"], facts["goals_reached"], facts["final_state"] or "-"))
    shots = screenshots.taken if screenshots is not None else []
    bag = "run.bag, " if os.path.exists(os.path.join(run_dir, "run.bag")) else ""
    print("run dir: %s (%s%d screenshots)" % (run_dir, bag, len(shots)))
    return 0 if all(c["passed"] for c in results) else 1


def parse_args(argv):
    import argparse

    parser = argparse.ArgumentParser(prog="scenario", description="Run a fleet scenario and judge it (mbot_bringup).")
    parser.add_argument("scenario", nargs="?", help="a name (scenarios/NAME.yaml of mbot_bringup) or a path")
    parser.add_argument("--run-dir", help="where the run's files go (default ~/.ros/mbot_runs/NAME)")
    parser.add_argument("--no-rviz", action="store_true", help="no rviz, no screenshots")
    parser.add_argument("--no-record", action="store_true", help="no rosbag")
    parser.add_argument("--real-time", action="store_true", help="real_time_factor 1 without lockstep (to watch it)")
    parser.add_argument("--list", action="store_true", help="list the scenarios and exit")
    return parser.parse_args(argv)


def _sim_time_set(rosgraph):
    """True once the master is up and /use_sim_time is true."""
    try:
        return rosgraph.Master("/scenario_runner").getParam("/use_sim_time") is True
    except Exception:  # noqa: B902 (no master yet, or the parameter is not set yet)
        return False


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.list:
        for name in list_scenarios():
            try:
                s = load_scenario(scenario_path(name))
                first = " ".join(s.description.split()).split(". ")[0].rstrip(".")   # its first sentence
                print("%-16s %s" % (name, first if len(first) <= 100 else first[:97] + "..."))
            except ConfigError as error:
                print("%-18s (bad file) %s" % (name, error))
        return 0
    if not args.scenario:
        say("error: name a scenario (--list shows them)")
        return 2
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
