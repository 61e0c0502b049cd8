"""Scenarios as data: what a fleet run does, step by step, and what makes it pass.

A scenario file (`scenarios/NAME.yaml`) names the world and the fleet (robots, formation, spacing,
controller, localization), a timeline of steps played in sim time, a time limit, and pass
criteria over the metrics of the run. This module reads it strictly (`mbot_common.strict_yaml`:
one line naming the file and the key for every mistake), plays the timeline's logic and judges
the criteria; it knows nothing of ROS (scenario_runner.py is the ROS side).

    scenario = load_scenario("scenarios/triangle_trio.yaml")
    timeline = Timeline(scenario)
    timeline.observe("navigating", 12.5)         # an event, sim seconds after the start
    for step in timeline.due(13.0):              # the steps to carry out now, in order
        print(step.action, step.arg)
    timeline.finished(60.0), timeline.timed_out(60.0)

The timeline runs in order: a step waits until its condition holds and every step before it has
run. `at: T` holds from T sim seconds after the start. `after: EVENT` holds once EVENT happens
after the step before ran (`delay: D` seconds later): `after: arrived` is the next arrival, not
an old one. The run ends when every step has run and the `end` event has happened after the last
one (then `settle` seconds more, so that the metrics see the end state), or at `time_limit`.
"""
import math
import os

from mbot_common.strict_yaml import ConfigError, Reader, load_yaml
from mbot_common.world import FAULT_KEYS, Faults, check_faults, check_name
from mbot_bringup.fleet_world import MAX_ROBOTS
from mbot_follower.metrics.settle import switch_done_times

MODES = ("formation", "dispatch")
LOCALIZATIONS = ("fake", "pf")
TOPOLOGIES = ("star", "chain")

#: Events a step can wait for (`after:`) and a run can end on (`end:`). The fleet states are the
#: coordinator's (/fleet/status) when they begin; `formed`: the current formation stands, by the
#: metrics' switch rule (mbot_follower.metrics.settle: every follower within 0.3 m of its slot
#: for 0.5 s, from ground truth); `goals_done`: every
#: dispatched move_base goal has finished (dispatch mode).
EVENTS = ("forming", "navigating", "arrived", "degraded", "aborted", "paused", "formed", "goals_done")

#: Actions (`do: {ACTION: ARGUMENT}`) and the modes that have them.
ACTIONS = {
    "target": ("formation",),           # [x, y, theta]: drive the formation there (/fleet/target_pose)
    "formation": ("formation",),        # NAME or {name, spacing}: switch (/fleet/set_formation)
    "kill_controller": ("formation",),  # ROBOT: rosnode kill /ROBOT/follower_controller
    "dispatch": ("dispatch",),          # [[x, y, theta], ...]: goals for the dispatcher (/dispatch/goals)
    "spawn_obstacle": MODES,            # {name, shape, size | radius, pose} (/spawn_obstacle)
    "remove_obstacle": MODES,           # NAME (/remove_obstacle)
    "remove_robot": MODES,              # ROBOT (/remove_robot)
    "spawn_robot": MODES,               # {name, model, pose} (/spawn_robot)
    "set_param": MODES,                 # {name, value}: rosparam set
    "fault": MODES,                     # {robot, laser_dropout, ..., silenced} (/set_fault)
    "screenshot": MODES,                # NAME: rviz screenshot RUN_DIR/screenshots/NAME.png
}

