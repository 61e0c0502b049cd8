"""Formation control laws: how a follower drives to its slot and stays there.

Everything a follower computes is in the LEADER FRAME L (the leader's base_link: x forward,
y left [m]). The follower's pose there is p = (x, y) and theta [rad]; its slot is a fixed point
s = (s_x, s_y) of L; the leader moves with the twist (v_L, w_L) in its own body frame
(v_L = (v_Lx, v_Ly) [m/s], w_L [rad/s]).

1. Feed-forward: the slot is a point of the moving leader, so over the ground it moves with

       v_s = v_L + w_L x s = (v_Lx - w_L * s_y,  v_Ly + w_L * s_x)

   A follower that sits in its slot and drives with v_s stays there.

2. Feedback: the slot error e = s - p adds a velocity towards the slot. The desired velocity of
   the follower over the ground, in L's axes, is

       slot tracking:  u   = v_s + k_position * (s - p)
       consensus:      u_i = v_s_i + k_position * (s_i - p_i)
                             + k_consensus * sum_j ((p_j - p_i) - (s_j - s_i))

   (j runs over the other followers: each corrects its distance to its neighbours as well as to
   the leader.) Why it converges: seen from the moving frame L, the follower moves with
   dp/dt = u - v_L - w_L x p, so slot tracking gives de/dt = -w_L x e - k_position * e: the
   error only turns and shrinks by the factor exp(-k_position * t). Consensus adds
   -k_consensus * sum_j (e_i - e_j), which pulls the errors of the followers together.

3. From u to a velocity command for the robot's body frame (Twist2D vx, vy, wz):

   omni (config.omni): drive u directly and turn to the leader's heading (theta = 0 in L):

       (vx, vy) = R(-theta) u,    wz = w_L + k_heading * (0 - theta)

   diff drive (vy = 0): the robot can only drive along its heading, so it steers to the
   direction of u and drives with the part of u along its heading:

       theta_ref = atan2(u_y, u_x)   if |u| > k_position * slot_tolerance
                 = 0 (the leader's heading)   otherwise: in a slot that does not move
       wz = w_L + k_heading * normalize(theta_ref - theta)
       vx = max(u . (cos theta, sin theta),  -max_reverse_vel)

   A slot behind the robot: u points backwards, so the robot turns in place towards it first
   (while it faces away, the projection of u on its heading is negative and it can only back up,
   at most max_reverse_vel, which also moves it towards the slot). Close to a still slot
   (|u| small) it does not turn around: it faces the leader's way and backs up the last
   centimetres. Backing up stays slow: turning round and driving forward at up to
   max_linear_vel is quicker for all but a short way.

4. CommandFilter smooths the command, limits the acceleration, then the velocity. safety_stop
   says when the laser sees something too close ahead. way_blocked says when something stands
   on the straight way to the slot, and detour finds the smallest turn of that way that is
   clear (the follower steers round the obstacle instead of stopping behind it). energy_rate is
   the power model.

Run `python3 -m mbot_follower.control_laws --plot` to watch a leader drive a curve with two
followers. Pure Python + numpy, no ROS: the ROS node only converts messages.
"""
import argparse
import math
import sys
from collections import namedtuple

import numpy as np

from mbot_common.geometry import Pose2D, Twist2D, compose, normalize_angle, relative


