"""The numbers of a formation run report: pass criteria, the rows of the tables, and the time
series the plots draw, all from the metrics collector's Run and summary
(`mbot_follower.metrics.load_run` / `summarize`). Plain data and numpy: no plotting, no ROS.

Times in the plots and tables count from the target: the first time the coordinator left IDLE
(the fleet got somewhere to go), so runs that waited longer before their target line up.
"""
import json
import math
import re
from collections import namedtuple

import numpy as np

from mbot_follower.trail import LeaderTrail, slot_pose, trail_start
from mbot_follower.metrics import _holds_under  # the recovery rule: the switch's settling figure


class ReportError(ValueError):
    """An input the report cannot use; the message is one line naming the file and the problem."""


# --- what the numbers are ---------------------------------------------------------------------

#: A number of the run: key (in run_numbers), label, unit as shown, scale from the SI value to
#: the shown one, digits after the point, better ("lower", "higher" or None: neither).
Metric = namedtuple("Metric", "key label unit scale digits better")

METRICS = [
    Metric("arrived", "arrived at the target", "", 1, 0, "higher"),
    Metric("arrival_s", "arrival: target to ARRIVED", "s", 1, 2, "lower"),
    Metric("steady_navigating_slot_rms_m", "formation error, RMS while moving (slots free)", "m", 1, 3, "lower"),
    Metric("slot_blocked_share", "share of moving time with a slot in a wall", "%", 100, 1, None),
    Metric("steady_arrived_slot_rms_m", "formation error, RMS after arrival", "m", 1, 3, "lower"),
    Metric("slot_rms_m", "formation error, RMS over the whole run", "m", 1, 3, "lower"),
    Metric("slot_p95_m", "formation error, 95th percentile", "m", 1, 3, "lower"),
    Metric("slot_max_m", "formation error, largest", "m", 1, 3, "lower"),
    Metric("fit_rms_m", "shape error after the best rigid fit, RMS", "m", 1, 3, "lower"),
    Metric("leader_lateral_rms_m", "leader lateral path error, RMS", "m", 1, 3, "lower"),
    Metric("leader_lateral_max_m", "leader lateral path error, largest", "m", 1, 3, "lower"),
    Metric("latency_p50_s", "control latency, median", "ms", 1000, 0, "lower"),
    Metric("latency_p95_s", "control latency, 95th percentile", "ms", 1000, 0, "lower"),
    Metric("latency_max_s", "control latency, largest", "ms", 1000, 0, "lower"),
    Metric("tf_success_rate", "tf lookup success", "%", 100, 3, "higher"),
    Metric("cycle_time_p99_ms", "controller cycle time, 99th percentile (wall)", "ms", 1, 1, "lower"),
    Metric("cycle_overruns", "controller cycles longer than the period (overruns, all robots)", "", 1, 0, "lower"),
    Metric("cycle_late_starts", "controller cycles started a period or more late (all robots)", "", 1, 0, "lower"),
    Metric("contacts", "contacts", "", 1, 0, "lower"),
    Metric("min_clearance_m", "closest robot-robot clearance", "m", 1, 2, "higher"),
    Metric("distance_m", "distance driven, all robots", "m", 1, 1, None),
    Metric("energy_j", "energy, all robots", "J", 1, 1, "lower"),
    Metric("switches", "formation switches", "", 1, 0, None),
    Metric("switch_settle_max_s", "switch: longest time until the slot RMS settled", "s", 1, 2, "lower"),
    Metric("losses", "robots lost", "", 1, 0, "lower"),
    Metric("rejoins", "robots that rejoined", "", 1, 0, None),
    Metric("recovery_max_s", "loss: longest recovery", "s", 1, 2, "lower"),
    Metric("duration_s", "run length (sim time)", "s", 1, 1, None),
]
STATES = ("IDLE", "FORMING", "NAVIGATING", "DEGRADED", "ARRIVED", "ABORTED")
for _state in STATES:
    METRICS.append(Metric("time_in_state_s." + _state, "time in " + _state, "s", 1, 1, None))
#: Criteria the scenario runner judges from what it saw (criteria.json), not in the metrics table.
RUNNER_METRICS = [
    Metric("max_switch_time_s", "switch: longest time until the new shape stood", "s", 1, 2, "lower"),
    Metric("max_time_to_degraded_s", "loss: longest time to DEGRADED", "s", 1, 2, "lower"),
    Metric("max_recovery_time_s", "loss: longest recovery", "s", 1, 2, "lower"),
    Metric("goals_reached", "move_base goals reached", "", 1, 0, "higher"),
    Metric("failed_steps", "timeline steps that failed", "", 1, 0, "lower"),
    Metric("finished", "timeline ran to its end", "", 1, 0, "higher"),
]
METRIC_BY_KEY = dict((m.key, m) for m in METRICS + RUNNER_METRICS)