#: Pass criteria: name -> (op, kind of threshold, what it measures). The values come from the
#: metrics summary (mbot_follower.metrics.summarize), from the run (switch times) and from what
#: the runner saw (facts: arrivals, goals, failed steps).
CRITERIA = {
    "steady_navigating_slot_rms_m": ("<=", float, "slot RMS, NAVIGATING, leader moving, slots clear of walls [m]"),
    "steady_arrived_slot_rms_m": ("<=", float, "slot error RMS while ARRIVED [m]"),
    "slot_rms_m": ("<=", float, "slot error RMS over the whole run [m]"),
    "fit_rms_m": ("<=", float, "shape error RMS after the best rigid fit [m]"),
    "leader_lateral_rms_m": ("<=", float, "leader's distance from its global plan, RMS [m]"),
    "latency_p95_s": ("<=", float, "control latency, 95th percentile [s]"),
    "tf_success_rate": (">=", float, "share of the followers' tf lookups that succeeded"),
    "contacts": ("<=", int, "collisions reported by the simulator"),
    "min_clearance_m": (">=", float, "smallest robot-robot gap [m]"),
    "switches": (">=", int, "formation switches"),
    "losses": (">=", int, "robots lost"),
    "rejoins": (">=", int, "robots that rejoined"),
    "max_switch_time_s": ("<=", float, "longest time from a switch until the new shape stood [s]"),
    "max_loss_detection_s": ("<=", float, "longest time from a step that takes a robot out (kill_controller, "
                             "remove_robot, a fault drive_frozen or silenced; from when its call "
                             "returned) to DEGRADED [s]"),
    "max_time_to_degraded_s": ("<=", float, "longest time from a loss (the status names it lost) to DEGRADED [s]"),
    "max_recovery_time_s": ("<=", float, "longest time from a loss until the slot RMS settled [s]"),
    "duration_s": ("<=", float, "sim time the metrics cover [s]"),
    "goals_reached": (">=", int, "dispatched move_base goals that SUCCEEDED"),
    "failed_steps": ("<=", int, "timeline steps the fleet refused (service answered no, unknown robot ...)"),
    "lost_at_end": ("<=", int, "robots the coordinator counts as lost when the run ends"),
    "arrived": ("==", bool, "the fleet reached every target and ended ARRIVED"),
    "finished": ("==", bool, "the timeline ran to its end before the time limit"),
}

#: The formation lab's thresholds: what every formation scenario must meet unless it says otherwise.
FORMATION_DEFAULTS = {
    "finished": True,
    "failed_steps": 0,
    "arrived": True,
    "steady_navigating_slot_rms_m": 0.15,
    "leader_lateral_rms_m": 0.08,
    "latency_p95_s": 0.12,
    "tf_success_rate": 0.9999,
    "contacts": 0,
}
#: The lab's thresholds (the defaults above, and docs/formation_benchmark.md's targets: a switch
#: within 6 s, DEGRADED within 2 s). A scenario may set a looser one only with a reason:
#: `NAME: {value: V, why: TEXT}`; the report shows both thresholds and the reason.
LAB_THRESHOLDS = dict(FORMATION_DEFAULTS, max_switch_time_s=6.0, max_loss_detection_s=2.0,
                      max_time_to_degraded_s=2.0)
#: Dispatch scenarios: every goal reached (goals_reached is set to the number of goals), no contact.
DISPATCH_DEFAULTS = {"finished": True, "failed_steps": 0, "contacts": 0}


class TimelineConfig(object):
    """How the runner judges events that no node announces."""

    def __init__(self, settle=2.0):
        self.settle = settle                      # after the end event, run on this long [s sim]


class Step(object):
    """One timeline step: when (at [s] or after EVENT + delay [s]), what (action, arg), and
    where it is in the file (key, e.g. "timeline[2]")."""

    def __init__(self, index, key, action, arg, at=None, after=None, delay=0.0):
        self.index = index
        self.key = key
        self.action = action
        self.arg = arg
        self.at = at          # [s sim after the start] or None
        self.after = after    # an EVENTS name or None
        self.delay = delay    # [s sim] after the event

    def when(self):
        """The condition in words: "at 5 s", "after arrived + 2 s"."""
        if self.at is not None:
            return "at %g s" % self.at
        return "after %s%s" % (self.after, " + %g s" % self.delay if self.delay else "")

    def describe(self):
        """The action in words, e.g. "target [5, 0, 0]", "formation column"."""
        arg = self.arg
        if self.action == "target":
            return "target [%s]" % ", ".join("%g" % v for v in arg)
        if self.action == "formation":
            return "formation %s%s" % (arg["name"], " (spacing %g m)" % arg["spacing"] if arg["spacing"] else "")
        if self.action == "dispatch":
            return "dispatch %d goals" % len(arg)
        if isinstance(arg, dict):
            return "%s %s" % (self.action, arg.get("name", arg.get("robot", "")))
        return "%s %s" % (self.action, arg)


