"""The live recorder: MetricsCollector builds a Run from the contents of messages (see
mbot_follower.metrics for what it measures). Nothing here knows ROS."""
import math

import numpy as np

from mbot_common.geometry import Twist2D
from mbot_follower.control_laws import energy_rate
from mbot_follower.metrics import obstacles as static_obstacles
from mbot_follower.metrics.records import NAN, ControllerSample, Event, MetricsConfig, RobotSample, Run, Sample
from mbot_follower.shape import ShapeErrors, rigid_fit, shape_errors
from mbot_follower.trail import LeaderTrail, slot_pose, trail_start


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


#: latency methods (the `latency_method` event, the summary's latency_method)
LATENCY_SIMULATOR = "simulator"   # when the simulator applied the command - the pose's stamp
LATENCY_POSE_AGE = "pose_age"     # when the command was computed - the pose's stamp (no simulator report)
_EPS = 1e-6   # [s] stamps pass through ROS time (whole nanoseconds)


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
        # The leader's ground-truth path (trail.LeaderTrail) at the sample times since the
        # assignment in force (_trail_of), for the slots of a formation along the path.
        self._trail = LeaderTrail()
        self._trail_of = None
        # The simulator's static obstacles (obstacles.Obstacle by name) and (t, tuple) of every
        # change: a slot beside one is blocked as one beside a wall (on_obstacles).
        self.obstacles = {}
        self._obstacle_sets = []
        # Control latency (on_follower_state, on_applied_commands): each robot's cycles wait here,
        # oldest first, until the simulator's report says when their command was applied; a cycle
        # becomes a ControllerSample (in order per robot) once that is known.
        self.latency_method = None   # LATENCY_SIMULATOR or LATENCY_POSE_AGE; None: not known yet
        self._cycles = {}            # robot -> [(ControllerSample, pose stamp or None, cmd tuple or None)]
        self._applied = {}           # robot -> [(applied [s], cmd tuple)] of the report, oldest first
        self._reported_until = None  # the report covers sim time up to here [s]; None: no report yet
        self._unreported = []        # (from, to) [s]: spans the report did not cover
        self._last_cycle = {}        # robot -> time of its newest cycle [s]

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
                          overruns=0, late_starts=0, cmd=None):
        """One follower controller cycle: t and pose_stamp [s sim], cycle_time [s wall], the
        overrun counters so far, cmd the command it sent (any tuple of numbers, compared exactly
        with the simulator's report: the twist's six fields). Its ControllerSample is recorded
        when its latency is known (module docstring: latency)."""
        self._know(robot)
        measured = active and pose_stamp > 0.0
        row = ControllerSample(t, robot, NAN, 1000.0 * cycle_time, int(lookups), int(lookup_failures), mode,
                               int(overruns), int(late_starts), NAN)
        self._cycles.setdefault(robot, []).append((row, pose_stamp if measured else None,
                                                   tuple(cmd) if cmd is not None else None))
        self._last_cycle[robot] = max(t, self._last_cycle.get(robot, t))
        self._resolve_cycles()

    def on_applied_commands(self, since, until, commands):
        """The simulator's report (/stage/applied_commands): every command applied in [since,
        until) [s sim], as (robot, received, applied, cmd tuple), in the order applied."""
        if self._reported_until is None:
            self._unreported.append((-math.inf, since))
        elif since > self._reported_until + _EPS:
            self._unreported.append((self._reported_until, since))   # a pause of the report: unknown
        self._reported_until = until if self._reported_until is None else max(until, self._reported_until)
        for robot, _received, applied, cmd in commands:
            self._applied.setdefault(robot, []).append((applied, tuple(cmd)))
        if self.latency_method != LATENCY_SIMULATOR:
            self._set_latency_method(until, LATENCY_SIMULATOR)
        self._resolve_cycles()

    def finish(self):
        """At the end of a run: record every cycle still waiting; one whose command the report
        has not shown yet gets a NaN latency, applied unknown."""
        if self.latency_method is None and any(self._cycles.values()):
            self._set_latency_method(max(self._last_cycle.values()), LATENCY_POSE_AGE)
        self._resolve_cycles(final=True)

    def _set_latency_method(self, t, method):
        self.latency_method = method
        detail = ("end to end: the simulator's report of when it applied each command (/stage/applied_commands)"
                  if method == LATENCY_SIMULATOR else
                  "no report of applied commands within command_wait (not a simulator): the pose's age when "
                  "the command was computed, without transport and actuation")
        self.run.events.append(Event(t, "latency_method", method, detail, NAN, NAN))

    def _resolve_cycles(self, final=False):
        """Record the waiting cycles whose latency is known now, in order per robot."""
        wait = self.config.command_wait
        if self.latency_method is None and self._last_cycle:
            oldest = min((c[0][0].t for c in self._cycles.values() if c), default=None)
            if oldest is not None and max(self._last_cycle.values()) - oldest >= wait:
                self._set_latency_method(max(self._last_cycle.values()), LATENCY_POSE_AGE)
        for robot, cycles in self._cycles.items():
            done = 0
            for row, pose_stamp, cmd in cycles:
                result = self._latency(robot, row.t, pose_stamp, cmd, final)
                if result is None:
                    break
                self.run.controller.append(row._replace(latency=result[0], applied=result[1]))
                done += 1
            del cycles[:done]
            # Reports older than every cycle still to come cannot be theirs (a robot's cycles come
            # in time order); for a robot without cycles (a leader on move_base) keep hold_back.
            applied = self._applied.get(robot)
            if applied:
                floor = cycles[0][0].t if cycles else self._last_cycle.get(robot, -math.inf)
                if not cycles and self._reported_until is not None:
                    floor = max(floor, self._reported_until - self.config.hold_back)
                k = 0
                while k < len(applied) and applied[k][0] < floor - _EPS:
                    k += 1
                del applied[:k]

    def _latency(self, robot, t, pose_stamp, cmd, final):
        """(latency, applied) of a cycle at t, or None while not known yet (module docstring:
        latency): the first command of the robot applied at or after t with exactly the twist sent."""
        if pose_stamp is None:
            return NAN, NAN
        if self.latency_method == LATENCY_POSE_AGE:
            return t - pose_stamp, NAN
        if self.latency_method is None:
            return (NAN, NAN) if final else None
        for applied, twist in self._applied.get(robot, ()):
            if applied >= t - _EPS and twist == cmd:
                if applied <= t + self.config.command_wait + _EPS:
                    return applied - pose_stamp, 1.0
                break
        if self._reported_until < t + self.config.command_wait - _EPS:
            return (NAN, NAN) if final else None   # it may still come
        end = t + self.config.command_wait
        if any(start < end and t < stop for start, stop in self._unreported):
            return NAN, NAN   # the report did not cover it
        return NAN, 0.0

    def on_power(self, robot, t, power):
        """The energy model's rate [W] of a robot; it holds until the next one (at most stale_after)."""
        self._know(robot)
        previous = self.power.get(robot)
        if previous is not None and t > previous[0]:
            self.energy[robot] += previous[1] * min(t - previous[0], self.config.stale_after)
        self.power[robot] = (t, power)

    def on_obstacles(self, t, obstacles):
        """The simulator's static obstacles at t (all of them, /stage/markers): a new or moved one
        is an `obstacle` event (shape and size in detail, its centre), one gone `obstacle_removed`.
        From t on a slot within slot_clearance of one is not free (the walls' rule)."""
        now = {o.name: o for o in obstacles}
        if now == self.obstacles:
            return
        for name in sorted(now):
            o = now[name]
            if self.obstacles.get(name) != o:
                self.run.events.append(Event(t, "obstacle", name, static_obstacles.describe(o), o.x, o.y))
        for name in sorted(set(self.obstacles) - set(now)):
            o = self.obstacles[name]
            self.run.events.append(Event(t, "obstacle_removed", name, static_obstacles.describe(o), o.x, o.y))
        self.obstacles = now
        self._obstacle_sets.append((t, tuple(now.values())))

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
        entry = self._in_force(self._obstacle_sets, t)
        obstacles = entry[1] if entry is not None else ()
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
                    if self.free_space is not None or obstacles:
                        free = (self.free_space is None or self.free_space.is_free(*desired[i])) and \
                            not static_obstacles.blocks(obstacles, desired[i][0], desired[i][1],
                                                        self.config.slot_clearance)
                        slot_free[r] = 1.0 if free else 0.0
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
            start = trail_start(self.history.get(leader, ()), since)
            self._trail.restart(since, start[1:4] if start is not None else pose)
            self._trail_of = a
        self._trail.follow(*pose)