class ControllerConfig(object):
    """Gains and limits of a follower. The ROS node copies its private parameters in with
    update() every cycle, so `rosparam set` takes effect at once."""

    def __init__(self, **values):
        self.k_position = 0.8              # slot error -> velocity gain [1/s]
        self.k_heading = 2.5               # heading error -> turn rate gain [1/s]
        self.k_consensus = 0.3             # neighbour error gain of the consensus law [1/s]
        self.max_linear_vel = 0.5          # [m/s]
        self.max_angular_vel = 1.5         # [rad/s]
        self.max_linear_accel = 1.0        # [m/s^2]
        self.max_angular_accel = 3.0       # [rad/s^2]
        self.max_reverse_vel = 0.1         # diff drive: fastest backing up [m/s]
        self.smoothing = 0.3               # weight of the new command in the filter, (0, 1] [-]
        self.slot_tolerance = 0.1          # closer than this to a still slot = in the slot: face the leader's way [m]
        self.safety_distance = 0.8         # stop if something is closer than this ahead [m]
        self.safety_half_angle = math.radians(30)  # half-width of "ahead" [rad]
        self.safety_near_distance = 0.45   # length of the lane ahead that must be clear [m]
        self.safety_lane_half_width = 0.25  # the lane's half-width: robot radius 0.15 + 0.1 margin [m]
        self.yield_after = 1.0             # held by the safety layer this long: give way [s]
        self.yield_stagger = 0.5           # ... plus this per follower slot farther back than its own [s]
        self.yield_time = 1.5              # how long to back away from what holds it [s]
        self.yield_speed = 0.15            # how fast [m/s]
        self.omni = False                  # True: holonomic robot (uses vy)
        # the predictive law (mpc_law.py); the other laws ignore these
        self.mpc_horizon = 15              # steps of the receding horizon [-]
        self.mpc_step = 2                  # one step = this many control periods [-]
        self.mpc_time_budget = 0.02        # a solve longer than this falls back to slot tracking [s wall]
        self.mpc_q_position = 20.0         # weight of the slot error [1/m^2]
        self.mpc_q_heading = 0.5           # weight of the heading error near the slot [1/rad^2]
        self.mpc_r_velocity = 0.05         # weight of the command minus the slot's own velocity [s^2/m^2]
        self.mpc_r_change = 0.2            # weight of the change of command from step to step [s^2/m^2]
        self.mpc_robot_distance = 0.45     # least centre distance to a teammate's predicted path [m]
        self.mpc_obstacle_distance = 0.25  # least distance from the centre to a laser point [m]
        self.mpc_obstacle_range = 1.5      # laser points within this of the robot are constraints [m]
        if values:
            self.update(values)

    # key -> (kind, check, what the check asks for)
    _RULES = {
        "k_position": (float, lambda v: v >= 0, ">= 0"),
        "k_heading": (float, lambda v: v >= 0, ">= 0"),
        "k_consensus": (float, lambda v: v >= 0, ">= 0"),
        "max_linear_vel": (float, lambda v: v > 0, "> 0"),
        "max_angular_vel": (float, lambda v: v > 0, "> 0"),
        "max_linear_accel": (float, lambda v: v > 0, "> 0"),
        "max_angular_accel": (float, lambda v: v > 0, "> 0"),
        "max_reverse_vel": (float, lambda v: v >= 0, ">= 0"),
        "smoothing": (float, lambda v: 0 < v <= 1, "in (0, 1]"),
        "slot_tolerance": (float, lambda v: v >= 0, ">= 0"),
        "safety_distance": (float, lambda v: v >= 0, ">= 0"),
        "safety_half_angle": (float, lambda v: 0 <= v <= math.pi, "in [0, pi] [rad]"),
        "safety_near_distance": (float, lambda v: v >= 0, ">= 0"),
        "safety_lane_half_width": (float, lambda v: v >= 0, ">= 0"),
        "yield_after": (float, lambda v: v >= 0, ">= 0"),
        "yield_stagger": (float, lambda v: v >= 0, ">= 0"),
        "yield_time": (float, lambda v: v >= 0, ">= 0"),
        "yield_speed": (float, lambda v: v >= 0, ">= 0"),
        "omni": (bool, None, None),
        "mpc_horizon": (int, lambda v: 1 <= v <= 100, "in [1, 100]"),
        "mpc_step": (int, lambda v: 1 <= v <= 20, "in [1, 20]"),
        "mpc_time_budget": (float, lambda v: v > 0, "> 0"),
        "mpc_q_position": (float, lambda v: v > 0, "> 0"),
        "mpc_q_heading": (float, lambda v: v >= 0, ">= 0"),
        "mpc_r_velocity": (float, lambda v: v >= 0, ">= 0"),
        "mpc_r_change": (float, lambda v: v >= 0, ">= 0"),
        "mpc_robot_distance": (float, lambda v: v >= 0, ">= 0"),
        "mpc_obstacle_distance": (float, lambda v: v >= 0, ">= 0"),
        "mpc_obstacle_range": (float, lambda v: v >= 0, ">= 0"),
    }

    def update(self, values):
        """Set the given keys. ValueError naming the key for an unknown key, a wrong type or a
        value out of range; then nothing is changed."""
        checked = {}
        for key, value in values.items():
            if key not in self._RULES:
                raise ValueError("ControllerConfig: unknown key %r (known: %s)"
                                 % (key, ", ".join(sorted(self._RULES))))
            kind, check, wanted = self._RULES[key]
            if kind is bool:
                if not isinstance(value, bool):
                    raise ValueError("ControllerConfig: %s: expected true or false, got %r" % (key, value))
            elif kind is int:
                if isinstance(value, bool) or not isinstance(value, int) or not check(value):
                    raise ValueError("ControllerConfig: %s: expected a whole number %s, got %r" % (key, wanted, value))
            else:
                # ints are fine for a float (a gain of 1); bools and strings are not
                if isinstance(value, bool) or not isinstance(value, (int, float)):
                    raise ValueError("ControllerConfig: %s: expected a number, got %r" % (key, value))
                value = float(value)
                if not math.isfinite(value) or not check(value):
                    raise ValueError("ControllerConfig: %s: expected a finite number %s, got %r"
                                     % (key, wanted, value))
            checked[key] = value
        for key, value in checked.items():
            setattr(self, key, value)

    def to_dict(self):
        """Every key and its current value."""
        return {key: getattr(self, key) for key in self._RULES}


