"""The records of a formation run (see mbot_follower.metrics): one Sample of the fleet per
sample time, the Events, the ControllerSamples, the MetricsConfig, and the Run holding them."""
import math
from collections import namedtuple

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
#:   latency_method / "simulator" or "pose_age" / why (how the control latency is measured from then on)
#:   contact / body_a / body_b, at x, y [m] (NaN for the other kinds)
Event = namedtuple("Event", "t kind name detail x y")

#: One follower controller cycle: t [s] when the command was computed, latency [s] (NaN if the
#: cycle used no pose or its command was not applied), cycle_time_ms [ms wall], the controller's
#: lookup counters, its mode, its overrun counters so far (cycles that took longer than the
#: period, cycles that started a period or more late), and applied: 1.0 the simulator applied its
#: command, 0.0 it did not (dropped, or replaced before a physics step), NaN unknown (no pose, no
#: simulator report: the latency is then the pose's age when the command was computed).
ControllerSample = namedtuple("ControllerSample", "t robot latency cycle_time_ms lookups lookup_failures mode "
                              "overruns late_starts applied", defaults=(0, 0, NAN))


class MetricsConfig(object):
    """Parameters of the metrics (the node reads them from its private parameters)."""

    def __init__(self, rate=10.0, command_wait=1.0, recovered_rms=0.15, recovered_hold=1.0,
                 robot_radius=0.15, stale_after=1.0, moving_speed=0.05, teleport_speed=5.0, hold_back=5.0,
                 slot_clearance=0.25, free_hold=3.0, controller_silence=0.5, energy_k_v=4.0, energy_k_w=0.5):
        self.rate = rate                      # samples per sim second [Hz]
        # a command the simulator has not applied this long after it was computed was not applied;
        # with no simulator report this long, the latency is the pose's age (a real robot) [s]
        self.command_wait = command_wait
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
        limits = [("rate", 0.0, False), ("command_wait", 0.0, False), ("recovered_rms", 0.0, False),
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
        values = {k: v for k, v in values.items() if k != "physics_step"}   # runs of before command_wait
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
