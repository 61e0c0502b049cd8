"""Navigation trial benchmark (not a test): robots drive to random reachable goals, one after the
other, in a world of its own roslaunch; count the goals reached and the contacts.

    rosrun mbot_navigation nav_trial --runs 100 --seed 1 --json
    rosrun mbot_navigation nav_trial --robots 3 --world maps/office.world.yaml --localization pf --json

prints ``{"runs", "succeeded", "contacts", "sim_seconds", "wall_seconds", "robots", "mean_goal_s"}``.

- The world defaults to test/fixtures/worlds/nav_office.world.yaml (the office with one robot, robot_0,
  and the crate). The program starts ``fleet_navigation.launch`` on a free private port (its own
  master) and stops it at the end.
- ``--robots N`` drives the world's first N robots at once, each its own sequence of goals (the
  runs split as evenly as possible: 100 over 3 is 34, 33, 33). Robot i's goals are drawn with the
  seed + i (robot 0's are the single-robot trial's).
- Goals are drawn with numpy's RandomState among the map cells whose clearance (distance to the
  nearest wall) is at least ``--clearance``, that are at least as far from the world's static
  obstacles, and that the robot can reach on the static map from where it starts; each goal gets a
  random yaw. With several robots, a goal closer than ``--goal-separation`` to another robot's
  current goal (or to where an idle robot stands) is not sent: the next of the robot's spare goals
  (its own seeded stream) that is clear replaces it. So the same seed gives the same goals except
  for these replacements, which depend on timing.
- A run is one goal. It succeeds when the action ends SUCCEEDED within ``--timeout`` sim seconds
  (otherwise it is cancelled) AND the simulator's ground truth (/<robot>/base_pose_ground_truth)
  puts the robot within the nav node's xy_goal_tolerance of the goal when it ends (judge()): the
  nav node checks its goal against its own localization, which may be wrong. The tolerance is
  read from the nav node's parameters (~DWAPlannerROS/xy_goal_tolerance, config/nav_dwa.yaml).
- Contacts are the simulator's /contacts that involve a driven robot (one message per pair that
  starts touching: robot-robot counts once). ``mean_goal_s`` is the mean sim time of the goals
  reached. ``sim_seconds`` and ``wall_seconds`` cover the runs (not the start-up).

The pure parts (goal sampling and picking, the judgement, the summary) work without ROS; run()
and main() need it.
"""
import argparse
import json
import math
import os
import signal
import subprocess
import sys
import time

import numpy as np

from mbot_common.net import free_port
from mbot_common.world import load_world
from mbot_navigation import grid_paths

ROBOT_RADIUS = 0.15  # [m] mbot's footprint; the clearance default keeps goals well away from walls


def default_world():
    """test/fixtures/worlds/nav_office.world.yaml of this package (source tree)."""
    here = os.path.dirname(os.path.abspath(__file__))  # src/mbot_navigation
    return os.path.normpath(os.path.join(here, "..", "..", "test", "fixtures", "worlds", "nav_office.world.yaml"))


def static_obstacles(world_path):
    """The world file's static obstacles as discs (x, y, radius) [m]: a box by its circumscribed
    circle (half its diagonal), a cylinder by its radius."""
    discs = []
    for o in load_world(world_path).obstacles:
        if o.shape.type == "box":
            discs.append((o.pose.x, o.pose.y, 0.5 * math.hypot(o.shape.length, o.shape.width)))
        else:
            discs.append((o.pose.x, o.pose.y, o.shape.radius))
    return discs


def candidate_cells(grid, start, clearance, obstacles=()):
    """Mask of goal cells: clearance from the map's walls >= `clearance` [m], at least that far from
    every obstacle disc (x, y, r), and reachable from `start` (x, y) [m] for a robot of ROBOT_RADIUS."""
    clear = grid_paths.clearance(grid)
    rows, cols = grid.occupancy.shape
    ys = grid.origin_y + (np.arange(rows) + 0.5) * grid.resolution
    xs = grid.origin_x + (np.arange(cols) + 0.5) * grid.resolution
    xx, yy = np.meshgrid(xs, ys)
    free = clear >= ROBOT_RADIUS
    for ox, oy, r in obstacles:
        free &= np.hypot(xx - ox, yy - oy) >= r + ROBOT_RADIUS
    cell = grid_paths.world_to_cell(grid, start[0], start[1])
    reachable = grid_paths.region_of(free, cell) if cell is not None else np.zeros_like(free)
    ok = reachable & (clear >= clearance)
    for ox, oy, r in obstacles:
        ok &= np.hypot(xx - ox, yy - oy) >= r + clearance
    return ok