class Scenario(object):
    """Everything a scenario file says (see the module docstring and the README)."""

    def __init__(self):
        self.path = ""
        self.name = ""               # the file name without .yaml
        self.description = ""
        self.world = ""              # a world name (maps/NAME.world.yaml) or a path
        self.robots = None           # number of robots, None: the world's
        self.mode = "formation"
        self.leader = ""             # "" = the world's first robot
        self.formation = ""
        self.spacing = 0.0           # [m]
        self.topology = "star"
        self.controller = "slot_tracking"
        self.localization = "fake"
        self.leader_max_vel = 0.35   # [m/s] the leader's move_base limit, below the followers' 0.5
        self.time_limit = 0.0        # [s sim]
        self.end = "arrived"
        self.timeline = []           # [Step]
        self.criteria = {}           # name -> threshold
        self.criteria_why = {}       # name -> why a threshold is looser than the lab's

    def steps(self, action):
        return [s for s in self.timeline if s.action == action]

    def robot_names_used(self):
        """[(key, robot name)] every robot a step names (to check against the world)."""
        used = []
        for s in self.timeline:
            if s.action in ("kill_controller", "remove_robot"):
                used.append(("%s.do.%s" % (s.key, s.action), s.arg))
            elif s.action == "fault":
                used.append(("%s.do.fault.robot" % s.key, s.arg["robot"]))
        return used


# --- reading --------------------------------------------------------------------------------

def _name_arg(r, key, what="a name"):
    value = r.required(key, str, what=what)
    problem = check_name(value)
    if problem:
        r.fail(key, problem)
    return value


def _pose(r, key):
    return r.number_list(key, 3, what="a list of 3 numbers [x, y, theta] [m, m, rad]")


def _read_formation_arg(r, key, value):
    if isinstance(value, str):
        if not value:
            r.expected(key, "a formation name or {name, spacing}", value)
        return {"name": value, "spacing": 0.0}
    fr = r.child(key)
    fr.check_keys(["name", "spacing"], required=["name"])
    name = fr.required("name", str)
    spacing = fr.optional("spacing", float, 0.0, what="a number > 0 [m]", check=lambda v: v > 0.0)
    return {"name": name, "spacing": spacing}


def _read_obstacle(r):
    r.check_keys(["name", "shape", "size", "radius", "pose"], required=["name", "shape", "pose"])
    name = _name_arg(r, "name")
    shape = r.required("shape", str, what="box or cylinder", check=lambda v: v in ("box", "cylinder"))
    obstacle = {"name": name, "shape": shape, "length": 0.0, "width": 0.0, "radius": 0.0, "pose": _pose(r, "pose")}
    if shape == "box":
        if "radius" in r:
            r.fail("radius", "a box has a size [length, width], not a radius")
        what = "a list of 2 numbers > 0 [length, width] [m]"
        if "size" not in r:
            r.fail("size", "missing key (required for a box)")
        length, width = r.number_list("size", 2, what=what)
        if length <= 0.0 or width <= 0.0:
            r.expected("size", what, r.data["size"])
        obstacle.update(length=length, width=width)
    else:
        if "size" in r:
            r.fail("size", "a cylinder has a radius, not a size")
        obstacle["radius"] = r.required("radius", float, what="a number > 0 [m]", check=lambda v: v > 0.0)
    return obstacle


def _read_fault(r):
    r.check_keys(["robot"] + FAULT_KEYS, required=["robot"])
    robot = _name_arg(r, "robot", "a robot name")
    faults = Faults(*[r.optional(k, float, 0.0) for k in FAULT_KEYS[:4]]
                    + [r.optional(k, bool, False) for k in FAULT_KEYS[4:]])
    problem = check_faults(faults)
    if problem:
        field, _, rest = problem.partition(": ")
        r.fail(field, rest)
    arg = {"robot": robot}
    arg.update(faults._asdict())
    return arg


