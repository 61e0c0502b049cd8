"""Run the project's benchmarks and report them as a table and JSON.

    scripts/bench sim [--json FILE]   simulator real-time factor for N robots, ray casting rate
    scripts/bench nav [--json FILE]   global plan time and length, DWA cycle time, and the
                                      seeded random-goal navigation trial in `office`
        --trial-runs N (default 100; 0 skips it), --trial-rtf X (default 0: as fast as possible)
    scripts/bench formation [--json FILE] [--seeds N] [--sizes 3,5,10]
                                      the formation fleet at real_time_factor 0 with lockstep:
                                      convergence, straight and route slot error, switch time,
                                      recovery after a loss, contacts, controller cycle time
                                      (mbot_follower/formation_bench.py)
    scripts/bench all [--json FILE]   sim and nav (the formation benchmark takes long: run it alone)

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
    lines = [l for l in out.strip().splitlines() if l.startswith("{")]
    if not lines:
        sys.exit("%s printed no JSON:\n%s" % (cmd[0], out))
    return json.loads(lines[-1])


def machine():
    cpu = ""
    try:
        with open("/proc/cpuinfo") as f:
            cpu = next(l.split(":", 1)[1].strip() for l in f if l.startswith("model name"))
    except (OSError, StopIteration):
        pass
    return "%s, %d cores, %s" % (cpu or platform.processor(), os.cpu_count(), platform.platform())


def bench_sim():
    rays = run_json([program("mbot_sim", "raycast_bench")])
    rtf = {}
    details = {}
    for robots, map_name, seconds in SIM_RUNS:
        r = run_json([program("mbot_sim", "sim_bench"), "--robots", str(robots),
                      "--map", os.path.join(ROOT, "maps", map_name), "--seconds", str(seconds)])
        rtf[str(robots)] = round(r["rtf"], 3)
        details[str(robots)] = r
    return {"rtf": rtf, "rays_per_second": rays["rays_per_second"], "sim_runs": details}


def nav_trial(runs, rtf):
    """Seeded random-goal trial: one robot in `office`, each run one goal with a timeout.

    It runs the whole ROS stack (simulator, map server, localization, nav node), so it cannot be
    pinned to one core. nav_trial turns on the simulator's lockstep: at real_time_factor 0 (the
    default, the issue's condition) sim time runs as fast as the nav node and the localization can
    follow, never ahead of them.
    """
    script = os.path.join(ROOT, "src", "mbot_navigation", "scripts", "nav_trial")
    print("$ nav_trial --runs %d --seed 1 --real-time-factor %g --json" % (runs, rtf), file=sys.stderr)
    out = subprocess.run(["/usr/bin/python3", script, "--runs", str(runs), "--seed", "1",
                          "--real-time-factor", str(rtf), "--json"],
                         check=True, stdout=subprocess.PIPE, universal_newlines=True).stdout
    result = json.loads([l for l in out.splitlines() if l.startswith("{")][-1])
    result["real_time_factor"] = rtf
    return result


def bench_nav(trial_runs=100, trial_rtf=0.0):
    plan = {}
    for n in ("1000", "2000"):
        r = run_json([program("mbot_navigation", "plan_bench"),
                      "--map", os.path.join(PLANNER_INPUTS, "map_%s.pgm" % n),
                      "--pairs", os.path.join(PLANNER_INPUTS, "pairs_%s.csv" % n), "--json"])
        plan[n] = {k: r[k] for k in ("p50", "p95", "mean_path_cells", "failures")}
    dwa = run_json([program("mbot_navigation", "dwa_bench")])
    result = {"plan_ms": plan, "dwa_ms": {"p50": dwa["p50"], "p99": dwa["p99"]}}
    if trial_runs > 0:
        result["trial"] = nav_trial(trial_runs, trial_rtf)
    return result


def bench_formation(seeds, sizes):
    """The whole formation stack (many processes, so not pinned to one core); worst of the seeds."""
    print("$ formation_bench --seeds %d --sizes %s --json" % (seeds, sizes), file=sys.stderr)
    out = subprocess.run(["/usr/bin/python3", "-m", "mbot_follower.formation_bench", "--seeds", str(seeds),
                          "--sizes", sizes, "--json"], check=True, stdout=subprocess.PIPE,
                         universal_newlines=True).stdout
    return json.loads([l for l in out.splitlines() if l.startswith("{")][-1])


def print_table(result):
    if "rtf" in result:
        print("\nSimulator (one core, as fast as possible, 360-beam 10 Hz lasers, 100 Hz physics)")
        print("  %-8s %12s" % ("robots", "real-time x"))
        for n, x in result["rtf"].items():
            print("  %-8s %12.2f" % (n, x))
        print("  ray casting: %.1f million rays/s" % (result["rays_per_second"] / 1e6))
    if "plan_ms" in result:
        print("\nGlobal planner (A*, the benchmark inputs, planning only, one thread)")
        print("  %-10s %8s %8s %12s %9s" % ("grid", "p50 ms", "p95 ms", "mean cells", "failures"))
        for n, r in result["plan_ms"].items():
            print("  %-10s %8.2f %8.2f %12.1f %9d" % (n + "^2", r["p50"], r["p95"],
                                                     r["mean_path_cells"], r["failures"]))
        print("\nDWA cycle: p50 %.2f ms, p99 %.2f ms" % (result["dwa_ms"]["p50"], result["dwa_ms"]["p99"]))
    if "formation" in result:
        print("\nFormation (worst over seeds; targets: straight <= 0.05 m, route <= 0.15 m, converge <= 10 s,"
              " switch <= 6 s, DEGRADED <= 2 s, re-converged <= 10 s, 0 contacts)")
        print("  %-6s %9s %9s %11s %10s %11s %8s %10s %10s %9s %10s" % (
            "robots", "succeeded", "contacts", "straight m", "route m", "converge s", "switch s",
            "degraded s", "recover s", "cycle p99", "wall s"))
        for n, r in result["formation"].items():
            wall = max((d.get("wall_s") or 0) for d in r.get("details", [{}]))

            def f(key, fmt):
                return fmt % r[key] if r.get(key) is not None else "-"
            print("  %-6s %9s %9d %11s %10s %11s %8s %10s %10s %9s %10.0f" % (
                n, "%d/%d" % (r["succeeded"], r["runs"]), r["contacts"], f("rms_straight_m", "%.3f"),
                f("rms_route_m", "%.3f"), f("converge_s", "%.1f"), f("switch_s", "%.1f"), f("degraded_s", "%.1f"),
                f("recover_s", "%.1f"), f("cycle_p99_ms", "%.1f ms"), wall))
    if "trial" in result:
        t = result["trial"]
        print("\nNavigation trial (office, real_time_factor %g): %d of %d goals reached, %d contacts, "
              "%.0f sim s in %.0f wall s" % (t["real_time_factor"], t["succeeded"], t["runs"], t["contacts"],
                                             t["sim_seconds"], t["wall_seconds"]))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("what", choices=["sim", "nav", "formation", "all"])
    parser.add_argument("--json", metavar="FILE", help="write the figures as JSON")
    parser.add_argument("--trial-runs", type=int, default=100, help="navigation trial runs (0: skip)")
    parser.add_argument("--trial-rtf", type=float, default=0.0,
                        help="real-time factor of the trial (default 0: as fast as possible, lockstep)")
    parser.add_argument("--seeds", type=int, default=10, help="formation: seeds per fleet size")
    parser.add_argument("--sizes", default="3,5,10", help="formation: fleet sizes")
    args = parser.parse_args(argv)
    result = {}
    if args.what in ("sim", "all"):
        result.update(bench_sim())
    if args.what in ("nav", "all"):
        result.update(bench_nav(args.trial_runs, args.trial_rtf))
    if args.what == "formation":
        result.update(bench_formation(args.seeds, args.sizes))
    result["machine"] = machine()
    print_table(result)
    if args.json:
        with open(args.json, "w") as f:
            json.dump(result, f, indent=2)
        print("\nwrote %s" % args.json)


if __name__ == "__main__":
    main()