OPS = {
    "<=": lambda v, t: v <= t,
    "<": lambda v, t: v < t,
    ">=": lambda v, t: v >= t,
    ">": lambda v, t: v > t,
    "==": lambda v, t: v == t,
}


class LabCriteria(object):
    """The pass criteria a formation lab uses when a run has no criteria.json."""

    def __init__(self):
        self.formation_rms = 0.15     # steady formation error (slot RMS while the leader moves) <= [m]
        self.leader_lateral = 0.08    # leader's distance from its global plan, RMS <= [m]
        self.latency_p95 = 0.12       # control latency, 95th percentile <= [s]
        self.tf_success = 0.9999      # share of tf lookups that succeeded >= [1]
        self.contacts = 0             # collisions <= [count]

    def criteria(self):
        """[(name, op, threshold)] over run_numbers' keys; arriving is always asked for."""
        return [("steady_navigating_slot_rms_m", "<=", self.formation_rms),
                ("leader_lateral_rms_m", "<=", self.leader_lateral),
                ("latency_p95_s", "<=", self.latency_p95),
                ("tf_success_rate", ">=", self.tf_success),
                ("contacts", "<=", self.contacts),
                ("arrived", "==", True)]


#: One pass criterion: name (a run_numbers key or the runner's own name), the measured value
#: (None: not measured), op, threshold, passed.
Criterion = namedtuple("Criterion", "name value op threshold passed")


def evaluate(numbers, criteria):
    """[Criterion] of (name, op, threshold) against run_numbers; a missing value fails."""
    out = []
    for name, op, threshold in criteria:
        value = numbers.get(name)
        out.append(Criterion(name, value, op, threshold, value is not None and bool(OPS[op](value, threshold))))
    return out


def _is_number(value):
    return isinstance(value, (int, float)) and not isinstance(value, bool)


def parse_criteria(data, path):
    """(scenario, passed, [Criterion], facts) of the contents of a criteria.json written by the
    scenario runner: {"scenario", "passed", "criteria": [{"name", "value", "threshold", "op",
    "passed"}], optional "facts": {name: value} (what the runner saw)}. ReportError naming the
    file and the key for anything else."""
    def bad(key, expected, got):
        raise ReportError("%s: %s: expected %s, got %s" % (path, key, expected, json.dumps(got)))
    if not isinstance(data, dict):
        bad("top level", "an object with scenario, passed, criteria", data)
    unknown = sorted(set(data) - {"scenario", "passed", "criteria", "facts"})
    if unknown:
        raise ReportError("%s: unknown key(s) %s (known: criteria, facts, passed, scenario)"
                          % (path, ", ".join(unknown)))
    facts = data.get("facts", {})
    if not isinstance(facts, dict):
        bad("facts", "an object {name: value}", facts)
    for key in ("scenario", "passed", "criteria"):
        if key not in data:
            raise ReportError("%s: %s: missing" % (path, key))
    if not isinstance(data["scenario"], str):
        bad("scenario", "a name", data["scenario"])
    if not isinstance(data["passed"], bool):
        bad("passed", "true or false", data["passed"])
    if not isinstance(data["criteria"], list):
        bad("criteria", "a list", data["criteria"])
    out = []
    for i, c in enumerate(data["criteria"]):
        where = "criteria[%d]" % i
        if not isinstance(c, dict):
            bad(where, "an object with name, value, threshold, op, passed", c)
        keys = {"name", "value", "threshold", "op", "passed"}
        if set(c) != keys:
            raise ReportError("%s: %s: expected the keys %s, got %s"
                              % (path, where, ", ".join(sorted(keys)), ", ".join(sorted(c)) or "none"))
        if not isinstance(c["name"], str) or not c["name"]:
            bad(where + ".name", "a name", c["name"])
        if c["op"] not in OPS:
            bad(where + ".op", "one of " + " ".join(sorted(OPS)), c["op"])
        if not (_is_number(c["threshold"]) or isinstance(c["threshold"], bool)):
            bad(where + ".threshold", "a number or true/false", c["threshold"])
        if not (c["value"] is None or _is_number(c["value"]) or isinstance(c["value"], bool)):
            bad(where + ".value", "a number, true/false or null", c["value"])
        if not isinstance(c["passed"], bool):
            bad(where + ".passed", "true or false", c["passed"])
        out.append(Criterion(c["name"], c["value"], c["op"], c["threshold"], c["passed"]))
    return data["scenario"], data["passed"], out, facts