def _read_action(dr, action, mode):
    """The argument of `action` from the `do` map's Reader `dr`."""
    if mode not in ACTIONS[action]:
        dr.fail(action, "not an action of %s mode (its actions: %s)" % (
            mode, ", ".join(a for a in ACTIONS if mode in ACTIONS[a])))
    if action == "target":
        return _pose(dr, action)
    if action == "formation":
        return _read_formation_arg(dr, action, dr.required(action, object))
    if action in ("kill_controller", "remove_robot", "remove_obstacle", "screenshot"):
        return _name_arg(dr, action)
    if action == "dispatch":
        goals = dr.required(action, list, what="a list of goals [[x, y, theta], ...]", check=lambda v: len(v) > 0)
        # each goal read as a key of its own, so that a message names it: "...do.dispatch[1]"
        return [_pose(Reader({"%s[%d]" % (action, i): goal}, dr.where), "%s[%d]" % (action, i))
                for i, goal in enumerate(goals)]
    if action == "spawn_obstacle":
        return _read_obstacle(dr.child(action))
    if action == "spawn_robot":
        rr = dr.child(action)
        rr.check_keys(["name", "model", "pose"], required=["name", "model", "pose"])
        return {"name": _name_arg(rr, "name"), "model": rr.required("model", str, what="mbot or mbot_omni",
                                                                    check=lambda v: v in ("mbot", "mbot_omni")),
                "pose": _pose(rr, "pose")}
    if action == "set_param":
        pr = dr.child(action)
        pr.check_keys(["name", "value"], required=["name", "value"])
        name = pr.required("name", str, what="a parameter name such as /robot_1/follower_controller/max_linear_vel",
                           check=lambda v: v.startswith("/") and len(v) > 1)
        value = pr.required("value", object)
        if value is None or isinstance(value, (list, dict)):
            pr.expected("value", "a number, true/false or a string", value)
        return {"name": name, "value": value}
    if action == "fault":
        return _read_fault(dr.child(action))
    raise AssertionError(action)  # every ACTIONS name is handled above


def _read_step(r, index, mode, time_limit):
    key = "timeline[%d]" % index
    r.check_keys(["at", "after", "delay", "do"], required=["do"])
    if ("at" in r) == ("after" in r):
        r.fail(None, "expected exactly one of at (sim seconds after the start) or after (an event)")
    at = after = None
    delay = 0.0
    if "at" in r:
        at = r.required("at", float, what="a number >= 0 [s sim]", check=lambda v: v >= 0.0)
        if at > time_limit:
            r.fail("at", "%g s is after the time limit (%g s)" % (at, time_limit))
        if "delay" in r:
            r.fail("delay", "only a step with after: waits a delay (at: gives the time itself)")
    else:
        after = r.required("after", str, what="an event (%s)" % ", ".join(EVENTS), check=lambda v: v in EVENTS)
        delay = r.optional("delay", float, 0.0, what="a number >= 0 [s sim]", check=lambda v: v >= 0.0)
    dr = r.child("do")
    names = dr.keys()
    if len(names) != 1 or names[0] not in ACTIONS:
        dr.fail(None if len(names) != 1 else names[0],
                "expected one action (%s), got %s" % (", ".join(ACTIONS), ", ".join(str(n) for n in names) or "none"))
    action = names[0]
    arg = _read_action(dr, action, mode)
    return Step(index, key, action, arg, at=at, after=after, delay=delay)


def _read_criteria(r, mode, scenario):
    defaults = dict(FORMATION_DEFAULTS if mode == "formation" else DISPATCH_DEFAULTS)
    if mode == "dispatch":
        defaults["goals_reached"] = sum(len(s.arg) for s in scenario.steps("dispatch"))
    criteria = dict(defaults)
    cr = r.child("criteria", required=False)
    for name in cr.keys():
        if name not in CRITERIA:
            cr.fail(name, "unknown criterion (expected one of %s)" % ", ".join(CRITERIA))
        op, kind, what = CRITERIA[name]
        value = cr.required(name, object)
        if value is None:
            if name not in defaults:
                cr.fail(name, "null removes a default criterion, and %s is none (defaults: %s)"
                        % (name, ", ".join(defaults)))
            del criteria[name]
            continue
        number = "an integer" if kind is int else "a number"
        what = "true or false" if kind is bool else "%s (%s %s)" % (number, op, what)
        why = ""
        if isinstance(value, dict):     # {value, why}: a threshold looser than the lab's, with its reason
            vr = cr.child(name)
            vr.check_keys(["value", "why"], required=["value", "why"])
            threshold = vr.required("value", kind, what=what)
            why = vr.required("why", str, what="a reason (text)", check=lambda v: v.strip() != "").strip()
        else:
            threshold = cr.required(name, kind, what=what)
        lab = LAB_THRESHOLDS.get(name)
        looser = lab is not None and kind is not bool and (threshold < lab if op == ">=" else threshold > lab)
        if looser and not why:
            cr.fail(name, "%s %g is looser than the lab's %s %g: say why ({value: %g, why: ...})"
                    % (op, threshold, op, lab, threshold))
        if why and not looser:
            cr.fail(name, "a why: is for a threshold looser than the lab's (%s %s), and %g is not"
                    % (op, "none" if lab is None else "%g" % lab, threshold))
        criteria[name] = threshold
        if why:
            scenario.criteria_why[name] = why
    return criteria


