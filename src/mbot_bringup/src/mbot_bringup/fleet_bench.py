"""What the fleet costs per robot: ``scripts/bench fleet [--sizes 3,10,20,40] [--json FILE]``.

For each fleet size it runs two scenarios with the scenario runner (real_time_factor 0 with
lockstep, no rviz, no rosbag), in the empty 40 x 40 m ``field`` (the trio's three robots, the
others placed near the leader; in the 20 x 20 m ``trio`` room a triangle of 20 has slots in the
wall):

- formation: a triangle, 1.2 m spacing, driving 6 m east;
- navigation: the same robots with a goal each (dispatch), no formation nodes.

While a run goes, it reads the CPU time of every process the runner started from /proc (twice a
second) and notes the wall time when the fleet is up (the runner's "fleet up" line) and when the
scenario is over ("stopping the fleet"). Between the two, the fleet does its work: that window
gives the real-time factor (sim s per wall s), the CPU s per robot per sim s and each process
kind's share of the CPU. The whole run, start-up and shut-down included, is reported beside it.

Benchmark, not a test: run it alone on a quiet machine (two benchmarks side by side on two cores
measure each other).
"""
import collections
import json
import os
import re
import subprocess
import sys
import tempfile
import time

#: A process's kind for the table: its ROS node name (``__name:=``), else its program.
KINDS = ("follower_controller", "move_base", "robot_state_publisher", "fake_localization", "pf_localization",
         "stage_node", "rosmaster", "coordinator", "metrics_collector", "dispatcher", "scenario_runner",
         "roslaunch", "rosout", "map_server", "fleet_tf_relay")

SPACING = 1.2      # [m] between the formation's slots
DISTANCE = 6.0     # [m] the formation drives east
LEADER_X = -5.0    # [m] the leader's start
WORLD = "field"


def formation_scenario(robots):
    return {
        "description": "Fleet cost benchmark: %d robots in a triangle drive %g m east." % (robots, DISTANCE),
        "world": WORLD, "robots": robots, "formation": "triangle", "spacing": SPACING,
        "time_limit": 150 + 5 * robots,
        "timeline": [{"at": 0, "do": {"target": [LEADER_X + DISTANCE, 0.0, 0.0]}}],
        "criteria": {"lost_at_end": 0},
    }


