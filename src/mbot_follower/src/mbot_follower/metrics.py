"""Formation metrics: what the fleet did, measured in sim time, from plain samples.

`MetricsCollector` is fed with the contents of messages (ground-truth poses, the slot
assignment, the coordinator's status, the follower controllers' states, power, contacts, the
leader's plan) and keeps a `Run`:
  * one `Sample` at every multiple of 1/rate sim seconds, with the newest ground-truth pose of
    every robot at or before that time (taken when the first later pose arrives),
  * the `Event`s: state changes, assignments, switches (the formation changed; switch_done when
    the coordinator saw the new shape stand), pauses (start, end), losses, rejoins, contacts,
  * one `ControllerSample` per follower controller cycle.
`summarize(run)` turns a Run into the numbers of metrics.json. `RunWriter` writes a Run to
metrics.csv, events.csv, controller.csv and metrics.json; `load_run(output_dir)` reads them back
into the same Run, so a report computes the same summary offline. Nothing here knows ROS.

What the numbers mean (all times sim time unless marked wall):
  slot error        distance of a follower's ground-truth position from its slot, the slot being
                    leader pose (+) offset of the current assignment; for a formation along the
                    path (a column) the slot on the leader's ground-truth path since the
                    assignment (trail.path_slot), and the heading errors are to each slot's
                    heading. A lost robot (in the status' `lost`) is excluded while lost; so is
                    a robot without a fresh pose.
  fit error         the same after the best rigid fit (rotation + translation) of the desired
                    shape onto the actual positions (shape.rigid_fit): the shape alone.
  slot free         whether a follower's slot keeps slot_clearance to the walls of the map (1/0;
                    NaN without a map): a slot in a wall (a column's slots behind a corner, a
                    wide formation in a doorway) cannot be held, the follower drives the free
                    path instead (the leader's trail).
  steady slot RMS   the slot RMS restricted to NAVIGATING while the leader moves, and to ARRIVED;
                    while navigating, a follower's sample counts once its slot has been free
                    for free_hold (the time to get back from the trail). slot_blocked_share
                    says how much of the navigating time the slots were in walls. A follower
                    whose controller has gone silent for controller_silence (killed, before
                    the coordinator declares it lost) does not count: that error is the loss
                    detection time, measured by the recovery figures.
  leader lateral    distance of the leader from the polyline of its global plan (the newest one not
                    later than the leader's pose; a new goal, FORMING, forgets the old plans); the
                    summary counts it while the leader follows the plan (NAVIGATING, DEGRADED).
  latency           FollowerState header.stamp (command computed) - pose_stamp (the tf pose it
                    used) + one physics step (`physics_step`): the simulator applies a command at
                    its next step. Only cycles that used a pose (active) count.
  tf success rate   1 - lookup_failures / lookups, from the newest FollowerState of each robot.
  cycle time        the controller's computation time per cycle [ms wall], p99.
  clearance         robot-robot centre distance - 2 x robot_radius, over the samples.
  distance          path length of each robot's ground truth (jumps faster than teleport_speed
                    and gaps longer than stale_after are not travel).
  energy            integral of each robot's power over sim time: every power value holds until
                    the next one, for at most stale_after. [J] if power is in [W]. The power is
                    the power model (control_laws.energy_rate, energy_k_v, energy_k_w) of the
                    velocity each ground-truth pose carries: what the robot really does, whoever
                    commands it (its follower controller, its move_base, nothing).
  sampling          a sample at t uses every robot's newest pose not later than t (and not older
                    than stale_after). Each robot's poses come on their own topic, and a busy
                    machine delivers one stream later than another (at real_time_factor 0 a
                    tenth of a wall second is seconds of sim time), so the sample at t waits
                    until every robot's stream has passed t; a stream more than hold_back
                    behind the newest pose (a removed robot) is not waited for.
  time in state     sim time between the coordinator's state changes, the last one up to the end.
  recovery          per loss (the status shows a new `lost` member at t0): time from t0 to the
                    state DEGRADED (0 if it already was), and the time from t0 until the slot RMS
                    falls under recovered_rms and then stays under it for recovered_hold.

Offline: `/usr/bin/python3 -m mbot_follower.metrics OUTPUT_DIR` prints the summary of a run.
"""
import argparse
import bisect
import csv
import json
import math
import os
import sys
from collections import namedtuple

import numpy as np

from mbot_common.geometry import Twist2D
from mbot_follower.control_laws import energy_rate
from mbot_follower.shape import ShapeErrors, rigid_fit, shape_errors
from mbot_follower.trail import Trail, slot_pose

NAN = float("nan")
PLAN_STATES = ("NAVIGATING", "DEGRADED")   # the leader follows its global plan

#: One robot in one sample. x, y [m] and theta [rad] in map (NaN: no fresh pose);
#: slot_error, fit_error [m] (NaN: not a measured follower); distance [m] and energy [J] so far.
#: slot_free: 1.0 / 0.0 if the slot is / is not free in the map, NaN when unknown.
RobotSample = namedtuple("RobotSample", "x y theta slot_error fit_error distance energy slot_free",
                         defaults=(NAN,))