def criteria_reasons(path):
    """{criterion: why} of a scenario file's widened thresholds ({} when it has none or cannot
    be read: the report shows what it can)."""
    try:
        data = load_yaml(path)
    except (ConfigError, IOError, OSError):
        return {}
    crit = data.get("criteria") if isinstance(data, dict) else None
    return dict((k, str(v["why"])) for k, v in (crit or {}).items() if isinstance(v, dict) and "why" in v)


def load_scenario(path):
    """Read the scenario file `path` strictly. ConfigError "<file>: <key>: <problem>"."""
    r = Reader(load_yaml(path), path)
    r.check_keys(["description", "world", "robots", "mode", "leader", "formation", "spacing", "topology",
                  "controller", "localization", "leader_max_vel", "time_limit", "end", "timeline", "criteria"],
                 required=["world", "time_limit", "timeline"])
    s = Scenario()
    s.path = path
    s.name = os.path.basename(path)[:-len(".yaml")] if path.endswith(".yaml") else os.path.basename(path)
    s.description = r.optional("description", str, "")
    s.world = r.required("world", str, what="a world name (maps/NAME.world.yaml) or a path", check=lambda v: v != "")
    s.robots = r.optional("robots", int, None, what="an integer from 1 to %d (the number of robots)" % MAX_ROBOTS,
                          check=lambda v: 1 <= v <= MAX_ROBOTS)
    s.mode = r.optional("mode", str, "formation", what=" or ".join(MODES), check=lambda v: v in MODES)
    formation_keys = ("leader", "formation", "spacing", "topology", "controller", "leader_max_vel")
    if s.mode == "formation":
        from mbot_follower.control_laws import CONTROL_LAWS
        from mbot_follower.formations import FORMATION_NAMES

        s.leader = _name_arg(r, "leader", "a robot name") if "leader" in r else ""
        s.formation = r.required("formation", str, what="one of %s" % ", ".join(FORMATION_NAMES),
                                 check=lambda v: v in FORMATION_NAMES)
        s.spacing = r.required("spacing", float, what="a number > 0 [m]", check=lambda v: v > 0.0)
        s.topology = r.optional("topology", str, "star", what=" or ".join(TOPOLOGIES),
                                check=lambda v: v in TOPOLOGIES)
        s.controller = r.optional("controller", str, "slot_tracking",
                                  what="one of %s" % ", ".join(sorted(CONTROL_LAWS)),
                                  check=lambda v: v in CONTROL_LAWS)
        s.leader_max_vel = r.optional("leader_max_vel", float, 0.35, what="a number > 0 [m/s]", check=lambda v: v > 0.0)
    else:
        for key in formation_keys:
            if key in r:
                r.fail(key, "not used in dispatch mode (no formation: every robot has its own goal)")
        s.end = "goals_done"
    s.localization = r.optional("localization", str, "fake", what=" or ".join(LOCALIZATIONS),
                                check=lambda v: v in LOCALIZATIONS)
    s.time_limit = r.required("time_limit", float, what="a number > 0 [s sim]", check=lambda v: v > 0.0)
    s.end = r.optional("end", str, s.end, what="an event (%s)" % ", ".join(EVENTS), check=lambda v: v in EVENTS)

    steps = r.children("timeline")
    if not steps:
        r.fail("timeline", "expected at least one step")
    last_at = 0.0
    for i, sr in enumerate(steps):
        step = _read_step(sr, i, s.mode, s.time_limit)
        if step.at is not None:
            if step.at < last_at:
                sr.fail("at", "%g s is before the %g s of an earlier step: steps run in order" % (step.at, last_at))
            last_at = step.at
        s.timeline.append(step)
    if s.mode == "formation" and not s.steps("target"):
        r.fail("timeline", "a formation scenario needs at least one target step")
    if s.mode == "dispatch" and not s.steps("dispatch"):
        r.fail("timeline", "a dispatch scenario needs at least one dispatch step")
    s.criteria = _read_criteria(r, s.mode, s)
    r.finish()
    return s