def navigation_scenario(robots):
    """A goal each, in rows of ten east of the fleet (the dispatcher assigns them)."""
    goals = [[2.0 + SPACING * (i // 10), -5.4 + SPACING * (i % 10), 0.0] for i in range(robots)]
    return {
        "description": "Fleet cost benchmark: %d robots, a move_base goal each, no formation." % robots,
        "world": WORLD, "robots": robots, "mode": "dispatch",
        "time_limit": 150 + 5 * robots,
        "timeline": [{"at": 0, "do": {"dispatch": goals}}],
    }


def kind_of(cmdline):
    """The process kind of a command line (KINDS, else its program's name)."""
    name = re.search(r"__name:=(\S+)", cmdline)
    if name:
        return name.group(1)
    words = cmdline.split()
    for word in words[:3]:
        base = os.path.basename(word)
        if base in KINDS:
            return base
    if "scenario_runner" in cmdline:
        return "scenario_runner"
    return os.path.basename(words[0]) if words else "?"


class ProcessTree(object):
    """CPU seconds of every process below a root process, read from /proc.

    A process's CPU time is known only while it lives, so the tree is read often and each
    process keeps its last reading (processes that end between two readings lose at most that
    half second). A process's kind is read again at every reading: between fork and exec a new
    process still has its parent's command line (roslaunch's), and a kind fixed then counted
    a 40-robot fleet's controllers started at that moment as `formation_fleet` (13 % of the CPU).
    Windows (cpu_between) are taken per process and summed by the kinds at the end."""

    def __init__(self, root_pid, proc="/proc"):
        self.root = root_pid
        self.proc = proc
        self.tick = os.sysconf("SC_CLK_TCK")
        self.cpu = {}       # pid -> CPU s at the last reading
        self.kind = {}      # pid -> kind

    def _stat(self, pid):
        with open(os.path.join(self.proc, pid, "stat")) as f:
            stat = f.read()
        fields = stat[stat.rfind(")") + 2:].split()
        return int(fields[1]), (int(fields[11]) + int(fields[12])) / float(self.tick)

    def read(self):
        parents, cpu = {}, {}
        for pid in os.listdir(self.proc):
            if not pid.isdigit():
                continue
            try:
                parents[int(pid)], cpu[int(pid)] = self._stat(pid)
            except (OSError, IndexError, ValueError):
                continue   # ended meanwhile
        below = {self.root}
        grown = True
        while grown:
            grown = False
            for pid, parent in parents.items():
                if parent in below and pid not in below:
                    below.add(pid)
                    grown = True
        for pid in below & set(cpu):
            self.cpu[pid] = cpu[pid]
            try:
                with open(os.path.join(self.proc, str(pid), "cmdline"), "rb") as f:
                    cmdline = f.read().replace(b"\0", b" ").decode("utf-8", "replace")
            except OSError:
                continue
            if cmdline.strip():
                self.kind[pid] = kind_of(cmdline)

    def snapshot(self):
        """{pid: CPU s} at the last reading (for cpu_between)."""
        return dict(self.cpu)

    def by_kind(self):
        """{kind: CPU s} of every process seen."""
        return self.cpu_between({})

    def cpu_between(self, since, until=None):
        """{kind: CPU s} spent between two snapshot()s (`until` None: the last reading), by each
        process's latest kind."""
        until = self.cpu if until is None else until
        total = collections.Counter()
        for pid, seconds in until.items():
            total[self.kind.get(pid, "?")] += seconds - since.get(pid, 0.0)
        return dict(total)


def figures(robots, sim_s, wall_s, cpu):
    """The benchmark's figures for one run window; cpu: {kind: CPU s}."""
    total = sum(cpu.values())
    shares = sorted(((k, v / total) for k, v in cpu.items() if total > 0), key=lambda kv: -kv[1])
    return {
        "sim_s": round(sim_s, 2), "wall_s": round(wall_s, 2),
        "rtf": round(sim_s / wall_s, 3) if wall_s > 0 else None,
        "cpu_s": round(total, 2),
        "cpu_per_robot": round(total / (robots * sim_s), 4) if sim_s > 0 else None,
        "top": {k: round(share, 3) for k, share in shares[:8]},
        "cpu_s_by_process": {k: round(v, 2) for k, v in sorted(cpu.items(), key=lambda kv: -kv[1]) if v >= 0.05},
    }


def run_one(scenario, robots, run_dir, log=sys.stderr):
    """Run one scenario (a dict) and measure it. Returns the figures of the fleet's working window
    and of the whole run, and whether the scenario passed."""
    import yaml

    os.makedirs(os.path.dirname(run_dir), exist_ok=True)
    path = run_dir + ".yaml"    # the runner starts the run directory afresh
    with open(path, "w") as f:
        yaml.safe_dump(scenario, f, sort_keys=False)
    command = ["/usr/bin/python3", "-m", "mbot_bringup.scenario_runner", path, "--run-dir", run_dir, "--no-rviz",
               "--no-record"]
    started = time.time()
    # the simulator writes where its lockstep waited, and for whom, when it stops (mbot_sim README)
    lockstep_report = os.path.abspath(run_dir + ".lockstep.txt")
    if os.path.exists(lockstep_report):
        os.remove(lockstep_report)
    runner = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True,
                              bufsize=1, env=dict(os.environ, MBOT_LOCKSTEP_REPORT=lockstep_report))
    tree = ProcessTree(runner.pid)
    marks = {}
    lines = []
    reader = _LineReader(runner.stdout)
    while True:
        tree.read()
        for line in reader.lines(0.5):
            lines.append(line)
            for mark, text in (("up", "fleet up"), ("over", "stopping the fleet")):
                if text in line and mark not in marks:
                    marks[mark] = (time.time(), tree.snapshot())
        if runner.poll() is not None and reader.done:
            break
    tree.read()
    ended = time.time()
    with open(run_dir + ".log", "w") as f:
        f.writelines(lines)
    result = {"robots": robots, "exit_status": runner.returncode, "passed": runner.returncode == 0}
    facts = {}
    try:
        with open(os.path.join(run_dir, "criteria.json")) as f:
            facts = json.load(f)["facts"]
    except (OSError, ValueError, KeyError):
        pass
    try:
        with open(lockstep_report) as f:
            result["lockstep"] = f.read().strip()
    except OSError:
        pass
    sim_s = facts.get("end_s") or 0.0
    result["whole_run"] = figures(robots, sim_s, ended - started, tree.by_kind())
    if "up" in marks and "over" in marks and sim_s > 0:
        (t_up, cpu_up), (t_over, cpu_over) = marks["up"], marks["over"]
        result.update(figures(robots, sim_s, t_over - t_up, tree.cpu_between(cpu_up, cpu_over)))
        result["startup_wall_s"] = round(t_up - started, 2)
    else:
        result["error"] = "no complete run (see %s.log)" % run_dir
        print("".join(lines[-30:]), file=log)
    return result


class _LineReader(object):
    """Lines of a pipe without blocking the /proc readings (a thread reads the pipe)."""

    def __init__(self, stream):
        import queue
        import threading

        self.queue = queue.Queue()
        self.done = False

        def pump():
            for line in stream:
                self.queue.put(line)
            self.done = True

        threading.Thread(target=pump, daemon=True).start()

    def lines(self, timeout):
        import queue

        out = []
        deadline = time.time() + timeout
        while True:
            try:
                out.append(self.queue.get(timeout=max(0.0, deadline - time.time())))
            except queue.Empty:
                return out


def bench_fleet(sizes, out_dir=None, modes=("formation", "navigation")):
    """{"fleet_scale": {N: figures}, "fleet_scale_navigation": {N: figures}}."""
    out_dir = out_dir or tempfile.mkdtemp(prefix="fleet_bench_")
    result = {}
    for mode in modes:
        key = "fleet_scale" if mode == "formation" else "fleet_scale_navigation"
        result[key] = {}
        for n in sizes:
            scenario = formation_scenario(n) if mode == "formation" else navigation_scenario(n)
            run_dir = os.path.join(out_dir, "%s_%d" % (mode, n))
            print("$ fleet %s, %d robots -> %s" % (mode, n, run_dir), file=sys.stderr)
            result[key][str(n)] = run_one(scenario, n, run_dir)
    return result


def table(result):
    lines = []
    titles = (("fleet_scale", "formation (triangle, 6 m)"), ("fleet_scale_navigation", "navigation only (a goal each)"))
    for key, title in titles:
        if key not in result:
            continue
        lines.append("\nFleet cost, %s: the fleet's working window (whole run in brackets)" % title)
        lines.append("  %-6s %-6s %16s %22s %7s  %s" % ("robots", "passed", "real-time x", "CPU s/robot/sim s",
                                                        "start s", "top processes (share of the CPU)"))
        for n, r in result[key].items():
            if "rtf" not in r:
                lines.append("  %-6s %-6s %s" % (n, r["passed"], r.get("error", "")))
                continue
            w = r["whole_run"]
            top = ", ".join("%s %.0f%%" % (k, 100 * v) for k, v in list(r["top"].items())[:5])
            lines.append("  %-6s %-6s %16s %22s %7.1f  %s" % (
                n, r["passed"], "%.2f (%.2f)" % (r["rtf"], w["rtf"] or 0.0),
                "%.3f (%.3f)" % (r["cpu_per_robot"], w["cpu_per_robot"] or 0.0), r["startup_wall_s"], top))
    return "\n".join(lines)