#: What a control law needs, all in the leader frame: pose (Pose2D) of this follower, slot
#: (x, y) its slot [m], leader_twist (Twist2D) of the leader in its body frame, neighbours a list
#: of (Pose2D, (slot_x, slot_y)) of the other followers (may be empty). Only the predictive law
#: (mpc) reads the rest: dt the control period [s], previous the command sent last (Twist2D),
#: obstacles laser points (x, y) and teammates their predicted positions [(x, y) per step of
#: the law's horizon], both in the same frame.
ControlInput = namedtuple("ControlInput", "pose slot leader_twist neighbours dt previous obstacles teammates")
ControlInput.__new__.__defaults__ = (None, None, (), ())


def slot_velocity(slot, leader_twist):
    """v_s = v_L + w_L x s: the velocity over the ground of the point `slot` of the leader
    frame, in the leader's axes [m/s]."""
    vx, vy, wz = leader_twist
    return (vx - wz * slot[1], vy + wz * slot[0])


def robot_command(u, pose, leader_twist, config):
    """Turn the desired velocity u (leader axes) into a body-frame Twist2D (omni or diff drive)."""
    ux, uy = u
    theta = pose.theta
    c, s = math.cos(theta), math.sin(theta)
    w_leader = leader_twist.wz
    if config.omni:
        wz = w_leader + config.k_heading * normalize_angle(0.0 - theta)
        return Twist2D(c * ux + s * uy, -s * ux + c * uy, wz)      # R(-theta) u

    if math.hypot(ux, uy) > config.k_position * config.slot_tolerance:
        theta_ref = math.atan2(uy, ux)   # face where the robot has to go
    else:
        theta_ref = 0.0                  # in a still slot: face the leader's way
    wz = w_leader + config.k_heading * normalize_angle(theta_ref - theta)
    vx = max(c * ux + s * uy, -config.max_reverse_vel)
    return Twist2D(vx, 0.0, wz)


class SlotTracking(object):
    """u = v_s + k_position * (s - p): each follower drives to its own slot (the default)."""

    smooth = True   # the command filter smooths its commands (the predictive law plans smooth ones)

    def compute(self, inp, config):
        vsx, vsy = slot_velocity(inp.slot, inp.leader_twist)
        ex, ey = inp.slot[0] - inp.pose.x, inp.slot[1] - inp.pose.y
        u = (vsx + config.k_position * ex, vsy + config.k_position * ey)
        return robot_command(u, inp.pose, inp.leader_twist, config)