def check_against_world(scenario, robot_names):
    """ConfigError when the scenario names a robot the run's world does not have, or its formation
    does not take that many robots. robot_names: the robots of the run (in world order)."""
    known = set(robot_names)
    for s in scenario.steps("spawn_robot"):
        known.add(s.arg["name"])
    for key, name in scenario.robot_names_used():
        if name not in known:
            raise ConfigError("%s: %s: no robot \"%s\" in the run (robots: %s)" % (
                scenario.path, key, name, ", ".join(robot_names)))
    if scenario.leader and scenario.leader not in robot_names:
        raise ConfigError("%s: leader: no robot \"%s\" in the run (robots: %s)" % (
            scenario.path, scenario.leader, ", ".join(robot_names)))
    if scenario.mode == "formation":
        from mbot_follower.formations import FormationError, make_formation

        checks = [("formation", scenario.formation, scenario.spacing)]
        checks += [("%s.do.formation" % s.key, s.arg["name"], s.arg["spacing"] or scenario.spacing)
                   for s in scenario.steps("formation")]
        for key, name, spacing in checks:
            try:
                make_formation(name, len(robot_names), spacing, scenario.topology)
            except FormationError as error:
                raise ConfigError("%s: %s: %s" % (scenario.path, key, error))


# --- the timeline ---------------------------------------------------------------------------

class Timeline(object):
    """The steps of a scenario against the events of a run; times are sim seconds after the start."""

    def __init__(self, scenario, config=None):
        self.steps = list(scenario.timeline)
        self.end_event = scenario.end
        self.time_limit = scenario.time_limit
        self.config = config or TimelineConfig()
        self.fired = []     # (Step, t)
        self.done_at = {}   # step index -> t its action returned (a service call takes sim time)
        self.events = []    # (name, t)

    def observe(self, name, t):
        """Record that event `name` happened at t [s]."""
        if name not in EVENTS:
            raise ValueError("unknown event %r (expected one of %s)" % (name, ", ".join(EVENTS)))
        self.events.append((name, t))

    def done(self, step, t):
        """Record that the action of `step` (fired before) returned at t [s]."""
        self.done_at[step.index] = t

    def _last_fired(self):
        return self.fired[-1][1] if self.fired else -math.inf

    def _event_since(self, name, since):
        """Time of the first `name` event after `since`, or None. An event at the very time a
        step ran counts as before it: that is the event the step itself waited for."""
        times = [t for (n, t) in self.events if n == name and t > since]
        return min(times) if times else None

    def _ready(self, step, t):
        if step.at is not None:
            return t >= step.at
        seen = self._event_since(step.after, self._last_fired())
        return seen is not None and t >= seen + step.delay

    def due(self, t):
        """The steps to carry out at t [s], in order (marked as run at t)."""
        out = []
        while len(self.fired) < len(self.steps):
            step = self.steps[len(self.fired)]
            if not self._ready(step, t):
                break
            self.fired.append((step, t))
            out.append(step)
        return out

    def next_step(self):
        """The step that waits, or None when every step has run."""
        return self.steps[len(self.fired)] if len(self.fired) < len(self.steps) else None

    def end_time(self):
        """When the end event came after the last step (None: not yet, or steps still wait)."""
        if self.next_step() is not None:
            return None
        return self._event_since(self.end_event, self._last_fired())

    def finished(self, t):
        """True once every step ran, the end event followed, and `settle` seconds passed."""
        end = self.end_time()
        return end is not None and t >= end + self.config.settle

    def timed_out(self, t):
        return t > self.time_limit


# --- criteria -------------------------------------------------------------------------------

def scenario_window(run, start, end):
    """The part of a metrics Run (mbot_follower.metrics) from `start` to `end` [s sim]: what the
    scenario's criteria judge, not the nodes starting up before the first step or shutting down
    after the end. Samples, events and controller cycles outside are left out; the state and the
    assignment in force at `start` are kept (as events at `start`); the controllers' lookup
    counters, which count from each controller's start, count from `start`."""
    from mbot_follower.metrics import Run

    out = Run(run.config)
    out.robots = list(run.robots)
    out.samples = [s for s in run.samples if start <= s.t <= end]
    before = {}
    for e in run.events:
        if e.t < start and e.kind in ("state", "assignment"):
            before[e.kind] = e._replace(t=start)
    out.events = sorted(before.values(), key=lambda e: e.kind != "state") + \
        [e for e in run.events if start <= e.t <= end]
    baseline = {}
    for c in run.controller:
        if c.t < start:
            baseline[c.robot] = (c.lookups, c.lookup_failures)
        elif c.t <= end:
            lookups, failures = baseline.get(c.robot, (0, 0))
            out.controller.append(c._replace(lookups=c.lookups - lookups, lookup_failures=c.lookup_failures - failures))
    return out


