"""Formation benchmark (``scripts/bench formation``): seeded runs of the whole stack at
real_time_factor 0 with lockstep, for fleets of 3, 5 and 10 robots, measured from the
simulator's ground truth.

One run (one fleet size, one seed) in ``field``, an empty 40 x 40 m room:

1. the followers start at random places within 2 m of their slots (the seed draws them), the
   leader at (-14, -10) facing east; the fleet gets the target (4, -10): **converge_s** is the
   time in FORMING;
2. the leader drives east: **rms_straight_m**, the followers' slot error RMS while the leader
   moves (>= 0.1 m/s), from 3 s after NAVIGATING until the switch;
3. when the leader passes x = -2 the formation switches to ``column`` on the move:
   **switch_s**, from the switch until the column stood (the metrics' switch rule,
   metrics.settle: every follower within 0.3 m of its new slot, held 0.5 s; the hold not counted);
4. at the target the first formation again, then a route with two 90 degree turns, (4, 4) and
   (-10, 4): **rms_route_m**, measured as in 2 over both legs;
5. on the way to (-10, -6) one follower's controller is killed: **degraded_s**, the time to
   DEGRADED with the slots re-planned, and **recover_s**, until the others' slot error RMS stays
   below 0.15 m for 1 s (both timed from the controller's last message: a loss is 1 s of silence);
6. **contacts** (from the simulator) and **cycle_p99_ms** (the controllers' cycle time, wall)
   with beside it **overruns** (cycles that took longer than the 50 ms period, all followers) and
   **late_starts** (cycles that began a period or more late), from the metrics collector.

The times (converge, switch, DEGRADED, recover) and both slot RMS are read after the run from
the metrics collector's record (``timings``): it stamps every sample and event with the sim time
of the data, and it is a lockstep pacer. The probe that drives the steps is not, and on a loaded
machine it notices a condition late while sim time runs on (a switch of 4.35 s read as 6.1 s),
and its own samples of the poses read worse than the record (a straight run of 0.048 m by the
probe was 0.002 m in the record). The probe gives only the route's window (sim time).

The formation is ``diamond`` (``triangle`` for 3 robots: a diamond needs 4), spacing 1.5 m.
A row of the table is the worst value over the seeds; ``succeeded`` counts runs in which every
step finished (ARRIVED at every target, DEGRADED after the kill).

The **office route** is a row of its own (``office`` in the output, 3 robots: the office world's;
its rooms hold no more at this spacing): the demo's route (the scenario ``office_route``) in
``office``, a triangle of 1 m formed in the south-east room, driven to its door (5, -3.5), a
switch to ``column``, through the 1.2 m door, the corridor and the north-east room's door to
(7.7, 3.5), and the triangle again. **rms_route_m** is measured as in 2 from the first target
to the last arrival (doors, corridor and both turns), **converge_s** as in 1, **switch_s** as in
3 (triangle -> column, standing at the door), **route_s** is the sim time from the first target
to the last arrival; the world's seed is the run's seed.

The **law** is a dimension (``--laws slot_tracking,mpc``: the followers' ``controller``): the rows
of slot_tracking keep their keys ("3", "3" office), another law's rows are "3 mpc". Every row
also has **slot_p95_switch_m** (the followers' slot errors from the diamond -> column switch
until it is done, 95th percentile; the office row: over the route, as rms_route_m),
**min_clearance_m** (the metrics' closest two robots: centre distance - 2 radii, lowest over
the run) and, for mpc, **mpc_solve_p50_ms** / **mpc_solve_p99_ms** (the worst robot's, from
each controller's ``~mpc_stats``) and **mpc_fallbacks** of **mpc_solves**.

The parent process runs one child process per run (rospy allows one node per process).
"""
import argparse
import json
import math
import os
import shutil
import subprocess
import sys
import tempfile
import time

import numpy as np

from mbot_common.geometry import Pose2D, compose

