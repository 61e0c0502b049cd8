"""Run the project's benchmarks and report them as a table and JSON.

    scripts/bench sim [--json FILE]   simulator real-time factor for N robots (median of
                                      --sim-runs runs, default 3; stepping alone and the whole
                                      run with loading and placing), ray casting rate; the 3D
                                      lidar: points per second of its caster (raycast_bench) and
                                      the real-time factor with 1 and 4 lidar robots (sim_bench
                                      --lidar; rtf_cpu by the process's CPU time)
    scripts/bench nav [--json FILE]   global plan time, length and cost (the shipped settings,
                                      one plan per pair; fastest of 5 beside it), DWA cycle time
                                      (defaults and the shipped nav_dwa.yaml), and the seeded
                                      random-goal navigation trial in `office`
        --trial-runs N (default 100; 0 skips it), --trial-rtf X (default 0: as fast as possible);
                                      and the fleet trial: 3 robots at once in `office` with its
                                      walking person, particle filter, goals split among them
        --fleet-runs N (default 100 in all; 0 skips it)
    scripts/bench formation [--json FILE] [--seeds N] [--sizes 3,5,10] [--laws slot_tracking,mpc]
                                      the formation fleet at real_time_factor 0 with lockstep:
                                      convergence, straight and route slot error, switch time,
                                      recovery after a loss, contacts, controller cycle time;
                                      for 3 robots also the office route (doors, corridor) as
                                      the row "3 office" (mbot_follower/formation_bench.py);
                                      --laws: a row per control law ("3 mpc"), with the slot
                                      error p95, the least clearance and the mpc solve time
    scripts/bench fleet [--json FILE] [--sizes 3,10,20,40] [--modes formation,navigation]
                                      what the fleet around the simulator costs: real-time
                                      factor, CPU s per robot per sim s and each process kind's
                                      share, for a triangle driving 6 m in `field` and for the
                                      same robots with a move_base goal each
                                      (mbot_bringup/fleet_bench.py)
    scripts/bench mapf [--json FILE] [--maps empty-32-32,...] [--time-limit S] [--max-agents K]
                      [--algorithm auto|pp|lacam|ecbs|eecbs] [--w W] [--agents 50,100]
                                      multi-agent path finding on the MovingAI instances
                                      (mbot_coordination/bench/mapf), the EECBS protocol: each map,
                                      scenarios 1..5, k = 10, 20, 30, ... agents until fewer than
                                      half of the five are solved, 60 s per instance by default;
                                      success, runtime p50 and sum of costs over the lower bound
                                      (ecbs: also over its proven bound; --agents: only these k)
    scripts/bench all [--json FILE]   sim and nav (the formation and fleet benchmarks take long: run them alone)

Each benchmark is a C++ program built with the workspace (Release); it prints one JSON object.
Every program runs pinned to one core (taskset) so figures compare with single-threaded peers.
"""
import argparse
import json
import os
import platform
import shutil
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
# The planner benchmark's inputs (shared with the peers we compare with; see its README).
PLANNER_INPUTS = os.path.join(ROOT, "src", "mbot_navigation", "bench", "inputs")
NAV_CONFIG = os.path.join(ROOT, "src", "mbot_navigation", "config")  # the shipped settings
DESCRIPTION = os.path.join(ROOT, "src", "mbot_description")

# The MAPF benchmark's inputs (MovingAI maps and scenarios; see its README).
MAPF_INPUTS = os.path.join(ROOT, "src", "mbot_coordination", "bench", "mapf")
MAPF_MAPS = ["empty-32-32", "random-32-32-10", "room-32-32-4", "maze-32-32-2", "warehouse-10-20-10-2-1"]

# Simulator benchmark plan: robots -> (map, sim seconds). The 1000-robot run uses the same room
# tiled 3x3 (60x60 m). Sim seconds are chosen so that each run takes tens of wall seconds.
SIM_RUNS = [
    (1, "bench_room.yaml", 120.0),
    (10, "bench_room.yaml", 60.0),
    (100, "bench_room.yaml", 20.0),
    (1000, "bench_room_3x3.yaml", 10.0),
]