def _largest(values):
    """max of the values; None when there are none or one is None (that one never happened)."""
    if not values or any(v is None for v in values):
        return None
    return max(values)


def takes_a_robot_out(step):
    """Whether a step takes a robot out of the fleet: its controller killed, the robot removed, or
    a fault that freezes its drive (its motors fail) or silences it (no odom, tf or scan)."""
    return step.action in ("kill_controller", "remove_robot") or \
        (step.action == "fault" and (step.arg["drive_frozen"] or step.arg["silenced"]))


def loss_detection_times(timeline):
    """For every step that ran and takes a robot out (takes_a_robot_out): the time [s] from the
    step's action (when its call returned: the robot is out by then) to the next `degraded` event
    (None: never; 0 if that came first). What the coordinator's loss detection takes, seen from
    outside (the metrics' own time_to_degraded starts when the status already names the loss).
    Not from when the step fired: on a loaded machine the simulator's remove_robot service
    answered 1.35 s of sim time after the call."""
    out = []
    for step, t in timeline.fired:
        if takes_a_robot_out(step):
            later = [te for (name, te) in timeline.events if name == "degraded" and te >= t]
            out.append(max(0.0, min(later) - timeline.done_at.get(step.index, t)) if later else None)
    return out


def measure(name, summary, run, facts):
    """The value of criterion `name` for a run: summary = summarize(run) (metrics.json), run = the
    metrics Run, facts = what the runner saw ({arrived, finished, goals_reached, failed_steps,
    loss_detection_s: [s or None per loss step]})."""
    fleet = summary["fleet"]
    if name in fleet:
        return fleet[name]
    if name == "duration_s":
        return summary["duration_s"]
    if name == "max_switch_time_s":
        times = switch_done_times(run)   # the metrics' one rule (mbot_follower.metrics.settle)
        return _largest([s["switch_time_s"] for s in times]) if times else None
    if name == "max_time_to_degraded_s":
        return _largest([r["time_to_degraded_s"] for r in summary["recoveries"]]) if summary["recoveries"] else None
    if name == "max_recovery_time_s":
        return _largest([r["recovery_time_s"] for r in summary["recoveries"]]) if summary["recoveries"] else None
    if name == "max_loss_detection_s":
        times = facts.get("loss_detection_s", [])
        return _largest(times) if times else None
    if name in facts:
        return facts[name]
    raise KeyError("criterion %r: no value in the summary or the facts" % name)


def check(op, value, threshold):
    """True if `value op threshold` holds; a missing value (None, NaN) never passes."""
    if value is None or (isinstance(value, float) and math.isnan(value)):
        return False
    if op == "<=":
        return value <= threshold
    if op == ">=":
        return value >= threshold
    if op == "==":
        return value == threshold
    raise ValueError("unknown operator %r" % op)


def evaluate(criteria, summary, run, facts):
    """[{"name", "value", "threshold", "op", "passed"}] for every criterion, in CRITERIA order."""
    out = []
    for name in CRITERIA:
        if name not in criteria:
            continue
        op = CRITERIA[name][0]
        value = measure(name, summary, run, facts)
        out.append({"name": name, "value": value, "threshold": criteria[name], "op": op,
                    "passed": check(op, value, criteria[name])})
    return out


def format_value(value):
    if value is None:
        return "no data"
    if isinstance(value, bool):
        return "yes" if value else "no"
    if isinstance(value, float):
        return "%.4g" % value
    return str(value)


def summary_lines(name, results):
    """The one-screen summary: a line per criterion, PASS or FAIL, and the verdict."""
    lines = ["scenario %s:" % name]
    for c in results:
        lines.append("  %s  %-30s %10s %s %s" % ("PASS" if c["passed"] else "FAIL", c["name"],
                                                 format_value(c["value"]), c["op"], format_value(c["threshold"])))
    failed = [c["name"] for c in results if not c["passed"]]
    lines.append("PASSED (%d criteria)" % len(results) if not failed else
                 "FAILED: %s" % ", ".join(failed))
    return lines
