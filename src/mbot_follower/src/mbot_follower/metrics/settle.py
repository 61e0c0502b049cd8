"""When is a formation switch done? The one rule, for the coordinator (online) and for everyone
who reads a run afterwards (scenario judge and runner, report, benchmark, rostests).

A switch is done when every follower whose slot can be held is within SWITCH_TOLERANCE of its new
slot, and stays so for SWITCH_HOLD (sim time). A follower whose slot is blocked (in a wall, beside
a lost robot) is left out; when none is left to check (every slot blocked, the leader alone) the
shape counts as reached. The switch time is the time from the switch until the new shape was
reached, i.e. the start of that hold: the hold is the proof, not part of the switch.

`SwitchSettle` applies the rule to one stream of slot errors (the coordinator feeds it every
cycle); `switch_done_times(run)` feeds the same class with a recorded run's samples, once per
switch, and adds what the coordinator itself recorded (its switch_done event), so both can be
compared. Only their inputs differ: the coordinator measures its localization's poses and leaves
out its blocked followers (a wall's slot until free_hold after it is clear, a slot beside a lost
robot); a recorded run has the ground truth at the sample rate and the collector's slot_free
(walls and obstacles, in that sample); the fleet probe of the rostests counts every follower.

Headings are not part of it: "formation stable" (FORMING -> NAVIGATING, ARRIVED; the
coordinator's edge and heading tolerances) also waits for followers that drove backwards into
their slots to turn round, 3-4 s more after a column forms in place.
"""
import math

#: [m] every follower this close to its new slot ...
SWITCH_TOLERANCE = 0.3
#: [s] ... for this long: the switch is done.
SWITCH_HOLD = 0.5


class SwitchSettle(object):
    """The rule (module docstring) on one stream of slot errors in time order.

    update() returns True once the shape has held; then `reached_at` is when it was reached (the
    start of the hold) and `done_at` when the hold was complete (when an online user knows)."""

    def __init__(self, tolerance=SWITCH_TOLERANCE, hold=SWITCH_HOLD):
        for name, value in (("tolerance", tolerance), ("hold", hold)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                    or value < 0 or (name == "tolerance" and value == 0):
                raise ValueError("SwitchSettle: %s must be a finite number %s 0, got %r"
                                 % (name, ">" if name == "tolerance" else ">=", value))
        self.tolerance = float(tolerance)
        self.hold = float(hold)
        self.reset()

    def reset(self):
        """A new switch: nothing reached yet."""
        self.since = None       # the shape has been within the tolerance since then [s]
        self.reached_at = None  # set once it held: when it was reached [s]
        self.done_at = None     # ... and when the hold was complete [s]

    @property
    def done(self):
        return self.done_at is not None

    def within(self, errors, blocked=()):
        """Whether {follower: slot distance [m]} is within the tolerance, leaving out the
        `blocked` followers (a NaN error, nothing measured, is not within)."""
        counted = [e for r, e in errors.items() if r not in blocked]
        return all(e < self.tolerance for e in counted)   # (none counted: within)

    def update(self, t, errors, blocked=()):
        """One observation at t [s]: errors {follower: distance to its slot [m]} of every
        follower with a pose, `blocked` the followers to leave out. True once the switch is done
        (it stays done until reset())."""
        if self.done:
            return True
        if not self.within(errors, blocked):
            self.since = None
            return False
        if self.since is None:
            self.since = t
        if t - self.since >= self.hold - 1e-9:
            self.reached_at, self.done_at = self.since, t
            return True
        return False


def switch_done_times(run, tolerance=SWITCH_TOLERANCE, hold=SWITCH_HOLD):
    """One dict per formation switch (a `switch` event) of a recorded Run, in time order:
      formation, previous: the new and the old formation; t_s: the switch [s];
      switch_time_s: SwitchSettle over the run's samples of the new formation from the switch on
        (the followers' slot_error, one whose slot was not free in that sample left out): reached_at - t_s,
        None when the shape was never reached before the next switch or the end;
      done_s: when the hold was complete, from the switch [s] (None: never);
      coordinator_done_s: the coordinator's own switch_done event after the switch and before the
        next one, from the switch [s]; None when it recorded none (a formation change it did not
        switch, e.g. a fallback after a loss, or a run that ended first)."""
    events = sorted(run.events, key=lambda e: e.t)
    switches = [e for e in events if e.kind == "switch"]
    out = []
    for k, switch in enumerate(switches):
        end = switches[k + 1].t if k + 1 < len(switches) else math.inf
        settle = SwitchSettle(tolerance, hold)
        for s in run.samples:
            if s.t < switch.t - 1e-9 or s.t >= end:
                continue
            if s.formation != switch.name:
                settle.since = None   # (a sample between the assignment and its status)
                continue
            errors = {r: rs.slot_error for r, rs in s.robots.items() if math.isfinite(rs.slot_error)}
            blocked = [r for r, rs in s.robots.items() if rs.slot_free == 0.0]
            if not errors and not blocked:
                errors = {None: math.nan}   # nobody measured (no leader pose) is not within
            if settle.update(s.t, errors, blocked):
                break
        mine = next((e.t for e in events if e.kind == "switch_done" and switch.t - 1e-9 <= e.t < end), None)
        out.append({"formation": switch.name, "previous": switch.detail, "t_s": switch.t,
                    "switch_time_s": None if settle.reached_at is None else settle.reached_at - switch.t,
                    "done_s": None if settle.done_at is None else settle.done_at - switch.t,
                    "coordinator_done_s": None if mine is None else mine - switch.t})
    return out
