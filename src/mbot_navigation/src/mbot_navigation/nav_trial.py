"""Navigation trial benchmark (not a test): one robot drives to random reachable goals, one after
the other, in a world of its own roslaunch; count the goals reached and the contacts.

    rosrun mbot_navigation nav_trial --runs 100 --seed 1 --json

prints ``{"runs": N, "succeeded": N, "contacts": N, "sim_seconds": X, "wall_seconds": X}``.

- The world defaults to test/fixtures/worlds/nav_office.world.yaml (the office with one robot, robot_0,
  and the crate). The program starts ``fleet_navigation.launch`` on a free private port (its own
  master) and stops it at the end.
- Goals are drawn with numpy's RandomState(seed) among the map cells whose clearance (distance to
  the nearest wall) is at least ``--clearance``, that are at least as far from the world's static
  obstacles, and that the robot can reach on the static map from where it starts; each goal gets a
  random yaw. The same seed gives the same goals.
- A run is one goal: it succeeds when the action ends SUCCEEDED within ``--timeout`` sim seconds
  (otherwise it is cancelled). Contacts are the simulator's /contacts that involve the robot.
- ``sim_seconds`` and ``wall_seconds`` cover the runs (not the start-up).

The pure parts (goal sampling, the summary) work without ROS; run() and main() need it.
"""
import argparse
import json
import math
import os
import signal
import socket
import subprocess
import sys
import time

import numpy as np

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


def summary(outcomes, sim_seconds, wall_seconds):
    """The benchmark's figures from a list of per-run dicts with 'succeeded' and 'contacts'."""
    return {"runs": len(outcomes),
            "succeeded": sum(1 for o in outcomes if o["succeeded"]),
            "contacts": sum(o["contacts"] for o in outcomes),
            "sim_seconds": round(sim_seconds, 1),
            "wall_seconds": round(wall_seconds, 1)}


def free_port():
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("localhost", 0))
        return s.getsockname()[1]


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
        return drive(args, log)
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


def drive(args, log):
    import rospy
    from actionlib_msgs.msg import GoalStatus
    from mbot_msgs.msg import Contact
    from nav_msgs.msg import OccupancyGrid, Odometry

    from mbot_navigation.move_base_client import connect_move_base, make_goal

    wait_for_sim_time("nav_trial", args.launch_log)
    rospy.init_node("nav_trial", disable_signals=True)
    robot = args.robot
    pose = []
    rospy.Subscriber("/%s/base_pose_ground_truth" % robot, Odometry,
                     lambda m: pose.__setitem__(slice(None), [m.pose.pose.position.x, m.pose.pose.position.y]))
    contacts = []
    rospy.Subscriber("/contacts", Contact,
                     lambda m: contacts.append(m) if robot in (m.body_a, m.body_b) else None, queue_size=100)
    grid = grid_paths.grid_from_msg(rospy.wait_for_message("/map", OccupancyGrid, timeout=60.0))
    try:
        client = connect_move_base(robot, wall_timeout=60.0)
    except RuntimeError as e:
        raise RuntimeError("%s (see %s)" % (e, args.launch_log))
    deadline = time.time() + 60.0
    while not pose and time.time() < deadline:
        time.sleep(0.05)
    if not pose:
        raise RuntimeError("no ground truth for %s" % robot)

    mask = candidate_cells(grid, pose, args.clearance, static_obstacles(args.world))
    goals = sample_goals(grid, mask, args.runs, args.seed)
    log("%d runs, goals drawn from %d cells with clearance >= %.2f m" % (args.runs, int(mask.sum()), args.clearance))

    outcomes = []
    sim_start, wall_start = rospy.Time.now(), time.time()
    for i, (x, y, yaw) in enumerate(goals):
        goal = make_goal(x, y, yaw)
        before = len(contacts)
        t0 = rospy.Time.now()
        client.send_goal(goal)
        finished = client.wait_for_result(rospy.Duration(args.timeout))
        if not finished:
            client.cancel_goal()
            client.wait_for_result(rospy.Duration(5.0))
        state = client.get_state()
        outcome = {"goal": [round(x, 2), round(y, 2), round(yaw, 2)], "succeeded": state == GoalStatus.SUCCEEDED,
                   "state": state, "text": client.get_goal_status_text() if finished else "timeout",
                   "sim_seconds": round((rospy.Time.now() - t0).to_sec(), 1), "contacts": len(contacts) - before,
                   "end": [round(v, 2) for v in pose]}
        outcomes.append(outcome)
        log("run %d/%d: (%.2f, %.2f, %.2f) %s in %.1f sim s, contacts %d%s" % (
            i + 1, args.runs, x, y, yaw, "ok" if outcome["succeeded"] else "FAILED", outcome["sim_seconds"],
            outcome["contacts"], "" if outcome["succeeded"] else " (%s)" % outcome["text"]))
    result = summary(outcomes, (rospy.Time.now() - sim_start).to_sec(), time.time() - wall_start)
    rospy.signal_shutdown("done")
    return result, outcomes


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="nav_trial", description=__doc__.split("\n\n")[0])
    parser.add_argument("--runs", type=int, default=100)
    parser.add_argument("--seed", type=int, default=1, help="goals and the simulator's noise")
    parser.add_argument("--json", action="store_true", help="print the figures as one JSON line")
    parser.add_argument("--world", default=default_world(), help="world file (default: %(default)s)")
    parser.add_argument("--robot", default="robot_0")
    parser.add_argument("--real-time-factor", type=float, default=0.0,
                        help="the simulator's; 0 = as fast as possible (default)")
    parser.add_argument("--localization", default="fake", choices=("fake", "pf"))
    parser.add_argument("--timeout", type=float, default=150.0, help="per run [sim s]")
    parser.add_argument("--clearance", type=float, default=0.5, help="goals this far from walls [m]")
    parser.add_argument("--details", default="", help="write every run's outcome to this JSON file")
    parser.add_argument("--launch-log", default="/tmp/nav_trial_roslaunch.log")
    return parser.parse_args(argv)


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
        print("%(succeeded)d of %(runs)d goals reached, %(contacts)d contacts, %(sim_seconds).1f sim s in "
              "%(wall_seconds).1f wall s" % result)
    return 0