SIZES = (3, 5, 10)
SPACING = 1.5                  # [m]
MAP = "field.yaml"             # 40 x 40 m, walls at +-20 m
LEADER_START = (-14.0, -10.0)  # [m] facing east; further east for deep formations
START_RADIUS = 2.0             # [m] followers start within this of their slots
MIN_GAP = 0.6                  # [m] centre distance between any two starting robots
ROOM = 19.0                    # [m] starting places stay within +-ROOM
OFFICE_SIZES = (3,)            # the office route: the office world's three robots
OFFICE_SPACING = 1.0           # [m] a triangle of 1 m fits the office's rooms (as office_route)
LAWS = ("slot_tracking",)      # the followers' control law (the controller parameter)


def formation_for(n):
    return "triangle" if n < 4 else "diamond"


def start_poses(n, seed):
    """Seeded start poses [(name, Pose2D)]: the leader at LEADER_START facing east, each follower
    within START_RADIUS of its slot, facing anywhere, no two closer than MIN_GAP."""
    from mbot_follower.formations import make_formation

    rng = np.random.RandomState(seed * 1000 + n)
    offsets = make_formation(formation_for(n), n, SPACING).offsets
    # a deep formation starts further east, so that its rear slots stay in the room
    leader = Pose2D(max(LEADER_START[0], -ROOM + 0.5 - float(offsets[:, 0].min())), LEADER_START[1], 0.0)
    poses = [("robot_0", leader)]
    for i in range(1, n):
        slot = compose(leader, Pose2D(offsets[i][0], offsets[i][1], 0.0))
        for _ in range(1000):
            r, a = START_RADIUS * math.sqrt(rng.uniform()), rng.uniform(-math.pi, math.pi)
            x, y = slot.x + r * math.cos(a), slot.y + r * math.sin(a)
            if abs(x) < ROOM and abs(y) < ROOM and all(math.hypot(x - p.x, y - p.y) >= MIN_GAP for _, p in poses):
                break
        else:
            raise RuntimeError("no free start for robot %d of %d (seed %d)" % (i, n, seed))
        poses.append(("robot_%d" % i, Pose2D(x, y, rng.uniform(-math.pi, math.pi))))
    return poses


def world_yaml(poses, map_path):
    lines = ["# formation benchmark world (generated)", "map: %s" % map_path, "physics_step: 0.01",
             "real_time_factor: 0.0", "seed: 1", "robots:"]
    for name, p in poses:
        lines += ["  - name: %s" % name, "    model: mbot", "    pose: [%.4f, %.4f, %.4f]" % (p.x, p.y, p.theta)]
    return "\n".join(lines) + "\n"


def office_world_yaml(seed, maps_dir):
    """The office world with its map path absolute and the run's seed."""
    with open(os.path.join(maps_dir, "office.world.yaml")) as f:
        lines = f.read().splitlines()
    out = []
    for line in lines:
        if line.startswith("map:"):
            line = "map: %s" % os.path.join(maps_dir, "office.yaml")
        elif line.startswith("seed:"):
            line = "seed: %d" % seed
        elif line.startswith("real_time_factor:"):
            line = "real_time_factor: 0.0"
        out.append(line)
    return "\n".join(out) + "\n"


def office_timings(run, route):
    """converge_s, switch_s [s] and rms_route_m [m] of an office run from the metrics collector's
    Run; route: (start, end) sim time [s] from the first target to the last arrival."""
    from mbot_follower.metrics import switch_done_times

    events = sorted(run.events, key=lambda e: e.t)
    out = {"converge_s": None, "switch_s": None, "rms_route_m": moving_rms(run, route[0], route[1]),
           "slot_p95_switch_m": moving_p95(run, route[0], route[1])}
    done = next((d["switch_time_s"] for d in switch_done_times(run) if d["formation"] == "column"), None)
    if done is not None:
        out["switch_s"] = round(done, 2)
    forming = next((e.t for e in events if e.kind == "state" and e.name == "FORMING"), None)
    navigating = next((e.t for e in events if e.kind == "state" and e.name == "NAVIGATING"
                       and forming is not None and e.t >= forming), None)
    if navigating is not None:
        out["converge_s"] = round(navigating - forming, 2)
    return out