def sample_goals(grid, mask, runs, seed):
    """`runs` goals (x, y, yaw) drawn uniformly from the cells of `mask`, reproducibly."""
    rng = np.random.RandomState(seed)
    rows, cols = np.nonzero(mask)
    if len(rows) == 0:
        raise ValueError("no goal cell: nothing is reachable with that clearance")
    picks = rng.randint(0, len(rows), size=runs)
    yaws = rng.uniform(-math.pi, math.pi, size=runs)
    return [grid_paths.cell_to_world(grid, rows[i], cols[i]) + (float(yaw),) for i, yaw in zip(picks, yaws)]


def split_runs(runs, robots):
    """`runs` goals over `robots` robots as evenly as possible, the first robots one more."""
    return [runs // robots + (1 if i < runs % robots else 0) for i in range(robots)]


def pick_goal(planned, spares, claims, separation):
    """The goal to send: `planned` (x, y, yaw) if it is at least `separation` [m] from every claimed
    point (x, y) of the other robots, else the first such goal taken from the iterator `spares`.
    Returns (goal, replaced). ValueError when the spares run out."""
    def clear(goal):
        return all(math.hypot(goal[0] - cx, goal[1] - cy) >= separation for cx, cy in claims)

    if clear(planned):
        return planned, False
    for goal in spares:
        if clear(goal):
            return goal, True
    raise ValueError("no spare goal is %.2f m clear of the other robots' goals" % separation)


def judge(reached, elapsed, timeout, end_xy, goal_xy, tolerance):
    """Did a run succeed? (succeeded, why not).

    :param reached: the action ended SUCCEEDED
    :param elapsed: [s sim] from sending the goal to its end; more than `timeout` fails the run
    :param end_xy: the robot's true position (ground truth) when the goal ended [m]
    :param goal_xy: the goal [m]
    :param tolerance: the nav node's xy_goal_tolerance [m]: the robot must truly be this close
    """
    if elapsed > timeout:
        return False, "timeout"
    if not reached:
        return False, "not SUCCEEDED"
    off = math.hypot(end_xy[0] - goal_xy[0], end_xy[1] - goal_xy[1])
    if off > tolerance:
        return False, "SUCCEEDED but truly %.3f m from the goal (tolerance %.3f m)" % (off, tolerance)
    return True, ""


def summary(outcomes, contacts, sim_seconds, wall_seconds, robots=1):
    """The benchmark's figures from a list of per-run dicts with 'succeeded' and 'sim_seconds' and
    the number of contacts during the runs. mean_goal_s: the mean sim time of the goals reached
    (None when none was)."""
    times = [o["sim_seconds"] for o in outcomes if o["succeeded"]]
    return {"runs": len(outcomes),
            "succeeded": len(times),
            "contacts": contacts,
            "sim_seconds": round(sim_seconds, 1),
            "wall_seconds": round(wall_seconds, 1),
            "robots": robots,
            "mean_goal_s": round(sum(times) / len(times), 1) if times else None}


def run(args, log):
    """Start the world, drive the runs, return (summary dict, per-run outcomes)."""
    port = free_port()
    os.environ["ROS_MASTER_URI"] = "http://localhost:%d" % port
    os.environ.pop("ROS_IP", None)
    launch = ["roslaunch", "-p", str(port), "mbot_navigation", "fleet_navigation.launch",
              "world:=" + os.path.abspath(args.world), "real_time_factor:=%g" % args.real_time_factor,
              "seed:=%d" % args.seed, "localization:=" + args.localization,
              "lockstep:=true"]  # sim time never runs ahead of the nav nodes, at any real-time factor
    log("starting: %s" % " ".join(launch))
    with open(args.launch_log, "w") as launch_log:
        process = subprocess.Popen(launch, stdout=launch_log, stderr=subprocess.STDOUT, start_new_session=True)
    try:
        return drive(args, log, process)
    finally:
        stop(process, log)


def stop(process, log):
    """SIGINT to the roslaunch's process group (it stops its nodes), SIGKILL after 20 s."""
    if process.poll() is not None:
        return
    os.killpg(process.pid, signal.SIGINT)
    try:
        process.wait(timeout=20)
    except subprocess.TimeoutExpired:
        log("roslaunch did not stop in 20 s: killing it")
        os.killpg(process.pid, signal.SIGKILL)
        process.wait()


def wait_for_sim_time(name, launch_log, wall_timeout=60.0):
    """rospy decides at init_node whether to use sim time: wait (wall time) until the launch has
    set /use_sim_time on the master. RuntimeError pointing at `launch_log` when it does not."""
    import rosgraph

    master = rosgraph.Master("/" + name)
    deadline = time.time() + wall_timeout
    while True:
        try:
            if master.hasParam("/use_sim_time"):
                return
        except (OSError, rosgraph.MasterException):
            pass  # the master is not up yet
        if time.time() > deadline:
            raise RuntimeError("no /use_sim_time from the launch after %.0f s (see %s)" % (wall_timeout, launch_log))
        time.sleep(0.1)


def trial_robots(args):
    """The robots to drive: --robot alone, or the world's first --robots."""
    if args.robots == 1:
        return [args.robot]
    names = [r.name for r in load_world(args.world).robots]
    if len(names) < args.robots:
        raise ValueError("--robots %d: the world %s has %d robot(s)" % (args.robots, args.world, len(names)))
    return names[:args.robots]


def goal_tolerance(robot):
    """The xy_goal_tolerance [m] of /<robot>/move_base, where the nav node reads it."""
    import rospy

    for key in ("/%s/move_base/DWAPlannerROS/xy_goal_tolerance" % robot, "/%s/move_base/xy_goal_tolerance" % robot):
        if rospy.has_param(key):
            return float(rospy.get_param(key))
    raise RuntimeError("/%s/move_base has no xy_goal_tolerance parameter (config/nav_dwa.yaml sets it)" % robot)


class Lane(object):
    """One robot's sequence of goals and the goal it drives to now."""

    def __init__(self, robot, client, goals, spares, tolerance):
        self.robot, self.client, self.goals, self.spares, self.tolerance = robot, client, goals, spares, tolerance
        self.pose = []       # ground truth (x, y) [m], updated by its subscriber
        self.estimate = []   # the localization's last amcl_pose (x, y) [m]: why a goal ends off
        self.next = 0        # index of the next goal in `goals`
        self.goal = None     # the goal it drives to (x, y, yaw), None when idle
        self.started = None  # sim time the goal was sent
        self.cancelled = None
        self.ended = None    # the goal's final state, set when its result has arrived
        self.contacts_before = 0
        self.replaced = False

    def on_done(self, state, result):
        """done_cb: the result has arrived. Only then may the next goal go out: a result that
        comes in after send_goal replaced the handle makes actionlib log an ERROR."""
        self.ended = state

    def claim(self):
        """The point the other robots' goals keep away from: its goal, or where it stands."""
        return self.goal[:2] if self.goal is not None else tuple(self.pose)


def drive(args, log, process=None):
    import rospy
    from actionlib_msgs.msg import GoalStatus
    from mbot_msgs.msg import Contact
    from geometry_msgs.msg import PoseWithCovarianceStamped
    from nav_msgs.msg import OccupancyGrid, Odometry

    from mbot_navigation.move_base_client import connect_move_base, make_goal

    wait_for_sim_time("nav_trial", args.launch_log)
    rospy.init_node("nav_trial", disable_signals=True)
    robots = trial_robots(args)
    contacts = []
    rospy.Subscriber("/contacts", Contact,
                     lambda m: contacts.append(m) if m.body_a in robots or m.body_b in robots else None,
                     queue_size=100)
    grid = grid_paths.grid_from_msg(rospy.wait_for_message("/map", OccupancyGrid, timeout=60.0))
    obstacles = static_obstacles(args.world)
    lanes = []
    for i, (robot, runs) in enumerate(zip(robots, split_runs(args.runs, len(robots)))):
        try:
            client = connect_move_base(robot, wall_timeout=60.0)
        except RuntimeError as e:
            raise RuntimeError("%s (see %s)" % (e, args.launch_log))
        lane = Lane(robot, client, None, None, goal_tolerance(robot))
        rospy.Subscriber("/%s/base_pose_ground_truth" % robot, Odometry,
                         lambda m, pose=lane.pose: pose.__setitem__(
                             slice(None), [m.pose.pose.position.x, m.pose.pose.position.y]))
        rospy.Subscriber("/%s/amcl_pose" % robot, PoseWithCovarianceStamped,
                         lambda m, estimate=lane.estimate: estimate.__setitem__(
                             slice(None), [m.pose.pose.position.x, m.pose.pose.position.y]))
        deadline = time.time() + 60.0
        while not lane.pose and time.time() < deadline:
            time.sleep(0.05)
        if not lane.pose:
            raise RuntimeError("no ground truth for %s" % robot)
        mask = candidate_cells(grid, lane.pose, args.clearance, obstacles)
        lane.goals = sample_goals(grid, mask, runs, args.seed + i)
        lane.spares = iter(sample_goals(grid, mask, 1000, [args.seed + i, 1]))
        lanes.append(lane)
        log("%s: %d runs, goals drawn from %d cells with clearance >= %.2f m, xy_goal_tolerance %.3f m" % (
            robot, runs, int(mask.sum()), args.clearance, lane.tolerance))

    outcomes = []
    sim_start, wall_start, contacts_start = rospy.Time.now(), time.time(), len(contacts)
    while any(lane.goal is not None or lane.next < len(lane.goals) for lane in lanes):
        if process is not None and process.poll() is not None:
            raise RuntimeError("the roslaunch stopped (see %s)" % args.launch_log)
        if rospy.is_shutdown():
            raise RuntimeError("ROS shut down during the trial")
        now = rospy.Time.now()
        for lane in lanes:
            if lane.goal is None:
                if lane.next == len(lane.goals):
                    continue
                claims = [other.claim() for other in lanes if other is not lane]
                lane.goal, lane.replaced = pick_goal(lane.goals[lane.next], lane.spares, claims,
                                                     args.goal_separation)
                lane.next += 1
                lane.started, lane.cancelled, lane.ended, lane.contacts_before = now, None, None, len(contacts)
                lane.client.send_goal(make_goal(*lane.goal), done_cb=lane.on_done)
                continue
            done = lane.ended is not None
            elapsed = (now - lane.started).to_sec()
            if not done and lane.cancelled is None and elapsed > args.timeout:
                lane.client.cancel_goal()
                lane.cancelled = now
            if not done and not (lane.cancelled is not None and (now - lane.cancelled).to_sec() > 5.0):
                continue
            state = lane.ended if done else lane.client.get_state()
            x, y, yaw = lane.goal
            succeeded, why = judge(state == GoalStatus.SUCCEEDED, elapsed, args.timeout, lane.pose, (x, y),
                                   lane.tolerance)
            outcome = {"robot": lane.robot, "goal": [round(x, 2), round(y, 2), round(yaw, 2)],
                       "replaced": lane.replaced, "succeeded": succeeded, "state": state,
                       "text": why or lane.client.get_goal_status_text(), "sim_seconds": round(elapsed, 1),
                       "contacts": len(contacts) - lane.contacts_before,
                       "contact_pairs": ["%s-%s" % (c.body_a, c.body_b) for c in contacts[lane.contacts_before:]],
                       "end": [round(v, 3) for v in lane.pose],
                       "estimate": [round(v, 3) for v in lane.estimate]}
            outcomes.append(outcome)
            lane.goal = None
            log("run %d/%d %s: (%.2f, %.2f, %.2f)%s %s in %.1f sim s, contacts %d%s" % (
                len(outcomes), args.runs, lane.robot, x, y, yaw, " (replaced)" if lane.replaced else "",
                "ok" if succeeded else "FAILED", elapsed, outcome["contacts"],
                "" if succeeded else " (%s; state %d %r, truly at %.2f, %.2f, localized at %s; others at %s)" % (
                    why, state, lane.client.get_goal_status_text(), lane.pose[0], lane.pose[1],
                    ", ".join("%.2f" % v for v in lane.estimate) or "-",
                    "; ".join("%s %.2f, %.2f" % (o.robot, o.pose[0], o.pose[1])
                              for o in lanes if o is not lane) or "-")))
        time.sleep(0.01)  # wall: a poll; sim time may run many times faster (or stand still)
    result = summary(outcomes, len(contacts) - contacts_start, (rospy.Time.now() - sim_start).to_sec(),
                     time.time() - wall_start, len(robots))
    rospy.signal_shutdown("done")
    return result, outcomes


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="nav_trial", description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1, help="goals and the simulator's noise")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON line")
    parser.add_argument("--world", default=default_world(), help="world file (default: %(default)s)")
    parser.add_argument("--robot", default="robot_0", help="the robot to drive with --robots 1")
    parser.add_argument("--robots", type=int, default=1,
                        help="drive the world's first N robots at once, the runs split among them")
    parser.add_argument("--goal-separation", type=float, default=1.0,
                        help="a goal at least this far from the other robots' goals [m]")
    parser.add_argument("--real-time-factor", type=float, default=0.0,
                        help="the simulator's; 0 = as fast as possible (default)")
    parser.add_argument("--localization", default="fake", choices=("fake", "pf"))
    parser.add_argument("--timeout", type=float, default=150.0, help="per run [sim s]")
    parser.add_argument("--clearance", type=float, default=0.5, help="goals this far from walls [m]")
    parser.add_argument("--details", default="", help="write every run's outcome to this JSON file")
    parser.add_argument("--launch-log", default="/tmp/nav_trial_roslaunch.log")
    args = parser.parse_args(argv)
    if args.robots < 1:
        parser.error("--robots must be >= 1, got %d" % args.robots)
    if args.runs < 1:
        parser.error("--runs must be >= 1, got %d" % args.runs)
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)

    def log(message):
        print("nav_trial: " + message, file=sys.stderr)
        sys.stderr.flush()

    result, outcomes = run(args, log)
    if args.details:
        with open(args.details, "w") as f:
            json.dump({"summary": result, "runs": outcomes}, f, indent=1)
    if args.json:
        print(json.dumps(result))
    else:
        print("%(robots)d robot(s): %(succeeded)d of %(runs)d goals reached (mean %(mean_goal_s)s sim s per goal "
              "reached), %(contacts)d contacts, %(sim_seconds).1f sim s in %(wall_seconds).1f wall s" % result)
    return 0