class Consensus(object):
    """u_i = v_s_i + k_position (s_i - p_i) + k_consensus sum_j ((p_j - p_i) - (s_j - s_i))."""

    smooth = True

    def compute(self, inp, config):
        vsx, vsy = slot_velocity(inp.slot, inp.leader_twist)
        ex, ey = inp.slot[0] - inp.pose.x, inp.slot[1] - inp.pose.y
        ux = vsx + config.k_position * ex     # the leader term
        uy = vsy + config.k_position * ey
        for pose_j, slot_j in inp.neighbours:
            ux += config.k_consensus * ((pose_j.x - inp.pose.x) - (slot_j[0] - inp.slot[0]))
            uy += config.k_consensus * ((pose_j.y - inp.pose.y) - (slot_j[1] - inp.slot[1]))
        return robot_command((ux, uy), inp.pose, inp.leader_twist, config)


def _mpc_law():
    # imported on use: only the predictive law needs cvxopt (and mpc_law imports this module)
    from mbot_follower.mpc_law import MpcLaw
    return MpcLaw()


# To add a law: a class (or a function making one) with compute(inp, config) -> Twist2D and
# smooth (True: the command filter smooths its commands), and its name here.
CONTROL_LAWS = {"slot_tracking": SlotTracking, "consensus": Consensus, "mpc": _mpc_law}


def make_control_law(name):
    """An instance of the law called `name`; ValueError listing the known names otherwise."""
    if name not in CONTROL_LAWS:
        raise ValueError("unknown control law %r (known: %s)" % (name, ", ".join(sorted(CONTROL_LAWS))))
    return CONTROL_LAWS[name]()


def _clamp(value, limit):
    return max(-limit, min(limit, value))


def _limit_norm(x, y, limit):
    """Scale the vector (x, y) down to length `limit` if it is longer (keeps its direction)."""
    norm = math.hypot(x, y)
    if norm > limit:
        return x * limit / norm, y * limit / norm
    return x, y


class CommandFilter(object):
    """Smooths commands, then limits acceleration, then velocity. One per robot.

    Smoothing: new = w * cmd + (1 - w) * previous with w = config.smoothing, once per call (so its
    time constant depends on the call rate: at 20 Hz w = 0.3 gives ~0.14 s). The linear part is
    limited as a vector (|(vx, vy)|), so an omni robot keeps its direction. The config is read at
    every call, so live parameter changes apply at once.
    """

    def __init__(self, config):
        self.config = config
        self.previous = Twist2D(0.0, 0.0, 0.0)   # the robot starts at rest

    def reset(self):
        self.previous = Twist2D(0.0, 0.0, 0.0)

    def sent(self, cmd):
        """Tell the filter what was sent instead of its output (the safety layer stopped the
        travel but let the turn through): the next command smooths from that, so a held robot
        keeps turning at its full rate instead of starting its turn from zero every cycle."""
        self.previous = Twist2D(*cmd)

    def apply(self, cmd, dt, smooth=True):
        """smooth False: only limit (the predictive law's commands are planned within the limits)."""
        if not (dt > 0 and math.isfinite(dt)):
            raise ValueError("CommandFilter.apply: dt must be a finite time > 0 [s], got %r" % (dt,))
        if not all(math.isfinite(v) for v in cmd):
            raise ValueError("CommandFilter.apply: command must be finite, got %r" % (cmd,))
        c = self.config
        prev = self.previous
        w = c.smoothing if smooth else 1.0
        vx = w * cmd.vx + (1.0 - w) * prev.vx
        vy = w * cmd.vy + (1.0 - w) * prev.vy
        wz = w * cmd.wz + (1.0 - w) * prev.wz

        dvx, dvy = _limit_norm(vx - prev.vx, vy - prev.vy, c.max_linear_accel * dt)
        vx, vy = prev.vx + dvx, prev.vy + dvy
        wz = prev.wz + _clamp(wz - prev.wz, c.max_angular_accel * dt)

        vx, vy = _limit_norm(vx, vy, c.max_linear_vel)
        wz = _clamp(wz, c.max_angular_vel)
        self.previous = Twist2D(vx, vy, wz)
        return self.previous