def worst(runs):
    """One table row from the runs of a fleet size: worst value per measure, success counted."""
    row = {"runs": len(runs), "succeeded": sum(1 for r in runs if r.get("succeeded")),
           "contacts": sum(r.get("contacts", 0) for r in runs),
           "overruns": sum(r.get("overruns") or 0 for r in runs),
           "late_starts": sum(r.get("late_starts") or 0 for r in runs)}
    for key in ("rms_straight_m", "rms_route_m", "converge_s", "switch_s", "degraded_s", "recover_s",
                "cycle_p99_ms", "route_s", "slot_p95_switch_m", "mpc_solve_p50_ms", "mpc_solve_p99_ms"):
        values = [r[key] for r in runs if r.get(key) is not None]
        row[key] = round(max(values), 4) if values else None
    clearances = [r["min_clearance_m"] for r in runs if r.get("min_clearance_m") is not None]
    row["min_clearance_m"] = round(min(clearances), 4) if clearances else None
    if any("mpc_solves" in r for r in runs):
        row["mpc_solves"] = sum(r.get("mpc_solves", 0) for r in runs)
        row["mpc_fallbacks"] = sum(r.get("mpc_fallbacks", 0) for r in runs)
    return row


def mpc_figures(stats):
    """The row's mpc figures from each controller's last ~mpc_stats {robot: stats}: the worst
    robot's solve time p50 and p99 [ms], solves and fallbacks summed."""
    if not stats:
        return {}
    out = {"mpc_solves": sum(s.get("solves", 0) for s in stats.values()),
           "mpc_fallbacks": sum(s.get("fallbacks", 0) for s in stats.values())}
    for key in ("solve_ms_p50", "solve_ms_p99"):
        values = [s[key] for s in stats.values() if key in s]
        if values:
            out["mpc_" + key.replace("solve_ms_", "solve_") + "_ms"] = max(values)
    return out


MOVING = 0.1                    # [m/s] the leader at least this fast: its followers' errors count
SETTLE = 3.0                    # [s] after NAVIGATING, before the straight run is measured


def moving_rms(run, since, until):
    """The followers' slot error RMS [m] over the record's samples since <= t < until in which the
    fleet navigates (NAVIGATING, DEGRADED) and the leader moves; None if there are none."""
    from mbot_follower.metrics import PLAN_STATES, finite_rms, leader_speed

    errors = []
    for before, s in zip(run.samples, run.samples[1:]):
        if since <= s.t < until and s.state in PLAN_STATES and leader_speed(before, s) >= MOVING:
            errors += [rs.slot_error for rs in s.robots.values()]
    rms = finite_rms(errors)
    return None if rms is None else round(rms, 4)


def moving_p95(run, since, until):
    """The 95th percentile [m] of the followers' slot errors in the samples moving_rms takes."""
    from mbot_follower.metrics import PLAN_STATES, leader_speed

    errors = []
    for before, s in zip(run.samples, run.samples[1:]):
        if since <= s.t < until and s.state in PLAN_STATES and leader_speed(before, s) >= MOVING:
            errors += [rs.slot_error for rs in s.robots.values() if math.isfinite(rs.slot_error)]
    return round(float(np.percentile(errors, 95)), 4) if errors else None


def window_p95(run, since, until):
    """The 95th percentile [m] of the followers' slot errors in every sample since <= t <= until."""
    errors = [rs.slot_error for s in run.samples if since <= s.t <= until
              for rs in s.robots.values() if math.isfinite(rs.slot_error)]
    return round(float(np.percentile(errors, 95)), 4) if errors else None