def format_value(key, value):
    """A value as the tables show it, in the unit of its Metric ("-" for no data)."""
    if value is None or (isinstance(value, float) and not math.isfinite(value)):
        return "-"
    if isinstance(value, bool):
        return "yes" if value else "no"
    metric = METRIC_BY_KEY.get(key)
    if metric is None:
        return "%g" % value
    return "%.*f" % (metric.digits, value * metric.scale)


# --- events, states, slots ----------------------------------------------------------------------

def sorted_events(run):
    """The run's events by time (the collector appends them in arrival order)."""
    return sorted(run.events, key=lambda e: e.t)


def target_time(run):
    """Sim time [s] the fleet got its target: its first state other than IDLE (the run's start
    if it never left IDLE)."""
    for e in sorted_events(run):
        if e.kind == "state" and e.name not in ("", "IDLE"):
            return e.t
    return run.samples[0].t if run.samples else 0.0


def arrival_time(run, last=False):
    """Sim time [s] of the first ARRIVED (last: of the last one, the end of a route of several
    targets), or None."""
    times = [e.t for e in sorted_events(run) if e.kind == "state" and e.name == "ARRIVED"]
    if not times:
        return None
    return times[-1] if last else times[0]


def state_spans(run, end):
    """[(state, t_from, t_to)] [s sim] of the coordinator's states up to `end`."""
    changes = [e for e in sorted_events(run) if e.kind == "state"]
    return [(e.name, e.t, after.t if after is not None else max(end, e.t))
            for e, after in zip(changes, changes[1:] + [None])]


#: Something to mark on a time axis: t [s sim], kind (switch, loss, rejoin, pause, contact, or
#: any other event kind the collector adds), label, the event's name (the robot of a loss).
Mark = namedtuple("Mark", "t kind label name")

#: A leader pause: from start to end [s sim] (end: the run's end if it never ended), and the
#: coordinator's reason without its "paused: " head.
Pause = namedtuple("Pause", "start end reason")


def _pause_reason(detail):
    return detail[len("paused:"):].strip() if detail.startswith("paused:") else detail.strip()


def pause_spans(run, end):
    """[Pause] from the collector's pause events (start / end, with the reason at the start); a
    pause still on at `end` [s sim] lasts until then. The coordinator's state stays NAVIGATING
    during a pause: these events are all that records it."""
    spans, start = [], None
    for e in sorted_events(run):
        if e.kind != "pause":
            continue
        if e.name == "start" and start is None:
            start = e
        elif e.name == "end" and start is not None:
            spans.append(Pause(start.t, e.t, _pause_reason(start.detail)))
            start = None
    if start is not None:
        spans.append(Pause(start.t, max(end, start.t), _pause_reason(start.detail)))
    return spans


def event_marks(run):
    """[Mark] of what happened: switches, losses, rejoins, contacts, the start of each pause
    (labelled with its reason; pause_spans gives its length), and any event kind other than
    states and assignments."""
    marks = []
    for e in sorted_events(run):
        if e.kind == "switch":
            marks.append(Mark(e.t, "switch", "switch %s > %s" % (e.detail, e.name), e.name))
        elif e.kind == "loss":
            marks.append(Mark(e.t, "loss", "lost " + e.name, e.name))
        elif e.kind == "rejoin":
            marks.append(Mark(e.t, "rejoin", e.name + " back", e.name))
        elif e.kind == "contact":
            marks.append(Mark(e.t, "contact", "contact %s-%s" % (e.name, e.detail), e.name))
        elif e.kind == "pause":
            if e.name == "start":   # the end closes the shaded span; no line of its own
                marks.append(Mark(e.t, "pause", "pause: " + _pause_reason(e.detail), e.name))
        elif e.kind not in ("state", "assignment"):
            marks.append(Mark(e.t, e.kind, ("%s %s" % (e.kind, e.name)).strip(), e.name))
    return marks


#: A slot assignment from t [s sim] on: leader, formation, slots {robot: (x, y)} in the leader
#: frame [m]; along_path: the slots behind the leader lie on its path (a column).
Assignment = namedtuple("Assignment", "t leader formation slots along_path", defaults=(False,))

_SLOT = re.compile(r"(\S+)\(([^,()]+),([^,()]+)\)")