# The laser checks below run every control cycle over every beam: numpy, not a Python loop per
# beam (a 360-beam scan took a follower ~1 ms per check in pure Python).

def _beams(ranges, angle_min, angle_increment):
    """(ranges, beam angles wrapped to [-pi, pi]) as arrays."""
    r = np.asarray(ranges, dtype=float)
    a = np.remainder(angle_min + np.arange(len(r)) * angle_increment + math.pi, 2.0 * math.pi) - math.pi
    return r, a


def safety_stop(ranges, angle_min, angle_increment, distance, half_angle):
    """True if a laser beam within +-half_angle [rad] of straight ahead reads less than
    `distance` [m]. REP-117 readings: -Inf = too close to measure (counts as close), +Inf =
    nothing in range, NaN = no valid reading (ignored)."""
    r, a = _beams(ranges, angle_min, angle_increment)
    ahead = np.abs(a) <= half_angle
    with np.errstate(invalid="ignore"):
        close = (r < distance)   # -Inf is less than any distance; NaN and +Inf are not
    return bool(np.any(ahead & close))


def lane_blocked(ranges, angle_min, angle_increment, length, half_width):
    """True if a laser point lies in the lane the robot's body sweeps next: ahead of it (0 < x <
    `length` [m]) and less than `half_width` [m] to either side (|y|), in a frame whose x axis
    is the direction of travel. -Inf (too close to measure) on the front half counts; NaN and
    +Inf do not."""
    r, a = _beams(ranges, angle_min, angle_increment)
    front = np.abs(a) <= math.pi / 2
    if np.any(front & (r == -np.inf)):
        return True
    finite = front & np.isfinite(r)
    r, a = r[finite], a[finite]
    x, y = r * np.cos(a), r * np.sin(a)
    return bool(np.any((x > 0.0) & (x < length) & (np.abs(y) < half_width)))


def safety_filter(cmd, ranges, angle_min, angle_increment, config):
    """The safety layer, last in the loop: (cmd, stopped). The robot stops its travel (keeps
    turning) when the laser sees something in the direction it drives in (ahead, behind when
    backing up, sideways for an omni robot):
    - closer than `safety_distance` within +-`safety_half_angle` of that direction, or
    - in the lane its body sweeps next: within `safety_near_distance` ahead and less than
      `safety_lane_half_width` to either side of its path (catches a corner at its shoulder).
    Something beside the robot, outside that lane, does not stop it: driving on does not bring
    it closer. Stopping for it held followers in doorways, beside the jambs, for ever."""
    speed = math.hypot(cmd.vx, cmd.vy)
    if speed < 1e-6:
        return cmd, False
    start = angle_min - math.atan2(cmd.vy, cmd.vx)   # beam angles relative to the travel direction
    if safety_stop(ranges, start, angle_increment, config.safety_distance, config.safety_half_angle) or \
            lane_blocked(ranges, start, angle_increment, config.safety_near_distance,
                         config.safety_lane_half_width):
        return Twist2D(0.0, 0.0, cmd.wz), True
    return cmd, False


def scan_points(ranges, angle_min, angle_increment, range_min, reach):
    """The laser's finite readings from `range_min` to `reach` [m] as points (x, y) of the
    robot's frame (a list of tuples)."""
    r = np.asarray(ranges, dtype=float)
    with np.errstate(invalid="ignore"):
        keep = np.flatnonzero((r >= range_min) & (r <= reach))
    a = angle_min + keep * angle_increment
    r = r[keep]
    return list(zip((r * np.cos(a)).tolist(), (r * np.sin(a)).tolist()))


def way_blocked(points, gx, gy, horizon, clearance):
    """True when a point lies closer than `clearance` [m] to the straight way from the robot
    (the origin) towards (gx, gy), over its first `horizon` [m]."""
    length = math.hypot(gx, gy)
    if length < 1e-6:
        return False
    ux, uy = gx / length, gy / length
    horizon = min(length, horizon)
    for px, py in points:
        along = px * ux + py * uy
        if 0.0 <= along <= horizon and abs(py * ux - px * uy) < clearance:
            return True
    return False