def program(package, name):
    path = os.path.join(ROOT, "devel", "lib", package, name)
    if not os.access(path, os.X_OK):
        sys.exit("benchmark program %s is not built (looked for %s); run scripts/setup" % (name, path))
    return path


def run_json(cmd):
    """Run a benchmark program on one core and return the JSON object it prints last."""
    full = ["taskset", "-c", "0"] + cmd if shutil.which("taskset") else cmd
    print("$ " + " ".join(cmd), file=sys.stderr)
    out = subprocess.run(full, check=True, stdout=subprocess.PIPE, universal_newlines=True).stdout
    lines = [line for line in out.strip().splitlines() if line.startswith("{")]
    if not lines:
        sys.exit("%s printed no JSON:\n%s" % (cmd[0], out))
    return json.loads(lines[-1])


def machine():
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(line.split(":", 1)[1].strip() for line in f if line.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return "%s, %d cores, %s" % (cpu or platform.processor(), os.cpu_count(), platform.platform())


def median(values):
    v = sorted(values)
    n = len(v)
    return v[n // 2] if n % 2 else 0.5 * (v[n // 2 - 1] + v[n // 2])


def spread(values):
    """Median and range of several runs' figures."""
    return {"median": round(median(values), 3), "min": round(min(values), 3), "max": round(max(values), 3),
            "runs": len(values)}


# 3D lidar runs: robots, each with the default lidar (20000 points at 10 Hz), in bench_room.
SIM_LIDAR_RUNS = [(1, 60.0), (4, 20.0)]


def bench_sim_lidar(raycast, runs):
    """The 3D lidar's figures: raycast_bench's caster alone, sim_bench's whole simulation."""
    out = {"points_per_second": raycast["lidar"]["points_per_second"],
           "cpu_points_per_second": raycast["lidar"]["cpu_points_per_second"], "rtf": {}, "rtf_cpu": {},
           "rays_per_cpu_second": {}}
    for robots, seconds in SIM_LIDAR_RUNS:
        results = [run_json([program("mbot_sim", "sim_bench"), "--robots", str(robots), "--lidar", str(robots),
                             "--map", os.path.join(ROOT, "maps", "bench_room.yaml"), "--seconds", str(seconds)])
                   for _ in range(runs)]
        out["rtf"][str(robots)] = round(median([r["rtf"] for r in results]), 2)
        out["rtf_cpu"][str(robots)] = round(median([r["rtf_cpu"] for r in results]), 2)
        out["rays_per_cpu_second"][str(robots)] = round(median([r["lidar_rays_per_cpu_second"] for r in results]))
    return out


def bench_sim(runs=3):
    rays = run_json([program("mbot_sim", "raycast_bench")])
    rtf = {}
    with_loading = {}
    details = {}
    all_runs = {}
    for robots, map_name, seconds in SIM_RUNS:
        results = [run_json([program("mbot_sim", "sim_bench"), "--robots", str(robots),
                             "--map", os.path.join(ROOT, "maps", map_name), "--seconds", str(seconds)])
                   for _ in range(runs)]
        rtf[str(robots)] = round(median([r["rtf"] for r in results]), 3)
        with_loading[str(robots)] = spread([r["rtf_with_loading"] for r in results])
        details[str(robots)] = sorted(results, key=lambda r: r["rtf"])[len(results) // 2]  # the median run
        all_runs[str(robots)] = results
    # rtf: the stepping alone (median run); rtf_with_loading: whole runs, loading and placing included.
    return {"rtf": rtf, "rtf_with_loading": with_loading, "rays_per_second": rays["rays_per_second"],
            "lidar": bench_sim_lidar(rays, runs),
            "sim_runs": details, "sim_runs_all": all_runs}


def run_nav_trial(options):
    """mbot_navigation's nav_trial with `options` (a list); the JSON object it prints."""
    script = os.path.join(ROOT, "src", "mbot_navigation", "scripts", "nav_trial")
    print("$ nav_trial " + " ".join(options), file=sys.stderr)
    out = subprocess.run(["/usr/bin/python3", script] + options + ["--json"],
                         check=True, stdout=subprocess.PIPE, universal_newlines=True).stdout
    return json.loads([line for line in out.splitlines() if line.startswith("{")][-1])


def nav_trial(runs, rtf):
    """Seeded random-goal trial: one robot in `office`, each run one goal with a timeout.

    It runs the whole ROS stack (simulator, map server, localization, nav node), so it cannot be
    pinned to one core. nav_trial turns on the simulator's lockstep: at real_time_factor 0 (the
    default, the issue's condition) sim time runs as fast as the nav node and the localization can
    follow, never ahead of them.
    """
    result = run_nav_trial(["--runs", str(runs), "--seed", "1", "--real-time-factor", str(rtf)])
    result["real_time_factor"] = rtf
    return result


def nav_trial_fleet(runs, rtf):
    """The harder trial: the 3 robots of maps/office.world.yaml at once, with its walking person,
    particle-filter localization, `runs` goals split among them (nav_trial --robots 3)."""
    result = run_nav_trial(["--robots", "3", "--world", os.path.join(ROOT, "maps", "office.world.yaml"),
                            "--localization", "pf", "--runs", str(runs), "--seed", "1",
                            "--real-time-factor", str(rtf), "--launch-log", "/tmp/nav_trial_fleet_roslaunch.log"])
    return {k: result[k] for k in ("robots", "runs", "succeeded", "contacts", "mean_goal_s")}


def bench_nav(trial_runs=100, trial_rtf=0.0, fleet_runs=100):
    # The planner as the nav node runs it: nav_move_base.yaml's GlobalPlanner settings.
    plan = {}
    single = {}
    for n in ("1000", "2000"):
        r = run_json([program("mbot_navigation", "plan_bench"),
                      "--map", os.path.join(PLANNER_INPUTS, "map_%s.pgm" % n),
                      "--pairs", os.path.join(PLANNER_INPUTS, "pairs_%s.csv" % n),
                      "--config", os.path.join(NAV_CONFIG, "nav_move_base.yaml"), "--json"])
        # plan_ms: the fastest of 5 plans per pair (as before); plan_ms_single: one plan per pair
        # after one warm-up, the peers' protocol (the headline).
        plan[n] = {k: r[k] for k in ("p50", "p95", "mean_path_cells", "mean_path_cost", "failures")}
        single[n] = {"p50": r["single_p50"], "p95": r["single_p95"], "mean_path_cells": r["mean_path_cells"],
                     "mean_path_cost": r["mean_path_cost"], "cpu_p50": r["single_cpu_p50"],
                     "cpu_p95": r["single_cpu_p95"]}
    dwa = run_json([program("mbot_navigation", "dwa_bench")])
    shipped = run_json([program("mbot_navigation", "dwa_bench"), "--config", os.path.join(NAV_CONFIG, "nav_dwa.yaml"),
                        "--description", DESCRIPTION])
    result = {"plan_ms": plan, "plan_ms_single": single, "dwa_ms": {"p50": dwa["p50"], "p99": dwa["p99"]},
              "dwa_ms_shipped": {"p50": shipped["p50"], "p99": shipped["p99"], "wall_p99": shipped["wall_p99"]}}
    if trial_runs > 0:
        result["trial"] = nav_trial(trial_runs, trial_rtf)
    if fleet_runs > 0:
        result["trial_fleet"] = nav_trial_fleet(fleet_runs, trial_rtf)
    return result


def bench_formation(seeds, sizes, laws="slot_tracking"):
    """The whole formation stack (many processes, so not pinned to one core); worst of the seeds.
    laws: the followers' control laws, each its own rows."""
    print("$ formation_bench --seeds %d --sizes %s --laws %s --json" % (seeds, sizes, laws), file=sys.stderr)
    out = subprocess.run(["/usr/bin/python3", "-m", "mbot_follower.formation_bench", "--seeds", str(seeds),
                          "--sizes", sizes, "--laws", laws, "--json"], check=True, stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    return json.loads([line for line in out.splitlines() if line.startswith("{")][-1])


def bench_fleet(sizes, modes):
    """The whole fleet, many processes (not pinned); one run per size and mode."""
    from mbot_bringup import fleet_bench

    return fleet_bench.bench_fleet([int(n) for n in sizes.split(",")], os.path.join(ROOT, "out", "bench_fleet"),
                                   modes.split(","))


def run_mapf(map_name, scen, agents, time_limit, algorithm, w):
    """One mapf_bench instance on one core; its JSON (success false is a result, not an error)."""
    cmd = [program("mbot_coordination", "mapf_bench"), "--map", os.path.join(MAPF_INPUTS, map_name + ".map"),
           "--scen", os.path.join(MAPF_INPUTS, "%s-random-%d.scen" % (map_name, scen)), "--agents", str(agents),
           "--time-limit", str(time_limit), "--algorithm", algorithm, "--w", str(w), "--json", "-"]
    full = ["taskset", "-c", "0"] + cmd if shutil.which("taskset") else cmd
    out = subprocess.run(full, stdout=subprocess.PIPE, universal_newlines=True)
    if out.returncode not in (0, 1):  # 2: bad input, 3: an invalid solution (a planner bug)
        sys.exit("mapf_bench failed (exit %d): %s" % (out.returncode, " ".join(cmd)))
    return json.loads([line for line in out.stdout.splitlines() if line.startswith("{")][-1])


def bench_mapf(maps, time_limit, max_agents, algorithm, w=1.05, agents=None):
    """The EECBS protocol: per map, k = 10, 20, ... on scenarios 1..5 until fewer than half are solved
    (agents: exactly these k instead). runtime_p50_s counts an unsolved run as the time limit; soc_ratio
    is the mean over solved runs of sum of costs / lower bound (each agent's own 4-connected shortest
    path); proven_ratio (ecbs) the same over the planner's proven lower bound, a certificate (<= w)."""
    table = {}
    runs = {}
    for map_name in maps:
        table[map_name] = {}
        ks = list(agents) if agents else None
        k = ks.pop(0) if ks else 10
        while max_agents is None or k <= max_agents:
            results = []
            for scen in range(1, 6):
                r = run_mapf(map_name, scen, k, time_limit, algorithm, w)
                print("  %s k=%d scen %d: %s %.3f s" % (map_name, k, scen, "solved" if r["success"] else "failed",
                                                        r["runtime_s"]), file=sys.stderr)
                results.append(r)
            solved = [r for r in results if r["success"]]
            times = [r["runtime_s"] if r["success"] else time_limit for r in results]
            row = {"solved": len(solved), "runs": len(results), "runtime_p50_s": round(median(times), 4)}
            if solved:
                row["soc_ratio"] = round(sum(r["sum_of_costs"] / r["lower_bound"] for r in solved) / len(solved), 4)
                row["soc_ratio_max"] = round(max(r["sum_of_costs"] / r["lower_bound"] for r in solved), 4)
                row["first_solution_p50_s"] = round(median([r["first_solution_s"] for r in solved]), 4)
                row["first_soc_ratio"] = round(sum(r["first_sum_of_costs"] / r["lower_bound"] for r in solved)
                                               / len(solved), 4)
                proven = [r for r in solved if r.get("proven_lower_bound")]
                if proven:
                    row["proven_ratio"] = round(sum(r["sum_of_costs"] / r["proven_lower_bound"] for r in proven)
                                                / len(proven), 4)
                    row["proven_ratio_max"] = round(max(r["sum_of_costs"] / r["proven_lower_bound"] for r in proven), 4)
            table[map_name][str(k)] = row
            runs["%s/%d" % (map_name, k)] = results
            if agents:
                if not ks:
                    break
                k = ks.pop(0)
                continue
            if 2 * len(solved) < len(results):
                break
            k += 10
    return {"mapf": table, "mapf_settings": {"time_limit_s": time_limit, "algorithm": algorithm, "w": w,
                                             "agents": agents, "max_agents": max_agents}, "mapf_runs": runs}


def formation_table(result):
    """The formation benchmark's main table (text): a row per fleet size (and "3 office"), the
    worst over the seeds; beside the cycle time p99 the cycles over the 50 ms period (overruns)
    and those started a period or more late, summed over the seeds ("-": not in the result)."""
    lines = ["\nFormation (worst over seeds; targets: straight <= 0.05 m, route <= 0.15 m, converge <= 10 s,"
             " switch <= 6 s, DEGRADED <= 2 s, re-converged <= 10 s, 0 contacts)",
             "  %-8s %9s %9s %11s %10s %11s %8s %10s %10s %9s %9s %11s %10s" % (
                 "robots", "succeeded", "contacts", "straight m", "route m", "converge s", "switch s",
                 "degraded s", "recover s", "cycle p99", "overruns", "late starts", "wall s")]
    rows = [(n, r) for n, r in result["formation"].items()]
    rows += [("%s office" % n, r) for n, r in result.get("formation_office", {}).items()]   # the office route
    for n, r in rows:
        wall = max((d.get("wall_s") or 0) for d in r.get("details", [{}]))

        def f(key, fmt):
            return fmt % r[key] if r.get(key) is not None else "-"
        lines.append("  %-8s %9s %9d %11s %10s %11s %8s %10s %10s %9s %9s %11s %10.0f" % (
            n, "%d/%d" % (r["succeeded"], r["runs"]), r["contacts"], f("rms_straight_m", "%.3f"),
            f("rms_route_m", "%.3f"), f("converge_s", "%.1f"), f("switch_s", "%.1f"), f("degraded_s", "%.1f"),
            f("recover_s", "%.1f"), f("cycle_p99_ms", "%.1f ms"), f("overruns", "%d"), f("late_starts", "%d"),
            wall))
    return "\n".join(lines)


def print_table(result):
    if "rtf" in result:
        print("\nSimulator (one core, as fast as possible, 360-beam 10 Hz lasers, 100 Hz physics)")
        print("  %-8s %12s %28s" % ("robots", "stepping x", "whole run x (median, range)"))
        for n, x in result["rtf"].items():
            w = result["rtf_with_loading"][n]
            print("  %-8s %12.2f %12.2f (%.2f-%.2f)" % (n, x, w["median"], w["min"], w["max"]))
        print("  ray casting: %.1f million rays/s" % (result["rays_per_second"] / 1e6))
        lidar = result.get("lidar")
        if lidar:
            print("  3D lidar caster: %.1f million points/s (%.1f per CPU s)" % (
                lidar["points_per_second"] / 1e6, lidar["cpu_points_per_second"] / 1e6))
            for n in lidar["rtf"]:
                print("  %s lidar robots (20000 points at 10 Hz each): %.1fx real time (%.1fx by CPU time)" % (
                    n, lidar["rtf"][n], lidar["rtf_cpu"][n]))
    if "plan_ms" in result:
        print("\nGlobal planner (A*, nav_move_base.yaml's settings, the benchmark inputs, planning only, one thread)")
        print("  %-8s %20s %20s %12s %10s %9s" % ("grid", "one plan p50/p95 ms", "fastest of 5 ms", "mean cells",
                                                  "mean cost", "failures"))
        for n, r in result["plan_ms"].items():
            s = result["plan_ms_single"][n]
            print("  %-8s %20s %20s %12.1f %10.1f %9d" % (
                n + "^2", "%.2f / %.2f" % (s["p50"], s["p95"]), "%.2f / %.2f" % (r["p50"], r["p95"]),
                r["mean_path_cells"], r["mean_path_cost"], r["failures"]))
        d, sh = result["dwa_ms"], result["dwa_ms_shipped"]
        print("\nDWA cycle (thread CPU time): defaults p50 %.2f ms, p99 %.2f ms; nav_dwa.yaml p50 %.2f ms, p99 %.2f ms"
              " (wall p99 %.2f ms)" % (d["p50"], d["p99"], sh["p50"], sh["p99"], sh["wall_p99"]))
    if "fleet_scale" in result or "fleet_scale_navigation" in result:
        from mbot_bringup import fleet_bench

        print(fleet_bench.table(result))
    if "formation" in result:
        print(formation_table(result))
        rows = [(n, r) for n, r in result["formation"].items()]
        rows += [("%s office" % n, r) for n, r in result.get("formation_office", {}).items()]   # the office route
        # the law comparison (issue 26): p95 slot error of the switch (office: of the route), the
        # closest two robots (centres - 2 radii; target >= 0.05 m), the mpc solve time
        print("\n  %-12s %16s %14s %15s %15s %16s" % ("robots", "slot p95 m", "clearance m", "mpc solve p50",
                                                      "mpc solve p99", "mpc fallbacks"))
        for n, r in rows:
            def g(key, fmt):
                return fmt % r[key] if r.get(key) is not None else "-"
            fallbacks = "%d/%d" % (r["mpc_fallbacks"], r["mpc_solves"]) if "mpc_solves" in r else "-"
            print("  %-12s %16s %14s %15s %15s %16s" % (
                n, g("slot_p95_switch_m", "%.3f"), g("min_clearance_m", "%.3f"), g("mpc_solve_p50_ms", "%.1f ms"),
                g("mpc_solve_p99_ms", "%.1f ms"), fallbacks))
    if "mapf" in result:
        st = result["mapf_settings"]
        name = st["algorithm"] + (" w=%g" % st["w"] if st["algorithm"] in ("ecbs", "eecbs") else "")
        print("\nMAPF (MovingAI instances, scenarios 1-5, %s, %g s limit; ratio = sum of costs / sum of the"
              " agents' own 4-connected shortest paths, mean over solved runs; proven = sum of costs / the"
              " planner's proven lower bound, mean and max)" % (name, st["time_limit_s"]))
        print("  %-24s %6s %8s %12s %14s %10s %10s %14s" % (
            "map", "agents", "solved", "runtime p50", "first sol. p50", "ratio", "first", "proven"))

        def g(row, key, fmt):
            return fmt % row[key] if key in row else "-"
        for map_name, rows in result["mapf"].items():
            for k, r in rows.items():
                proven = ("%.3f / %.3f" % (r["proven_ratio"], r["proven_ratio_max"])) if "proven_ratio" in r else "-"
                print("  %-24s %6s %8s %12s %14s %10s %10s %14s" % (
                    map_name, k, "%d/%d" % (r["solved"], r["runs"]), "%.3f s" % r["runtime_p50_s"],
                    g(r, "first_solution_p50_s", "%.3f s"), g(r, "soc_ratio", "%.3f"), g(r, "first_soc_ratio", "%.3f"),
                    proven))
    if "trial" in result:
        t = result["trial"]
        print("\nNavigation trial (office, real_time_factor %g): %d of %d goals reached, %d contacts, "
              "%.0f sim s in %.0f wall s" % (t["real_time_factor"], t["succeeded"], t["runs"], t["contacts"],
                                             t["sim_seconds"], t["wall_seconds"]))
    if "trial_fleet" in result:
        t = result["trial_fleet"]
        print("Fleet trial (office with its walking person, %d robots at once, particle filter): %d of %d goals"
              " reached, %d contacts, %s sim s per goal reached" % (t["robots"], t["succeeded"], t["runs"],
                                                                    t["contacts"], t["mean_goal_s"]))


def main(argv=None):
    parser = argparse.ArgumentParser(prog="scripts/bench", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["sim", "nav", "formation", "fleet", "mapf", "all"])
    parser.add_argument("--json", metavar="FILE", help="write the figures as JSON")
    parser.add_argument("--trial-runs", type=int, default=100, help="navigation trial runs (0: skip)")
    parser.add_argument("--trial-rtf", type=float, default=0.0,
                        help="real-time factor of the trial (default 0: as fast as possible, lockstep)")
    parser.add_argument("--fleet-runs", type=int, default=100,
                        help="goals of the fleet trial (3 robots, person, particle filter; 0: skip)")
    parser.add_argument("--sim-runs", type=int, default=3, help="sim: runs per fleet size (median and range)")
    parser.add_argument("--seeds", type=int, default=10, help="formation: seeds per fleet size")
    parser.add_argument("--sizes", help="formation: fleet sizes (default 3,5,10); fleet: (default 3,10,20,40)")
    parser.add_argument("--laws", default="slot_tracking",
                        help="formation: the followers' control laws, e.g. slot_tracking,mpc (default slot_tracking)")
    parser.add_argument("--modes", default="formation,navigation", help="fleet: formation, navigation or both")
    parser.add_argument("--maps", default=",".join(MAPF_MAPS), help="mapf: map names (default: all five)")
    parser.add_argument("--time-limit", type=float, default=60.0, help="mapf: seconds per instance (default 60)")
    parser.add_argument("--max-agents", type=int, help="mapf: stop each map at this many agents")
    parser.add_argument("--algorithm", default="auto", help="mapf: auto, pp, lacam, ecbs or eecbs (default auto)")
    parser.add_argument("--w", type=float, default=1.05,
                        help="mapf: ecbs's and eecbs's suboptimality bound (default 1.05)")
    parser.add_argument("--agents", help="mapf: only these agent counts, e.g. 50,100 (default: 10, 20, ... as the"
                        " protocol says)")
    args = parser.parse_args(argv)
    if args.sim_runs < 1:
        parser.error("--sim-runs must be >= 1")
    result = {}
    if args.what in ("sim", "all"):
        result.update(bench_sim(args.sim_runs))
    if args.what in ("nav", "all"):
        result.update(bench_nav(args.trial_runs, args.trial_rtf, args.fleet_runs))
    if args.what == "formation":
        result.update(bench_formation(args.seeds, args.sizes or "3,5,10", args.laws))
    if args.what == "fleet":
        if not set(args.modes.split(",")) <= {"formation", "navigation"}:
            parser.error("--modes: formation, navigation or both (comma-separated)")
        result.update(bench_fleet(args.sizes or "3,10,20,40", args.modes))
    if args.what == "mapf":
        maps = args.maps.split(",")
        unknown = [m for m in maps if not os.path.exists(os.path.join(MAPF_INPUTS, m + ".map"))]
        if unknown:
            parser.error("--maps: no such map %s (known: %s)" % (", ".join(unknown), ", ".join(MAPF_MAPS)))
        if args.time_limit <= 0:
            parser.error("--time-limit must be > 0")
        if args.max_agents is not None and args.max_agents < 10:
            parser.error("--max-agents must be >= 10")
        if args.algorithm not in ("auto", "pp", "lacam", "ecbs", "eecbs"):
            parser.error("--algorithm: auto, pp, lacam, ecbs or eecbs")
        if not args.w >= 1.0:
            parser.error("--w must be >= 1")
        try:
            agents = [int(k) for k in args.agents.split(",")] if args.agents else None
        except ValueError:
            parser.error("--agents: comma-separated whole numbers, e.g. 50,100")
        if agents and min(agents) < 1:
            parser.error("--agents must be >= 1")
        result.update(bench_mapf(maps, args.time_limit, args.max_agents, args.algorithm, args.w, agents))
    result["machine"] = machine()
    print_table(result)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=2)
        print("\nwrote %s" % args.json)


if __name__ == "__main__":
    main()