def timings(run, route=None):
    """converge_s, switch_s, degraded_s, recover_s [s], rms_straight_m and rms_route_m [m] from a
    metrics collector's Run (its events, samples and controller cycles carry the data's sim
    time); None where the record lacks the step. The loss is timed from the killed controller's
    last cycle. route: (start, end) sim time [s] of the route with turns, from the probe."""
    from mbot_follower.metrics import recoveries, switch_done_times

    events = sorted(run.events, key=lambda e: e.t)
    out = {"converge_s": None, "switch_s": None, "degraded_s": None, "recover_s": None,
           "rms_straight_m": None, "rms_route_m": None, "slot_p95_switch_m": None}
    if route is not None:
        out["rms_route_m"] = moving_rms(run, route[0], route[1])
    forming = next((e.t for e in events if e.kind == "state" and e.name == "FORMING"), None)
    navigating = next((e.t for e in events if e.kind == "state" and e.name == "NAVIGATING"
                       and forming is not None and e.t >= forming), None)
    if navigating is not None:
        out["converge_s"] = round(navigating - forming, 2)
    switch = next((e.t for e in events if e.kind == "switch" and e.name == "column"), None)
    if navigating is not None and switch is not None:
        out["rms_straight_m"] = moving_rms(run, navigating + SETTLE, switch)
    if switch is not None:
        done = next((d["switch_time_s"] for d in switch_done_times(run) if d["t_s"] == switch), None)
        if done is not None:
            out["switch_s"] = round(done, 2)
            out["slot_p95_switch_m"] = window_p95(run, switch, switch + done)
    # the kill: a loss for good. A robot lost for a moment (its controller starved on a busy
    # machine, as the fleet starts) rejoins, and that loss is not the one measured.
    loss = next((e for e in events if e.kind == "loss" and not any(
        r.kind == "rejoin" and r.name == e.name and r.t >= e.t for r in events)), None)
    if loss is None:
        return out
    victim = loss.name
    killed = max((c.t for c in run.controller if c.robot == victim and c.t <= loss.t), default=None)
    if killed is None:
        return out
    # re-planned: the first assignment from the loss on without the victim in a slot
    replanned = next((e.t for e in events if e.kind == "assignment" and e.t >= loss.t
                      and " %s(" % victim not in " " + e.detail.split("slots", 1)[-1]), None)
    if replanned is not None:
        out["degraded_s"] = round(replanned - killed, 2)
    recovered = next((r["recovery_time_s"] for r in recoveries(run)
                      if r["robot"] == victim and r["t_s"] == loss.t), None)
    if recovered is not None:
        out["recover_s"] = round(loss.t + recovered - killed, 2)
    return out


# --- one run (child process) -----------------------------------------------------------------

def listen_mpc_stats(robots):
    """{robot: its controller's last ~mpc_stats} (filled while the run goes on; empty without mpc)."""
    import rospy
    from std_msgs.msg import String

    stats = {}

    def on_stats(msg, robot):
        stats[robot] = json.loads(msg.data)

    for robot in robots:
        rospy.Subscriber("/%s/follower_controller/mpc_stats" % robot, String, on_stats, robot, queue_size=1)
    return stats