def detour(points, gx, gy, horizon, clearance, step, max_turn, prefer=1, is_free=None):
    """A way round something standing between the robot and its goal (gx, gy), both in the
    robot's frame: ((x, y), side), the goal turned about the robot by the smallest multiple of
    `step` [rad], to either side up to `max_turn`, whose straight way way_blocked finds clear
    (and is_free(x, y), if given, accepts). Of two equal turns the one to side `prefer`
    (+1 left, -1 right) comes first, so that a robot keeps to the side it chose. None if no way
    is clear."""
    turns = int(max_turn / step + 1e-9)
    for k in range(1, turns + 1):
        for side in (prefer, -prefer):
            c, s = math.cos(side * k * step), math.sin(side * k * step)
            x, y = c * gx - s * gy, s * gx + c * gy
            if not way_blocked(points, x, y, horizon, clearance) and (is_free is None or is_free(x, y)):
                return (x, y), side
    return None


class GiveWay(object):
    """Breaks a standoff the safety layer cannot: two followers that want to pass each other
    stop, each waiting for the other, for ever. A follower held for `yield_after` (+
    `yield_stagger` for every follower slot farther from the leader than its own, so that the
    one further back gives way first and the other can go) backs away from the nearest thing it
    sees for `yield_time`, then drives on. Its commands still pass the safety layer."""

    def __init__(self):
        self.held_since = None    # when the safety layer started holding the robot [s]
        self.until = None         # giving way until then [s]
        self.cmd = None           # the command while giving way

    def step(self, now, held, ranges, angle_min, angle_increment, rank, config):
        """The command that gives way, or None to go on normally.

        :param now: [s]; held: the safety layer stopped the last command
        :param rank: how many follower slots lie farther from the leader than this robot's
        """
        if self.until is not None:
            if now < self.until:
                return self.cmd
            self.until = None
            self.held_since = None
        if not held:
            self.held_since = None
            return None
        if self.held_since is None:
            self.held_since = now
        if now - self.held_since < config.yield_after + config.yield_stagger * rank:
            return None
        nearest = min(((r, angle_min + i * angle_increment) for i, r in enumerate(ranges)
                       if math.isfinite(r)), default=None)
        if nearest is None:
            return None
        away = nearest[1] + math.pi
        if config.omni:
            self.cmd = Twist2D(config.yield_speed * math.cos(away), config.yield_speed * math.sin(away), 0.0)
        else:  # along the body axis, away from it
            self.cmd = Twist2D(config.yield_speed * (1.0 if math.cos(away) > 0 else -1.0), 0.0, 0.0)
        self.until = now + config.yield_time
        return self.cmd


def energy_rate(cmd, k_v, k_w):
    """The power model [W]: k_v * (vx^2 + vy^2) + k_w * wz^2."""
    return k_v * (cmd.vx ** 2 + cmd.vy ** 2) + k_w * cmd.wz ** 2


# --------------------------------------------------------------------------------------------
# A small kinematic simulation, for main() and the tests: no physics, no ROS.

def integrate(pose, cmd, dt):
    """Pose2D after driving the body-frame twist `cmd` for dt [s] (exact on the arc)."""
    vx, vy, wz = cmd
    turn = wz * dt
    if abs(turn) < 1e-9:
        dx, dy = vx * dt, vy * dt
    else:
        sin_t, cos_t = math.sin(turn), math.cos(turn)
        dx = (vx * sin_t + vy * (cos_t - 1.0)) / wz
        dy = (vx * (1.0 - cos_t) + vy * sin_t) / wz
    return compose(pose, Pose2D(dx, dy, turn))


#: Per time step: times [s]; leader: its Pose2D; followers: a list of their Pose2Ds (world
#: frame); errors: each follower's distance to its slot [m]; commands: each follower's filtered
#: command (Twist2D) sent at that step.
Simulation = namedtuple("Simulation", "times leader followers errors commands")