def assignments(run, where="events.csv"):
    """[Assignment] from the collector's assignment events, whose detail reads
    "leader L spacing S m slots r(x,y) ..." ("... m along_path slots ..." for a column)."""
    out = []
    for e in sorted_events(run):
        if e.kind != "assignment":
            continue
        head, _, slot_text = e.detail.partition(" slots ")
        words = head.split()
        slots = {}
        try:
            for robot, x, y in _SLOT.findall(slot_text):
                slots[robot] = (float(x), float(y))
        except ValueError:
            slots = {}
        if len(words) < 2 or words[0] != "leader" or not slots:
            raise ReportError("%s: assignment at t = %.2f s: expected \"leader L spacing S m slots r(x,y) ...\", "
                              "got %r" % (where, e.t, e.detail))
        out.append(Assignment(e.t, words[1], e.name, slots, "along_path" in words))
    return out


def assignment_at(assigned, t):
    """The Assignment in force at t [s] (None before the first)."""
    current = None
    for a in assigned:
        if a.t > t + 1e-9:
            break
        current = a
    return current


def slot_positions(assignment, leader_pose, trail=None):
    """{robot: (x, y)} [m, map] of every follower's slot for the leader at (x, y, theta); for an
    assignment along the path, on the leader's path `trail` (leader_trail) when it is given."""
    if assignment is None or leader_pose is None or not all(math.isfinite(v) for v in leader_pose):
        return {}
    trail = trail if assignment.along_path else None
    return dict((r, tuple(slot_pose(leader_pose, off, trail)[:2]))
                for r, off in assignment.slots.items() if r != assignment.leader)


def leader_trail(series, assignment, i):
    """The leader's path (trail.LeaderTrail) of the assignment up to sample i, from the samples:
    the path its slots lie on when it is along the path (None without a pose)."""
    # from the newest sample with a leader pose not later than the assignment on
    first = int(np.searchsorted(series.t + series.t0, assignment.t + 1e-9, side="right")) - 1
    while first > 0 and series.pose(assignment.leader, first) is None:
        first -= 1
    poses = [(series.t[j] + series.t0,) + p for j, p in
             ((j, series.pose(assignment.leader, j)) for j in range(max(first, 0), i + 1)) if p is not None]
    start = trail_start(poses, assignment.t)
    if start is None:
        return None
    trail = LeaderTrail()
    trail.restart(assignment.t, start[1:4])
    for p in poses:
        if p[0] > start[0] + 1e-9:
            trail.follow(*p[1:4])
    return trail


# --- time series ---------------------------------------------------------------------------------

class Series(object):
    """The samples of a run as arrays (NaN where nothing was measured); t from the target [s]."""

    def __init__(self, run):
        self.t0 = target_time(run)                                      # sim time of the target [s]
        self.t = np.array([s.t for s in run.samples], dtype=float) - self.t0
        self.state = [s.state for s in run.samples]
        self.leader = [s.leader for s in run.samples]
        self.lost = [s.lost for s in run.samples]
        self.slot_rms = np.array([s.slot_rms for s in run.samples], dtype=float)           # [m]
        self.fit_rms = np.array([s.fit_rms for s in run.samples], dtype=float)             # [m]
        self.leader_lateral = np.array([s.leader_lateral for s in run.samples], dtype=float)  # [m]
        self.robots = list(run.robots)
        self.x, self.y, self.theta, self.slot_error, self.distance, self.slot_blocked = {}, {}, {}, {}, {}, {}
        for r in self.robots:
            rows = [s.robots.get(r) for s in run.samples]
            self.x[r] = np.array([p.x if p else np.nan for p in rows], dtype=float)             # [m]
            self.y[r] = np.array([p.y if p else np.nan for p in rows], dtype=float)             # [m]
            self.theta[r] = np.array([p.theta if p else np.nan for p in rows], dtype=float)     # [rad]
            self.slot_error[r] = np.array([p.slot_error if p else np.nan for p in rows], dtype=float)  # [m]
            self.distance[r] = np.array([p.distance if p else np.nan for p in rows], dtype=float)   # so far [m]
            self.slot_blocked[r] = np.array([bool(p) and p.slot_free == 0.0 for p in rows])  # slot in a wall

    def pose(self, robot, i):
        """(x, y, theta) of robot at sample i, or None without a pose."""
        if robot not in self.x:
            return None
        p = (self.x[robot][i], self.y[robot][i], self.theta[robot][i])
        return p if all(math.isfinite(v) for v in p) else None

    def followers(self):
        """Robots that were a follower (had a slot error) at some sample."""
        return [r for r in self.robots if np.any(np.isfinite(self.slot_error[r]))]