#: The fleet at one sample time t [s]. Errors in [m] (heading_max [rad]), NaN when nothing was
#: measured; lost: tuple of names; clearance_pair: "a b" of the closest robots ("" if < 2 robots);
#: robots: {name: RobotSample} of every robot known at that time.
Sample = namedtuple("Sample", "t state leader formation lost slot_rms slot_max fit_rms fit_max "
                              "edge_max heading_max leader_lateral min_clearance clearance_pair robots")

#: Something that happened at t [s]. kind / name / detail:
#:   state / new state / reason        assignment / formation / "leader L spacing S m [along_path] slots ..."
#:   switch / new formation / old one  loss, rejoin / robot / ""
#:   switch_done / formation / reason  pause / "start" or "end" / the coordinator's reason
#:   contact / body_a / body_b, at x, y [m] (NaN for the other kinds)
Event = namedtuple("Event", "t kind name detail x y")

#: One follower controller cycle: t [s] when the command was computed, latency [s] (NaN if the
#: cycle used no pose), cycle_time_ms [ms wall], the controller's lookup counters, its mode, and
#: its overrun counters so far: cycles that took longer than the period, cycles that started a
#: period or more late.
ControllerSample = namedtuple("ControllerSample", "t robot latency cycle_time_ms lookups lookup_failures mode "
                              "overruns late_starts", defaults=(0, 0))


class MetricsConfig(object):
    """Parameters of the metrics (the node reads them from its private parameters)."""

    def __init__(self, rate=10.0, physics_step=0.01, recovered_rms=0.15, recovered_hold=1.0,
                 robot_radius=0.15, stale_after=1.0, moving_speed=0.05, teleport_speed=5.0, hold_back=5.0,
                 slot_clearance=0.25, free_hold=3.0, controller_silence=0.5, energy_k_v=4.0, energy_k_w=0.5):
        self.rate = rate                      # samples per sim second [Hz]
        self.physics_step = physics_step      # added to every latency: a command acts at the next step [s]
        self.recovered_rms = recovered_rms    # slot RMS under which the fleet has recovered from a loss [m]
        self.recovered_hold = recovered_hold  # ... and must stay under it this long [s]
        self.robot_radius = robot_radius      # clearance = centre distance - 2 radii [m]
        self.stale_after = stale_after        # an older pose is not used; power holds at most this long [s]
        self.moving_speed = moving_speed      # a leader faster than this is moving [m/s]
        self.teleport_speed = teleport_speed  # a faster jump between two poses is a teleport, not travel [m/s]
        self.hold_back = hold_back            # a sample waits this long for a late robot's poses [s]
        self.slot_clearance = slot_clearance  # a slot closer than this to a wall is not free [m]
        self.free_hold = free_hold            # a slot free this long counts in the steady RMS [s]
        self.controller_silence = controller_silence  # a controller unheard this long is gone [s]
        # the power model (control_laws.energy_rate) of every robot's measured velocity [W/(m/s)^2, W/(rad/s)^2]
        self.energy_k_v = energy_k_v
        self.energy_k_w = energy_k_w
        self.check()

    def check(self):
        """ValueError naming the first bad value (every value must be a finite number)."""
        limits = [("rate", 0.0, False), ("physics_step", 0.0, True), ("recovered_rms", 0.0, False),
                  ("recovered_hold", 0.0, True), ("robot_radius", 0.0, True), ("stale_after", 0.0, False),
                  ("moving_speed", 0.0, True), ("teleport_speed", 0.0, False), ("hold_back", 0.0, True),
                  ("slot_clearance", 0.0, True), ("free_hold", 0.0, True), ("controller_silence", 0.0, False),
                  ("energy_k_v", 0.0, True), ("energy_k_w", 0.0, True)]
        for key, low, low_ok in limits:
            value = getattr(self, key)
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or value < low or (value == low and not low_ok):
                raise ValueError("metrics config: %s: expected a finite number %s %g, got %r"
                                 % (key, ">=" if low_ok else ">", low, value))

    def to_dict(self):
        return dict(vars(self))

    @classmethod
    def from_dict(cls, values, where="metrics config"):
        unknown = sorted(set(values) - set(vars(cls())))
        if unknown:
            raise ValueError("%s: unknown key(s) %s (known: %s)"
                             % (where, ", ".join(unknown), ", ".join(sorted(vars(cls())))))
        return cls(**values)


class Run(object):
    """Everything one run measured: samples, events, controller cycles, in arrival order."""

    def __init__(self, config=None):
        self.config = config or MetricsConfig()
        self.robots = []       # every robot seen, in order of appearance (the CSV columns)
        self.samples = []      # Sample
        self.events = []       # Event
        self.controller = []   # ControllerSample

    def snapshot(self):
        """A copy that later appends do not change (the entries themselves are immutable)."""
        copy = Run(self.config)
        copy.robots, copy.samples = list(self.robots), list(self.samples)
        copy.events, copy.controller = list(self.events), list(self.controller)
        return copy


def distance_to_polyline(x, y, points):
    """Distance [m] of the point (x, y) from the polyline through points (n, 2), n >= 1."""
    pts = np.asarray(points, dtype=float).reshape(-1, 2)
    if len(pts) == 0:
        raise ValueError("distance_to_polyline: the polyline has no points")
    p = np.array([x, y], dtype=float)
    if len(pts) == 1:
        return float(np.hypot(*(p - pts[0])))
    a, ab = pts[:-1], pts[1:] - pts[:-1]
    length2 = np.sum(ab * ab, axis=1)
    # Position of the nearest point along each segment, 0..1 (a zero-length segment: its start).
    u = np.divide(np.sum((p - a) * ab, axis=1), length2, out=np.zeros(len(a)), where=length2 > 0)
    nearest = a + np.clip(u, 0.0, 1.0)[:, None] * ab
    return float(np.min(np.hypot(*(p - nearest).T)))