def simulate(law, config, slots, starts, leader_twist_at, duration, dt=0.05, leader_start=None):
    """Drive a leader with leader_twist_at(t) -> Twist2D and followers with `law`.

    slots: (x, y) of each follower in the leader frame; starts: their world Pose2Ds. Each follower
    has its own CommandFilter; diff-drive followers (config.omni False) get vy = 0.
    """
    leader = leader_start or Pose2D(0.0, 0.0, 0.0)
    followers = list(starts)
    filters = [CommandFilter(config) for _ in followers]
    times, leader_path, follower_paths, errors, sent = [], [], [], [], []
    for step in range(int(round(duration / dt)) + 1):
        t = step * dt
        twist = leader_twist_at(t)
        seen = [relative(leader, f) for f in followers]     # followers in the leader frame
        times.append(t)
        leader_path.append(leader)
        follower_paths.append(list(followers))
        errors.append([math.hypot(p.x - s[0], p.y - s[1]) for p, s in zip(seen, slots)])
        commands = []
        for i in range(len(followers)):
            neighbours = [(seen[j], slots[j]) for j in range(len(followers)) if j != i]
            cmd = law.compute(ControlInput(seen[i], slots[i], twist, neighbours, dt, filters[i].previous), config)
            cmd = filters[i].apply(cmd, dt, getattr(law, "smooth", True))
            if not config.omni:
                cmd = Twist2D(cmd.vx, 0.0, cmd.wz)
            commands.append(cmd)
        sent.append(commands)
        followers = [integrate(f, c, dt) for f, c in zip(followers, commands)]
        leader = integrate(leader, twist, dt)
    return Simulation(times, leader_path, follower_paths, errors, sent)


def curve_twist(t):
    """The demo leader: straight for 8 s, a left curve (radius 2 m) for 20 s, straight again."""
    if 8.0 <= t < 28.0:
        return Twist2D(0.3, 0.0, 0.15)
    return Twist2D(0.3, 0.0, 0.0)


def rms(values):
    return math.sqrt(sum(v * v for v in values) / len(values)) if values else 0.0


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--law", choices=sorted(CONTROL_LAWS), default="slot_tracking")
    parser.add_argument("--omni", action="store_true", help="holonomic followers (default: diff drive)")
    parser.add_argument("--duration", type=float, default=40.0, help="simulated time [s]")
    parser.add_argument("--plot", action="store_true", help="show the paths and errors (matplotlib)")
    args = parser.parse_args(argv)

    config = ControllerConfig(omni=args.omni)
    slots = [(-0.8, 0.8), (-0.8, -0.8)]                     # a wedge behind the leader
    starts = [Pose2D(-2.0, 1.5, 0.5), Pose2D(-1.0, -2.0, -1.0)]
    result = simulate(make_control_law(args.law), config, slots, starts, curve_twist, args.duration)
    final = rms(result.errors[-1])
    print("%s, %s followers, %.0f s: final RMS slot error %.4f m"
          % (args.law, "omni" if args.omni else "diff-drive", args.duration, final))

    if args.plot:
        import matplotlib.pyplot as plt   # only here: the library itself does not need it
        fig, (ax, ax_err) = plt.subplots(1, 2, figsize=(12, 5))
        ax.plot([p.x for p in result.leader], [p.y for p in result.leader], "k-", label="leader")
        for i in range(len(slots)):
            path = [poses[i] for poses in result.followers]
            ax.plot([p.x for p in path], [p.y for p in path], label="follower %d" % (i + 1))
            sx, sy = compose(result.leader[-1], Pose2D(slots[i][0], slots[i][1], 0.0))[:2]
            ax.plot(sx, sy, "kx")
        ax.set_aspect("equal")
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        ax.legend()
        for i in range(len(slots)):
            ax_err.plot(result.times, [e[i] for e in result.errors], label="follower %d" % (i + 1))
        ax_err.set_xlabel("t [s]")
        ax_err.set_ylabel("slot error [m]")
        ax_err.legend()
        plt.show()
    return 0


if __name__ == "__main__":
    sys.exit(main())