def speeds(t, x, y, window, max_gap):
    """Speed [m/s] at each sample (t [s], x, y [m]): the distance between the samples window/2
    [s] before and after it over their time apart (a sample holds the newest pose at or before its
    time, so neighbouring samples jitter by a pose period; a window of ~1 s averages that out).
    NaN where a pose is missing or the two samples are more than window + max_gap [s] apart."""
    t, x, y = (np.asarray(a, dtype=float) for a in (t, x, y))
    n = len(t)
    out = np.full(n, np.nan)
    if n < 2:
        return out
    lo = np.clip(np.searchsorted(t, t - window / 2.0), 0, n - 1)
    hi = np.clip(np.searchsorted(t, t + window / 2.0, side="right") - 1, 0, n - 1)
    dt = t[hi] - t[lo]
    step = np.hypot(x[hi] - x[lo], y[hi] - y[lo])
    ok = (dt > 0) & (dt <= window + max_gap) & np.isfinite(step)
    out[ok] = step[ok] / dt[ok]
    return out


def fleet_path_length(series):
    """[m] at each sample: the distance all robots have driven so far, together (the metrics'
    per-robot distance; a robot not known yet counts 0)."""
    total = np.zeros(len(series.t))
    for r in series.robots:
        d = series.distance[r].copy()
        for i in range(len(d)):   # hold the last known value over a missing one
            if not math.isfinite(d[i]):
                d[i] = d[i - 1] if i else 0.0
        total += d
    return total


# --- derived numbers ---------------------------------------------------------------------------

def switch_settling(run):
    """One dict per formation switch: t_s (sim), formation, previous, settle_s (time until the
    slot RMS is under the recovery bound and stays there for the recovery hold, as for a loss;
    None: never) and peak_rms_m (largest slot RMS from the switch until it settled). Settling is
    its own figure, later than the switch time (switch_done_times: the metrics' one rule of when
    a switch is done)."""
    config = run.config
    out = []
    for e in sorted_events(run):
        if e.kind != "switch":
            continue
        after = [s for s in run.samples if s.t >= e.t]
        settle = None
        for i, s in enumerate(after):
            if _holds_under(after, i, config.recovered_rms, config.recovered_hold):
                settle = s.t - e.t
                break
        window = [s.slot_rms for s in after if settle is None or s.t <= e.t + settle]
        finite = [v for v in window if math.isfinite(v)]
        out.append({"t_s": e.t, "formation": e.name, "previous": e.detail, "settle_s": settle,
                    "peak_rms_m": max(finite) if finite else None})
    return out


def run_numbers(run, summary):
    """{key: value} in SI units of everything METRICS lists (None: not measured)."""
    fleet = summary["fleet"]
    numbers = dict((k, v) for k, v in fleet.items() if not isinstance(v, (dict, str)))
    arrived = arrival_time(run)
    numbers["arrived"] = summary["state"] == "ARRIVED"
    numbers["arrival_s"] = arrived - target_time(run) if arrived is not None else None
    numbers["duration_s"] = summary["duration_s"]
    settles = [s["settle_s"] for s in switch_settling(run)]
    numbers["switch_settle_max_s"] = None if not settles or None in settles else max(settles)
    recovered = [r["recovery_time_s"] for r in summary["recoveries"]]
    numbers["recovery_max_s"] = None if not recovered or None in recovered else max(recovered)
    for state in STATES:
        numbers["time_in_state_s." + state] = fleet["time_in_state_s"].get(state)
    return numbers


def compare_rows(numbers_a, numbers_b):
    """[(key, a, b, difference b - a, better: "A", "B", "same" or "")] for every METRICS key that
    either run has."""
    rows = []
    for m in METRICS:
        a, b = numbers_a.get(m.key), numbers_b.get(m.key)
        if a is None and b is None:
            continue
        diff, better = None, ""
        if isinstance(a, bool) or isinstance(b, bool):   # yes / no: no difference to show
            if a is not None and b is not None and m.better is not None:
                better = "same" if a == b else ("B" if (b > a) == (m.better == "higher") else "A")
        elif a is not None and b is not None:
            diff = float(b) - float(a)
            if m.better is not None:
                if abs(diff) < 0.5 * 10.0 ** -m.digits / m.scale:   # equal as shown
                    better = "same"
                elif (diff < 0) == (m.better == "lower"):
                    better = "B"
                else:
                    better = "A"
        rows.append((m.key, a, b, diff, better))
    return rows