def drive(n, seed, log):
    """Play the steps of one run against the fleet already launched; returns what the probe
    saw (contacts, the route's window); the measures come from the record afterwards (`timings`)."""
    import rospy
    from std_msgs.msg import String
    from std_srvs.srv import Empty

    from mbot_follower.fleet_probe import FleetProbe

    robots = ["robot_%d" % i for i in range(n)]
    mpc_stats = listen_mpc_stats(robots)
    probe = FleetProbe(robots, pace=True)
    probe.wait_for_fleet(wall_timeout=300.0)
    result = {"n": n, "seed": seed, "succeeded": False}
    first = formation_for(n)

    def arrive(x, y, theta, what):
        probe.send_target(x, y, theta)
        probe.wait(lambda: probe.state() in ("FORMING", "NAVIGATING"), 20.0, "%s to be taken" % what)
        probe.wait(lambda: probe.state() in ("ARRIVED", "ABORTED"), 300.0, what)
        if probe.state() != "ARRIVED":
            raise RuntimeError("%s: %s (%s)" % (what, probe.state(), probe.status.reason))

    # 1-2: converge from the random starts, then straight east
    probe.send_target(4.0, -10.0, 0.0)
    probe.wait(lambda: probe.state() == "NAVIGATING", 120.0, "the end of FORMING")
    probe.wait(lambda: probe.truth["robot_0"][1].x > -2.0, 300.0, "the leader at x = -2")
    log("n=%d seed=%d: formed, the leader at x = -2" % (n, seed))
    # 3: switch to a column on the move
    t_switch = rospy.get_time()
    probe.formation_pub.publish(String("column"))
    probe.wait(lambda: probe.assignment is not None and probe.assignment.formation == "column", 10.0, "column")
    probe.wait_switch_done("column", t_switch, 60.0)
    probe.wait(lambda: probe.state() in ("ARRIVED", "ABORTED"), 300.0, "the straight run")
    if probe.state() != "ARRIVED":
        raise RuntimeError("the straight run: %s (%s)" % (probe.state(), probe.status.reason))
    # 4: the first formation again, then the route with two turns
    t_switch = rospy.get_time()
    probe.formation_pub.publish(String(first))
    probe.wait(lambda: probe.assignment.formation == first, 10.0, first)
    probe.wait_switch_done(first, t_switch, 60.0)
    t_route = rospy.get_time()
    arrive(4.0, 4.0, math.pi / 2, "the route's first leg")
    arrive(-10.0, 4.0, math.pi, "the route's second leg")
    result["route"] = (t_route, rospy.get_time())
    # 5: a follower's controller is killed on the way south
    probe.send_target(-10.0, -6.0, -math.pi / 2)
    probe.wait(lambda: probe.state() == "NAVIGATING" and probe.truth["robot_0"][1].y < 2.0, 120.0, "the last leg")
    victim = sorted(s.robot for s in probe.assignment.slots if s.robot != probe.assignment.leader)[-1]
    # paused: on a loaded machine `rosnode kill` takes wall seconds, and the fleet must not reach
    # its target meanwhile (a slot beside the dead robot stays blocked where the leader stops)
    rospy.ServiceProxy("/pause_physics", Empty)()
    try:
        subprocess.check_call(["rosnode", "kill", "/%s/follower_controller" % victim],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    finally:
        rospy.ServiceProxy("/unpause_physics", Empty)()
    # the loss shows in `lost` (the state may read ARRIVED if the leader got there meanwhile)
    probe.wait(lambda: victim in probe.status.lost and victim not in
               [s.robot for s in probe.assignment.slots], 30.0, "DEGRADED")
    result["victim"] = victim
    held = []

    def reconverged():
        poses = {r: v[1] for r, v in probe.truth.items() if r != victim}
        errors = list(probe.slot_errors(poses, probe.assignment).values())
        ok = bool(errors) and math.sqrt(sum(e * e for e in errors) / len(errors)) < 0.15
        now = rospy.get_time()
        if not ok:
            del held[:]
        elif not held:
            held.append(now)
        return ok and now - held[0] >= 1.0

    probe.wait(reconverged, 60.0, "re-converged")
    probe.wait(lambda: probe.state() in ("ARRIVED", "ABORTED"), 300.0, "the last leg")
    result["contacts"] = len(probe.contacts)
    result["succeeded"] = probe.state() == "ARRIVED"
    wait_for_record(rospy.get_time(), 120.0, log)
    result.update(mpc_figures(dict(mpc_stats)))
    return result


def drive_office(n, seed, log):
    """The office route on the fleet already launched (module docstring); returns what the probe
    saw (contacts, the route's window)."""
    import rospy
    from std_msgs.msg import String

    from mbot_follower.fleet_probe import FleetProbe

    mpc_stats = listen_mpc_stats(["robot_%d" % i for i in range(n)])
    probe = FleetProbe(["robot_%d" % i for i in range(n)], pace=True)
    probe.wait_for_fleet(wall_timeout=300.0)
    result = {"n": n, "seed": seed, "succeeded": False}

    def arrive(x, y, theta, what):
        probe.send_target(x, y, theta)
        probe.wait(lambda: probe.state() in ("FORMING", "NAVIGATING"), 20.0, "%s to be taken" % what)
        probe.wait(lambda: probe.state() in ("ARRIVED", "ABORTED"), 400.0, what)
        if probe.state() != "ARRIVED":
            raise RuntimeError("%s: %s (%s)" % (what, probe.state(), probe.status.reason))

    def switch(formation):
        t_switch = rospy.get_time()
        probe.formation_pub.publish(String(formation))
        probe.wait(lambda: probe.assignment is not None and probe.assignment.formation == formation, 10.0, formation)
        probe.wait_switch_done(formation, t_switch, 60.0)

    t_route = rospy.get_time()
    arrive(5.0, -3.5, math.pi / 2, "the south-east room's door")
    switch("column")
    arrive(7.7, 3.5, math.pi / 2, "the north-east room, through the doors and the corridor")
    result["route"] = (t_route, rospy.get_time())
    result["route_s"] = round(result["route"][1] - result["route"][0], 2)
    log("n=%d seed=%d: office route in %.1f s sim" % (n, seed, result["route_s"]))
    switch("triangle")
    result["contacts"] = len(probe.contacts)
    result["succeeded"] = probe.state() == "ARRIVED"
    wait_for_record(rospy.get_time(), 120.0, log)
    result.update(mpc_figures(dict(mpc_stats)))
    return result


def wait_for_record(until, wall_timeout, log):
    """Wait (wall time) until the metrics collector's record reaches sim time `until`. On a busy
    machine it lags behind the fleet (the simulator's lockstep waits for its heartbeat at most 2 s
    of wall time), and stopping the fleet at once cut the record short: 10-robot seed 1 at load 80
    lost the 33 s of sim time after its loss, and with them the recovery."""
    import rospy
    from std_msgs.msg import Header

    newest = [None]

    def on_heartbeat(msg):
        if msg.frame_id.lstrip("/") == "metrics_collector":
            newest[0] = msg.stamp.to_sec()

    sub = rospy.Subscriber("/lockstep/heartbeat", Header, on_heartbeat, queue_size=50)
    end = time.time() + wall_timeout
    try:
        while time.time() < end and not rospy.is_shutdown():
            if newest[0] is not None and newest[0] >= until:
                return True
            time.sleep(0.1)
    finally:
        sub.unregister()
    log("the metrics record reached sim time %s of %.2f s within %.0f s wall" % (newest[0], until, wall_timeout))
    return False


def run_one(n, seed, out_dir, log, office=False, law=LAWS[0]):
    """Launch the fleet for (n, seed) with the followers' control law `law` on a private master,
    drive it (office: the office route), stop it. Returns measures."""
    from mbot_common.paths import find_maps_directory
    from mbot_common.net import free_port
    from mbot_navigation.nav_trial import stop, wait_for_sim_time

    suffix = "" if law == LAWS[0] else "_" + law
    run_dir = os.path.join(out_dir, "%sn%d_seed%d%s" % ("office_" if office else "", n, seed, suffix))
    shutil.rmtree(run_dir, ignore_errors=True)
    os.makedirs(run_dir)
    world = os.path.join(run_dir, "world.yaml")
    with open(world, "w") as f:
        if office:
            f.write(office_world_yaml(seed, find_maps_directory()))
        else:
            f.write(world_yaml(start_poses(n, seed), os.path.join(find_maps_directory(), MAP)))
    port = free_port()
    os.environ["ROS_MASTER_URI"] = "http://localhost:%d" % port
    os.environ.pop("ROS_IP", None)
    launch_log = os.path.join(run_dir, "roslaunch.log")
    cmd = ["roslaunch", "-p", str(port), "mbot_follower", "formation.launch", "world:=" + world,
           "formation:=" + formation_for(n), "spacing:=%g" % (OFFICE_SPACING if office else SPACING),
           "real_time_factor:=0", "lockstep:=true", "controller:=" + law,
           "metrics_dir:=" + os.path.join(run_dir, "metrics")]
    with open(launch_log, "w") as f:
        process = subprocess.Popen(cmd, stdout=f, stderr=subprocess.STDOUT, start_new_session=True)
    result = {"n": n, "seed": seed, "succeeded": False, "law": law}
    try:
        import rospy

        wait_for_sim_time("formation_bench", launch_log, wall_timeout=120.0)
        rospy.init_node("formation_bench", disable_signals=True)
        started = time.time()
        result = dict((drive_office if office else drive)(n, seed, log), law=law)
        result["wall_s"] = round(time.time() - started, 1)
    except Exception as error:  # a failed run is a row of the table, not a crash of the benchmark
        result["error"] = str(error).splitlines()[0]
        log("n=%d seed=%d FAILED: %s" % (n, seed, str(error)))
    finally:
        stop(process, log)
    metrics = os.path.join(run_dir, "metrics", "metrics.json")
    if os.path.exists(metrics):
        from mbot_follower.metrics import RunFileError, load_run

        with open(metrics) as f:
            fleet = json.load(f)["fleet"]
        result["cycle_p99_ms"] = fleet.get("cycle_time_p99_ms")
        result["overruns"] = fleet.get("cycle_overruns")
        result["late_starts"] = fleet.get("cycle_late_starts")
        result["contacts"] = max(result.get("contacts", 0), fleet.get("contacts") or 0)
        result["min_clearance_m"] = fleet.get("min_clearance_m")
        try:
            if office:
                record = load_run(os.path.dirname(metrics))
                result.update(office_timings(record, result["route"]) if "route" in result else {})
            else:
                result.update(timings(load_run(os.path.dirname(metrics)), result.get("route")))
        except RunFileError as error:
            result["error"] = "the metrics record: %s" % error
            result["succeeded"] = False
        needed = ("converge_s", "switch_s", "rms_route_m") if office else \
            ("converge_s", "switch_s", "degraded_s", "recover_s", "rms_straight_m", "rms_route_m")
        missing = [k for k in needed if result.get(k) is None]
        if result.get("succeeded") and missing:
            result["error"] = "the metrics record lacks %s" % ", ".join(missing)
            result["succeeded"] = False
    elif result.get("succeeded"):
        result["error"] = "no metrics record in %s" % os.path.dirname(metrics)
        result["succeeded"] = False
    return result


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="formation_bench", description=__doc__.split("\n\n")[0])
    parser.add_argument("--sizes", default=",".join(map(str, SIZES)), help="fleet sizes (default %(default)s)")
    parser.add_argument("--seeds", type=int, default=10, help="seeds per size (default %(default)s)")
    parser.add_argument("--first-seed", type=int, default=1)
    parser.add_argument("--out", default=os.path.join(tempfile.gettempdir(), "formation_bench"),
                        help="run folders (world, launch log, metrics)")
    parser.add_argument("--laws", default=",".join(LAWS),
                        help="the followers' control laws, each a row (default %(default)s; e.g. slot_tracking,mpc)")
    parser.add_argument("--json", action="store_true", help="print the table as one JSON line")
    parser.add_argument("--one", nargs=2, type=int, metavar=("N", "SEED"), help=argparse.SUPPRESS)
    parser.add_argument("--office", action="store_true", help=argparse.SUPPRESS)   # --one: the office route
    return parser.parse_args(argv)


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)

    def log(message):
        print("formation_bench: " + message, file=sys.stderr)
        sys.stderr.flush()

    from mbot_follower.control_laws import CONTROL_LAWS

    laws = [law for law in args.laws.split(",") if law]
    unknown = [law for law in laws if law not in CONTROL_LAWS]
    if unknown or not laws:
        sys.exit("formation_bench: --laws: %s: expected control laws of %s" % (
            ", ".join(unknown) or "none given", ", ".join(sorted(CONTROL_LAWS))))
    if args.one:  # child: one run, its measures as the last line of stdout
        print(json.dumps(run_one(args.one[0], args.one[1], args.out, log, office=args.office, law=laws[0])))
        return 0

    def row(n, office, law):
        runs = []
        for seed in range(args.first_seed, args.first_seed + args.seeds):
            out = subprocess.run([sys.executable, "-m", "mbot_follower.formation_bench", "--one", str(n), str(seed),
                                  "--out", args.out, "--laws", law] + (["--office"] if office else []),
                                 stdout=subprocess.PIPE, universal_newlines=True)
            lines = [line for line in out.stdout.splitlines() if line.startswith("{")]
            run = json.loads(lines[-1]) if lines else {
                "n": n, "seed": seed, "succeeded": False, "error": "the run printed nothing (exit %d)" % out.returncode}
            log("%sn=%d seed=%d %s: %s" % ("office " if office else "", n, seed, law, json.dumps(run)))
            runs.append(run)
        out = worst(runs)
        out["details"] = runs
        return out

    sizes = [int(s) for s in args.sizes.split(",")]
    table, office = {}, {}
    for law in laws:   # slot tracking's rows keep their keys ("3"); another law's: "3 mpc"
        name = "" if law == LAWS[0] else " " + law
        table.update({str(n) + name: row(n, False, law) for n in sizes})
        # the office route: its own row, for the sizes the office world holds
        office.update({str(n) + name: row(n, True, law) for n in sizes if n in OFFICE_SIZES})
    result = {"formation": table, "formation_office": office}
    if args.json:
        print(json.dumps(result))
    else:
        print(json.dumps(result, indent=1))
    return 0


if __name__ == "__main__":
    sys.exit(main())