class MetricsCollector(object):
    """Builds a Run from message contents; every `on_*` takes the sim time t [s] of its message."""

    def __init__(self, config=None, free_space=None):
        self.config = config or MetricsConfig()
        self.run = Run(self.config)
        self.free_space = free_space   # free_space.FreeSpace of the map (slot_clearance), None: no map yet
        self.assignment = None   # fleet_io.Assignment (or anything with .leader .formation .spacing .slots)
        self.state = ""          # coordinator state, "" before the first status
        self.lost = ()           # robots the status reports lost
        self.paused = False      # the status says the fleet is paused
        self.switching = False   # the status says a formation switch is under way
        self.poses = {}          # robot -> (t, x, y, theta): the newest ground truth
        self.history = {}        # robot -> [(t, x, y, theta, distance)] of the last hold_back + stale_after seconds
        self.distance = {}       # robot -> path length so far [m]
        self.energy = {}         # robot -> energy so far [J]
        self.power = {}          # robot -> (t, power [W]) of the newest power message
        self.plans = {}          # robot -> [(t, (n, 2) array or None)]: its global plans in map, in arrival order
        # (t, assignment) and (t, state, lost) in arrival order: a sample at t uses the newest
        # one not later than t. A message stamped after the sample time may arrive before the
        # pose that triggers the sample (the coordinator sends a new assignment, then its status).
        self._assignments = []
        self._statuses = []
        self._next_tick = None   # the next sample is at _next_tick / rate [s]
        # The leader's ground-truth path at the sample times since the assignment in force
        # (_trail_of), for the slots of a formation along the path.
        self._trail = Trail()
        self._trail_of = None

    def _know(self, robot):
        if robot not in self.distance:
            self.run.robots.append(robot)
            self.distance[robot] = 0.0
            self.energy[robot] = 0.0

    # --- inputs -------------------------------------------------------------------------

    def on_pose(self, robot, t, x, y, theta, twist=None):
        """A ground-truth pose in map, with its body-frame velocity `twist` (vx, vy, wz) when
        known (its power, module docstring: energy); then every sample whose time all robots'
        streams have passed (module docstring: sampling)."""
        self._know(robot)
        previous = self.poses.get(robot)
        if previous is not None and t < previous[0]:
            return   # older than what we have: arrived out of order
        if twist is not None:
            self.on_power(robot, t, energy_rate(Twist2D(*twist), self.config.energy_k_v, self.config.energy_k_w))
        if previous is not None and 0.0 < t - previous[0] <= self.config.stale_after:
            step = math.hypot(x - previous[1], y - previous[2])
            if step <= self.config.teleport_speed * (t - previous[0]):
                self.distance[robot] += step
        self.poses[robot] = (t, x, y, theta)
        history = self.history.setdefault(robot, [])
        history.append((t, x, y, theta, self.distance[robot]))
        keep = self.config.hold_back + self.config.stale_after + 1.0
        if history[0][0] < t - 2.0 * keep:   # trim now and then, not on every pose
            del history[:next(i for i, h in enumerate(history) if h[0] >= t - keep)]
        ticks = t * self.config.rate   # sample times are whole ticks: k / rate
        if self._next_tick is None:
            self._next_tick = int(math.ceil(ticks - 1e-6))
        self._take_samples()

    def _take_samples(self):
        newest = max(p[0] for p in self.poses.values())
        # After a gap (e.g. a reset) the next sample is the first tick the fleet's poses can fill.
        first = int(math.ceil((newest - self.config.hold_back - self.config.stale_after) * self.config.rate - 1e-6))
        self._next_tick = max(self._next_tick, first)
        while True:
            t = self._next_tick / self.config.rate
            if newest <= t + 1e-9:
                return   # nobody has passed t yet
            waiting = [p for p in self.poses.values() if p[0] <= t + 1e-9 and newest - p[0] <= self.config.hold_back]
            if waiting:
                return   # a late stream may still bring its pose at t
            self.run.samples.append(self.sample(t))
            self._next_tick += 1

    def _pose_at(self, robot, t):
        """(t, x, y, theta, distance so far): the robot's newest pose not later than t, or None."""
        for entry in reversed(self.history.get(robot, ())):
            if entry[0] <= t + 1e-9:
                return entry
        return None

    def on_assignment(self, t, assignment):
        """A new slot assignment (leader, formation, spacing, slots {robot: (x, y)} in the leader frame)."""
        old = self.assignment
        self.assignment = assignment
        self._assignments.append((t, assignment))
        for robot in [assignment.leader] + sorted(assignment.slots):
            self._know(robot)
        slots = " ".join("%s(%g,%g)" % (r, assignment.slots[r][0], assignment.slots[r][1])
                         for r in sorted(assignment.slots))
        path = " along_path" if getattr(assignment, "along_path", False) else ""
        self.run.events.append(Event(t, "assignment", assignment.formation, "leader %s spacing %g m%s slots %s"
                                     % (assignment.leader, assignment.spacing, path, slots), NAN, NAN))
        if old is not None and old.formation != assignment.formation:
            self.run.events.append(Event(t, "switch", assignment.formation, old.formation, NAN, NAN))

    def on_status(self, t, state, reason, lost, paused=False, switching=False):
        """The coordinator's status: records state changes, new losses and rejoins, the start and
        end of a pause (paused) and the end of a switch (switching goes off: the coordinator saw
        the new shape stand). A pause keeps the state NAVIGATING: its events are what records it."""
        if paused != self.paused:
            self.run.events.append(Event(t, "pause", "start" if paused else "end", reason, NAN, NAN))
            self.paused = paused
        if self.switching and not switching:
            self.run.events.append(Event(t, "switch_done", self.assignment.formation if self.assignment else "",
                                         reason, NAN, NAN))
        self.switching = switching
        if state != self.state:
            self.run.events.append(Event(t, "state", state, reason, NAN, NAN))
            self.state = state
            if state == "FORMING":
                # A new goal: the plans of the old one no longer say where the leader should
                # drive; the lateral error waits for the new goal's plan.
                for plans in self.plans.values():
                    plans.append((t, None))
        lost = tuple(lost)
        self._statuses.append((t, state, lost))
        for robot in lost:
            if robot not in self.lost:
                self.run.events.append(Event(t, "loss", robot, "", NAN, NAN))
        for robot in self.lost:
            if robot not in lost:
                self.run.events.append(Event(t, "rejoin", robot, "", NAN, NAN))
        self.lost = lost

    def on_follower_state(self, robot, t, pose_stamp, active, lookups, lookup_failures, cycle_time, mode,
                          overruns=0, late_starts=0):
        """One follower controller cycle: t and pose_stamp [s sim], cycle_time [s wall], the
        overrun counters so far. Its latency is t - pose_stamp + physics_step (the simulator
        applies the command at its next step)."""
        self._know(robot)
        latency = t - pose_stamp + self.config.physics_step if active and pose_stamp > 0.0 else NAN
        self.run.controller.append(ControllerSample(t, robot, latency, 1000.0 * cycle_time,
                                                    int(lookups), int(lookup_failures), mode,
                                                    int(overruns), int(late_starts)))

    def on_power(self, robot, t, power):
        """The energy model's rate [W] of a robot; it holds until the next one (at most stale_after)."""
        self._know(robot)
        previous = self.power.get(robot)
        if previous is not None and t > previous[0]:
            self.energy[robot] += previous[1] * min(t - previous[0], self.config.stale_after)
        self.power[robot] = (t, power)

    def on_contact(self, t, body_a, body_b, x, y):
        self.run.events.append(Event(t, "contact", body_a, body_b, x, y))

    def on_plan(self, robot, t, points):
        """A robot's global plan in map: points (n, 2); an empty plan clears it."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        self.plans.setdefault(robot, []).append((t, points if len(points) else None))

    # --- one sample -----------------------------------------------------------------------

    @staticmethod
    def _in_force(history, t):
        """The newest entry of history (tuples starting with their time) not later than t, or
        None; older entries are dropped (samples come in time order)."""
        current = None
        for k, entry in enumerate(history):
            if entry[0] <= t + 1e-9 and (current is None or entry[0] >= history[current][0]):
                current = k
        if current is None:
            return None
        del history[:current]
        return history[0]

    def sample(self, t):
        """A Sample of the fleet at t from the newest fresh pose of every robot, with the
        assignment and the status in force at t."""
        at_t = {r: self._pose_at(r, t) for r in self.poses}
        at_t = {r: p for r, p in at_t.items() if p is not None and t - p[0] <= self.config.stale_after}
        fresh = {r: p[1:4] for r, p in at_t.items()}
        # The coordinator stamps a decision's assignment and status alike, but they come on two
        # topics: a sample taken between them would see the new slots under the old state (a
        # loss: the survivors' new slots counted as NAVIGATING errors). An assignment counts once
        # the status of its time is here.
        decided = min(t, self._statuses[-1][0]) if self._statuses else t
        entry = self._in_force(self._assignments, decided)
        a, entry_t = (entry[1], entry[0]) if entry is not None else (None, None)
        entry = self._in_force(self._statuses, t)
        state, lost = (entry[1], entry[2]) if entry is not None else ("", ())
        slot_error, fit_error, slot_free = {}, {}, {}
        errors = ShapeErrors(NAN, NAN, NAN, NAN, NAN, NAN)   # no follower measured
        lateral = NAN
        leader = a.leader if a is not None else ""
        if a is not None and leader in fresh and leader not in lost:
            lx, ly, lth = fresh[leader]
            self._follow_leader(a, entry_t, leader, (lx, ly, lth))
            trail = self._trail if getattr(a, "along_path", False) else None
            followers = sorted(r for r in a.slots if r != leader and r not in lost and r in fresh)
            if followers:
                actual = [(lx, ly)] + [fresh[r][:2] for r in followers]
                slots = [slot_pose((lx, ly, lth), a.slots.get(leader, (0.0, 0.0)), trail)]
                slots += [slot_pose((lx, ly, lth), a.slots[r], trail) for r in followers]
                desired = [(p.x, p.y) for p in slots]
                errors = shape_errors(actual, desired, headings=[lth] + [fresh[r][2] for r in followers],
                                      desired_headings=[p.theta for p in slots])
                _, _, fitted = rigid_fit(actual, desired)
                for i, r in enumerate(followers, start=1):
                    slot_error[r] = math.hypot(actual[i][0] - desired[i][0], actual[i][1] - desired[i][1])
                    fit_error[r] = math.hypot(actual[i][0] - fitted[i][0], actual[i][1] - fitted[i][1])
                    if self.free_space is not None:
                        slot_free[r] = 1.0 if self.free_space.is_free(*desired[i]) else 0.0
            # The plan in force when the leader was where its pose says: under load the 100 Hz
            # ground truth may lag behind the plans, and a plan that starts ahead of an old pose
            # is not the leader's lateral error.
            entry = self._in_force(self.plans.get(leader, []), at_t[leader][0])
            if entry is not None and entry[1] is not None:
                lateral = distance_to_polyline(lx, ly, entry[1])
        clearance, pair = NAN, ""
        names = sorted(fresh)
        for i, r in enumerate(names):
            for s in names[i + 1:]:
                c = math.hypot(fresh[r][0] - fresh[s][0], fresh[r][1] - fresh[s][1]) - 2.0 * self.config.robot_radius
                if pair == "" or c < clearance:
                    clearance, pair = c, "%s %s" % (r, s)
        robots = {}
        for r in self.run.robots:
            x, y, theta = fresh.get(r, (NAN, NAN, NAN))
            distance = at_t[r][4] if r in at_t else self.distance[r]
            robots[r] = RobotSample(x, y, theta, slot_error.get(r, NAN), fit_error.get(r, NAN), distance,
                                    self.energy[r], slot_free.get(r, NAN))
        return Sample(t, state, leader, a.formation if a is not None else "", lost,
                      errors.rms, errors.max, errors.fit_rms, errors.fit_max, errors.edge_max,
                      errors.heading_max, lateral, clearance, pair, robots)

    def _follow_leader(self, a, since, leader, pose):
        """Record the leader's pose on its trail; a new assignment `a` (in force since `since`)
        starts the trail where the leader was then."""
        if a is not self._trail_of:
            start = self._pose_at(leader, since)
            self._trail.start(*(start[1:4] if start is not None else pose))
            self._trail_of = a
        self._trail.add(pose[0], pose[1])


# --- the summary ----------------------------------------------------------------------------

def _number(value):
    """A float for JSON: None for NaN (no data)."""
    value = float(value)
    return value if math.isfinite(value) else None


def _finite(values):
    v = np.asarray(values, dtype=float)
    return v[np.isfinite(v)]


def finite_rms(values):
    """RMS of the finite values; None when there are none."""
    v = _finite(values)
    return _number(np.sqrt(np.mean(v * v))) if len(v) else None


def _stats(values, prefix, unit, rms=False, percentiles=()):
    """{prefix_rms_unit, prefix_pNN_unit..., prefix_max_unit} of the finite values (None: none).
    Percentiles interpolate linearly between the sorted values (numpy's default)."""
    v = _finite(values)
    out = {}
    if rms:
        out["%s_rms_%s" % (prefix, unit)] = finite_rms(v)
    for p in percentiles:
        out["%s_p%d_%s" % (prefix, p, unit)] = _number(np.percentile(v, p)) if len(v) else None
    out["%s_max_%s" % (prefix, unit)] = _number(np.max(v)) if len(v) else None
    return out


def _controller_stats(rows):
    """Latency p50/p95/max, tf success rate (newest counters per robot), cycle time p99 and the
    overruns and late starts (newest counters per robot, summed)."""
    newest = {}
    for row in rows:
        newest[row.robot] = row
    lookups = sum(r.lookups for r in newest.values())
    failures = sum(r.lookup_failures for r in newest.values())
    out = _stats([r.latency for r in rows], "latency", "s", percentiles=(50, 95))
    out["tf_success_rate"] = 1.0 - failures / float(lookups) if lookups > 0 else None
    out["cycle_time_p99_ms"] = _stats([r.cycle_time_ms for r in rows], "cycle_time", "ms",
                                      percentiles=(99,))["cycle_time_p99_ms"]
    # beside the cycle time: how often a controller missed its period (newest counters per robot)
    out["cycle_overruns"] = sum(r.overruns for r in newest.values())
    out["cycle_late_starts"] = sum(r.late_starts for r in newest.values())
    return out


def run_span(run):
    """(start, end) sim time [s] of everything in the run; (0, 0) when it is empty."""
    times = [s.t for s in run.samples] + [e.t for e in run.events] + [c.t for c in run.controller]
    return (min(times), max(times)) if times else (0.0, 0.0)


def time_in_states(events, end):
    """{state: seconds} from the state events (sorted by time) up to `end` [s]."""
    changes = sorted((e for e in events if e.kind == "state"), key=lambda e: e.t)
    spent = {}
    for e, after in zip(changes, changes[1:] + [None]):
        until = after.t if after is not None else max(end, e.t)
        spent[e.name] = spent.get(e.name, 0.0) + (until - e.t)
    return spent


def state_at(events, t):
    """The coordinator state at t [s] from the state events ("" before the first)."""
    state = ""
    for e in sorted((e for e in events if e.kind == "state"), key=lambda e: e.t):
        if e.t > t:
            break
        state = e.name
    return state


def _holds_under(samples, i, bound, hold):
    """True if the slot RMS of samples[i] and of every sample up to hold [s] later is under
    bound [m], and the samples reach that far (NaN, no follower measured, is not under)."""
    for j in range(i, len(samples)):
        w = samples[j]
        if w.t > samples[i].t + hold + 1e-9:
            return True
        if not w.slot_rms < bound:
            return False
        if w.t >= samples[i].t + hold - 1e-9:
            return True
    return False


def recoveries(run):
    """One dict per loss: robot, t_s, time_to_degraded_s, recovery_time_s (None: never)."""
    config = run.config
    out = []
    for loss in (e for e in run.events if e.kind == "loss"):
        degraded = None
        if state_at(run.events, loss.t) == "DEGRADED":
            degraded = 0.0
        else:
            later = [e.t for e in run.events if e.kind == "state" and e.name == "DEGRADED" and e.t >= loss.t]
            degraded = min(later) - loss.t if later else None
        recovered = None
        samples = [s for s in run.samples if s.t >= loss.t]
        for i, s in enumerate(samples):
            if _holds_under(samples, i, config.recovered_rms, config.recovered_hold):
                recovered = s.t - loss.t
                break
        out.append({"robot": loss.name, "t_s": loss.t, "time_to_degraded_s": degraded,
                    "recovery_time_s": recovered})
    return out


def leader_speed(before, now):
    """Speed [m/s] of now's leader between two samples; 0 if unknown (no pose, new leader)."""
    leader = now.leader
    if not leader or leader != before.leader or now.t <= before.t \
            or leader not in now.robots or leader not in before.robots:
        return 0.0
    a, b = before.robots[leader], now.robots[leader]
    speed = math.hypot(b.x - a.x, b.y - a.y) / (now.t - before.t)
    return speed if math.isfinite(speed) else 0.0


def _controller_silent(times, t, config):
    """Whether a controller heard at the sorted times has been silent at t for controller_silence
    (one never heard is not: it may not publish at all)."""
    k = bisect.bisect_right(times, t + 1e-9)
    return k > 0 and t - times[k - 1] >= config.controller_silence


def summarize(run):
    """The summary of a Run: a JSON-ready dict (units in the key names, None = no data)."""
    config = run.config
    start, end = run_span(run)
    controller = {r: [] for r in run.robots}
    for c in run.controller:
        controller.setdefault(c.robot, []).append(c)
    robots = {}
    pooled_slot, pooled_fit = [], []
    for r in run.robots:
        track = [s.robots[r] for s in run.samples if r in s.robots]
        slot = [rs.slot_error for rs in track]
        fit = [rs.fit_error for rs in track]
        pooled_slot += slot
        pooled_fit += fit
        entry = {"slot_samples": len(_finite(slot))}
        entry.update(_stats(slot, "slot", "m", rms=True, percentiles=(95,)))
        entry.update(_stats(fit, "fit", "m", rms=True, percentiles=(95,)))
        entry.update(_controller_stats(controller[r]))
        entry["distance_m"] = track[-1].distance if track else 0.0
        entry["energy_j"] = track[-1].energy if track else 0.0
        robots[r] = entry

    # Steady errors: ARRIVED, and NAVIGATING while the leader moves (its speed from this sample
    # and the one before) for the followers whose slots have been free for free_hold and whose
    # controllers are alive.
    heard = {r: sorted(c.t for c in cs) for r, cs in controller.items()}
    navigating, arrived = [], []
    blocked_since = {}   # robot -> time of its slot's newest blocked sample
    moving_samples = blocked_samples = 0
    for i, s in enumerate(run.samples):
        for r, rs in s.robots.items():
            if rs.slot_free == 0.0:
                blocked_since[r] = s.t
        followers = {r: rs for r, rs in s.robots.items()
                     if math.isfinite(rs.slot_error) and not _controller_silent(heard.get(r, ()), s.t, config)}
        if s.state == "ARRIVED":
            arrived += [rs.slot_error for rs in followers.values()]
        elif s.state == "NAVIGATING" and i > 0 and leader_speed(run.samples[i - 1], s) > config.moving_speed:
            for r, rs in followers.items():
                moving_samples += 1
                if s.t - blocked_since.get(r, -math.inf) >= config.free_hold - 1e-9:
                    navigating.append(rs.slot_error)
                if rs.slot_free == 0.0:
                    blocked_samples += 1

    fleet = {"slot_samples": len(_finite(pooled_slot))}
    fleet.update(_stats(pooled_slot, "slot", "m", rms=True, percentiles=(95,)))
    fleet.update(_stats(pooled_fit, "fit", "m", rms=True, percentiles=(95,)))
    fleet["steady_navigating_slot_rms_m"] = finite_rms(navigating)
    fleet["steady_arrived_slot_rms_m"] = finite_rms(arrived)
    fleet["slot_blocked_share"] = blocked_samples / moving_samples if moving_samples else None
    lateral = [s.leader_lateral for s in run.samples if s.state in PLAN_STATES]
    fleet.update(_stats(lateral, "leader_lateral", "m", rms=True))
    fleet.update(_controller_stats(run.controller))
    closest = None
    for s in run.samples:
        if math.isfinite(s.min_clearance) and (closest is None or s.min_clearance < closest.min_clearance):
            closest = s
    fleet["min_clearance_m"] = closest.min_clearance if closest else None
    fleet["min_clearance_t_s"] = closest.t if closest else None
    fleet["min_clearance_pair"] = closest.clearance_pair if closest else None
    fleet["distance_m"] = sum(e["distance_m"] for e in robots.values())
    fleet["energy_j"] = sum(e["energy_j"] for e in robots.values())
    contacts = [e for e in run.events if e.kind == "contact"]
    fleet["contacts"] = len(contacts)
    fleet["switches"] = sum(1 for e in run.events if e.kind == "switch")
    fleet["losses"] = sum(1 for e in run.events if e.kind == "loss")
    fleet["rejoins"] = sum(1 for e in run.events if e.kind == "rejoin")
    fleet["time_in_state_s"] = time_in_states(run.events, end)
    return {
        "start_s": start,
        "duration_s": end - start,
        "samples": len(run.samples),
        "state": state_at(run.events, end),
        "fleet": fleet,
        "robots": robots,
        "recoveries": recoveries(run),
        "contact_list": [{"t_s": e.t, "body_a": e.name, "body_b": e.detail, "x_m": e.x, "y_m": e.y}
                         for e in contacts],
        "config": config.to_dict(),
    }


# --- files ----------------------------------------------------------------------------------

SAMPLE_COLUMNS = ["t_s", "state", "leader", "formation", "lost", "slot_rms_m", "slot_max_m", "fit_rms_m",
                  "fit_max_m", "edge_max_m", "heading_max_rad", "leader_lateral_m", "min_clearance_m",
                  "clearance_pair"]
ROBOT_COLUMNS = ["x_m", "y_m", "theta_rad", "slot_error_m", "fit_error_m", "distance_m", "energy_j", "slot_free"]
#: what runs recorded before slot_free have
OLD_ROBOT_COLUMNS = ROBOT_COLUMNS[:-1]
EVENT_COLUMNS = ["t_s", "kind", "name", "detail", "x_m", "y_m"]
CONTROLLER_COLUMNS = ["t_s", "robot", "latency_s", "cycle_time_ms", "lookups", "lookup_failures", "mode",
                      "overruns", "late_starts"]
FILES = ("metrics.csv", "events.csv", "controller.csv", "metrics.json")


def _cell(value):
    """A CSV cell: floats exactly (repr), NaN as an empty cell."""
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ""
    return str(value)


def sample_columns(robots):
    """metrics.csv's header: the fleet columns, then ROBOT_COLUMNS of each robot as "<robot>/<column>"."""
    return SAMPLE_COLUMNS + ["%s/%s" % (r, c) for r in robots for c in ROBOT_COLUMNS]


def _sample_row(sample, robots):
    row = [sample.t, sample.state, sample.leader, sample.formation, " ".join(sample.lost), sample.slot_rms,
           sample.slot_max, sample.fit_rms, sample.fit_max, sample.edge_max, sample.heading_max,
           sample.leader_lateral, sample.min_clearance, sample.clearance_pair]
    for r in robots:
        row += list(sample.robots[r]) if r in sample.robots else [NAN] * len(ROBOT_COLUMNS)
    return [_cell(v) for v in row]


class RunWriter(object):
    """Writes a Run into output_dir: the CSV files grow by the rows that are new since the last
    write (metrics.csv is written again whole when a robot appears: it adds columns);
    metrics.json is replaced atomically, so a killed run always leaves a complete one."""

    def __init__(self, output_dir):
        self.output_dir = output_dir
        try:
            os.makedirs(output_dir, exist_ok=True)
        except OSError as error:
            raise OSError("metrics output_dir %s: cannot create it: %s" % (output_dir, error.strerror))
        if not os.access(output_dir, os.W_OK):
            raise OSError("metrics output_dir %s: not writable" % output_dir)
        self.written = {}        # file -> rows written
        self.columns = None      # metrics.csv's current header

    def path(self, name):
        return os.path.join(self.output_dir, name)

    def _append(self, name, header, items, convert):
        """Write the items that are new since the last write (all of them, with the header, the first time)."""
        done = self.written.get(name)
        with open(self.path(name), "a" if done is not None else "w", newline="") as f:
            out = csv.writer(f)
            if done is None:
                out.writerow(header)
                done = 0
            out.writerows(convert(item) for item in items[done:])
        self.written[name] = len(items)

    def write(self, run, summary):
        """The run's new rows; metrics.json too unless `summary` is None."""
        columns = sample_columns(run.robots)
        if columns != self.columns:
            self.written.pop("metrics.csv", None)   # new columns: write it again from the start
            self.columns = columns
        self._append("metrics.csv", columns, run.samples, lambda s: _sample_row(s, run.robots))
        self._append("events.csv", EVENT_COLUMNS, run.events, lambda e: [_cell(v) for v in e])
        self._append("controller.csv", CONTROLLER_COLUMNS, run.controller, lambda c: [_cell(v) for v in c])
        if summary is None:
            return
        tmp = self.path("metrics.json.tmp")
        with open(tmp, "w") as f:
            json.dump(summary, f, indent=1)
            f.write("\n")
        os.replace(tmp, self.path("metrics.json"))


class RunFileError(ValueError):
    """A run file that cannot be read back; the message names the file, the line and the problem."""


def _read_csv(path, expected=None):
    """(header, rows) of a CSV file; RunFileError if missing or if its header is not `expected`."""
    if not os.path.isfile(path):
        raise RunFileError("%s: missing (a metrics run folder holds %s)" % (path, ", ".join(FILES)))
    with open(path, newline="") as f:
        rows = list(csv.reader(f))
    if not rows:
        raise RunFileError("%s: empty, expected a header line" % path)
    header = rows[0]
    if expected is not None and header != expected:
        raise RunFileError("%s: line 1: expected the columns %s, got %s" % (path, ",".join(expected), ",".join(header)))
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise RunFileError("%s: line %d: %d cells, expected %d" % (path, number, len(row), len(header)))
    return header, rows[1:]


def _float(path, number, column, text):
    if text == "":
        return NAN
    try:
        return float(text)
    except ValueError:
        raise RunFileError("%s: line %d: %s: expected a number, got %r" % (path, number, column, text))


def _int(path, number, column, text):
    try:
        return int(text)
    except ValueError:
        raise RunFileError("%s: line %d: %s: expected an integer, got %r" % (path, number, column, text))


def load_run(output_dir):
    """The Run that a RunWriter wrote into output_dir (metrics.csv, events.csv, controller.csv;
    the config from metrics.json when it is there, else the default one)."""
    config = MetricsConfig()
    json_path = os.path.join(output_dir, "metrics.json")
    if os.path.isfile(json_path):
        try:
            with open(json_path) as f:
                config = MetricsConfig.from_dict(json.load(f).get("config", {}), json_path + ": config")
        except (ValueError, TypeError, AttributeError) as error:
            raise RunFileError("%s: %s" % (json_path, error))
    run = Run(config)

    path = os.path.join(output_dir, "metrics.csv")
    header, rows = _read_csv(path)
    if header[:len(SAMPLE_COLUMNS)] != SAMPLE_COLUMNS:
        raise RunFileError("%s: line 1: expected the columns to start with %s" % (path, ",".join(SAMPLE_COLUMNS)))
    robot_columns = header[len(SAMPLE_COLUMNS):]
    run.robots, per_robot = None, None
    for columns in (ROBOT_COLUMNS, OLD_ROBOT_COLUMNS):   # an old run has no slot_free: NaN (unknown)
        names = [c.rsplit("/", 1)[0] for c in robot_columns[::len(columns)]]
        if robot_columns == ["%s/%s" % (r, c) for r in names for c in columns]:
            run.robots, per_robot = names, columns
            break
    if per_robot is None:
        raise RunFileError("%s: line 1: expected %s for every robot after the fleet columns, got %s"
                           % (path, ",".join("<robot>/" + c for c in ROBOT_COLUMNS), ",".join(robot_columns)))
    n = len(SAMPLE_COLUMNS)
    for number, row in enumerate(rows, start=2):
        def num(i):
            return _float(path, number, header[i], row[i])
        robots = {}
        for k, r in enumerate(run.robots):
            cells = range(n + k * len(per_robot), n + (k + 1) * len(per_robot))
            if any(row[i] != "" for i in cells):   # all empty: the robot was not known yet
                robots[r] = RobotSample(*[num(i) for i in cells])
        run.samples.append(Sample(num(0), row[1], row[2], row[3], tuple(row[4].split()), num(5), num(6),
                                  num(7), num(8), num(9), num(10), num(11), num(12), row[13], robots))

    path = os.path.join(output_dir, "events.csv")
    for number, row in enumerate(_read_csv(path, EVENT_COLUMNS)[1], start=2):
        run.events.append(Event(_float(path, number, "t_s", row[0]), row[1], row[2], row[3],
                                _float(path, number, "x_m", row[4]), _float(path, number, "y_m", row[5])))

    path = os.path.join(output_dir, "controller.csv")
    header, rows = _read_csv(path)
    if header not in (CONTROLLER_COLUMNS, CONTROLLER_COLUMNS[:7]):   # a run of before the overrun counters
        _read_csv(path, CONTROLLER_COLUMNS)   # raises, naming the expected columns
    for number, row in enumerate(rows, start=2):
        counters = [_int(path, number, "overruns", row[7]), _int(path, number, "late_starts", row[8])] \
            if len(row) > 7 else [0, 0]
        run.controller.append(ControllerSample(
            _float(path, number, "t_s", row[0]), row[1], _float(path, number, "latency_s", row[2]),
            _float(path, number, "cycle_time_ms", row[3]), _int(path, number, "lookups", row[4]),
            _int(path, number, "lookup_failures", row[5]), row[6], *counters))
    return run


def main(argv=None):
    """Print the summary of a run folder (as the collector computed it) as JSON."""
    parser = argparse.ArgumentParser(description="Summary of a formation metrics run folder.")
    parser.add_argument("output_dir", help="folder with metrics.csv, events.csv, controller.csv")
    args = parser.parse_args(argv)
    try:
        summary = summarize(load_run(args.output_dir))
    except RunFileError as error:
        print(error, file=sys.stderr)
        return 1
    json.dump(summary, sys.stdout, indent=1)
    print()
    return 0


if __name__ == "__main__":
    sys.exit(main())
