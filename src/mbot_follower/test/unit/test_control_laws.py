"""Control laws in closed loop without ROS, the command filter, safety stop, the way round an
obstacle, energy model."""
import math
import random
import sys

import pytest

from mbot_common.geometry import Pose2D, Twist2D
from mbot_follower.control_laws import (CONTROL_LAWS, CommandFilter, Consensus, ControlInput,
                                        ControllerConfig, SlotTracking, detour, energy_rate, integrate,
                                        main, make_control_law, safety_filter, safety_stop, scan_points,
                                        simulate, slot_velocity, way_blocked)

DT = 0.05
SLOTS = [(-0.8, 0.8), (-0.8, -0.8), (-1.6, 0.0)]     # three followers behind the leader


def straight(t):
    return Twist2D(0.3, 0.0, 0.0)


def circle(t):
    return Twist2D(0.3, 0.0, 0.15)      # radius 2 m; the outer slot moves at ~0.42 m/s


def still(t):
    return Twist2D(0.0, 0.0, 0.0)


def random_starts(rng, slots, within=2.0):
    """World poses (the leader starts at the origin facing +x) within `within` m of each slot,
    facing anywhere."""
    starts = []
    for sx, sy in slots:
        r, a = within * math.sqrt(rng.random()), rng.uniform(-math.pi, math.pi)
        starts.append(Pose2D(sx + r * math.cos(a), sy + r * math.sin(a), rng.uniform(-math.pi, math.pi)))
    return starts


# ------------------------------------------------------------------ config

def test_config_defaults_and_live_update():
    c = ControllerConfig()
    assert (c.max_linear_vel, c.max_angular_vel, c.max_linear_accel, c.max_angular_accel) == (0.5, 1.5, 1.0, 3.0)
    assert c.smoothing == 0.3 and c.safety_distance == 0.8 and c.omni is False
    assert c.safety_half_angle == pytest.approx(math.radians(30))
    c.update({"max_linear_vel": 1, "k_position": 0.25, "omni": True})   # an int is a fine float
    assert c.max_linear_vel == 1.0 and isinstance(c.max_linear_vel, float)
    assert c.k_position == 0.25 and c.omni is True
    assert ControllerConfig(smoothing=1.0).smoothing == 1.0
    # every field has a rule, and nothing else is a field (the node lists the keys with vars())
    assert set(vars(ControllerConfig())) == set(ControllerConfig._RULES) == set(c.to_dict())


@pytest.mark.parametrize("values,says", [
    ({"max_speed": 1.0}, "ControllerConfig: unknown key 'max_speed' (known: "),
    ({"max_linear_vel": -0.5}, "ControllerConfig: max_linear_vel: expected a finite number > 0, got -0.5"),
    ({"max_angular_accel": 0}, "max_angular_accel: expected a finite number > 0, got 0.0"),
    ({"smoothing": 0.0}, "smoothing: expected a finite number in (0, 1], got 0.0"),
    ({"smoothing": 1.5}, "smoothing: expected a finite number in (0, 1], got 1.5"),
    ({"k_heading": True}, "k_heading: expected a number, got True"),
    ({"k_heading": "2.0"}, "k_heading: expected a number, got '2.0'"),
    ({"k_position": float("nan")}, "k_position: expected a finite number >= 0, got nan"),
    ({"safety_half_angle": 4.0}, "safety_half_angle: expected a finite number in [0, pi] [rad]"),
    ({"omni": 1}, "omni: expected true or false, got 1"),
])
def test_config_rejects_bad_values_and_changes_nothing(values, says):
    c = ControllerConfig()
    before = c.to_dict()
    with pytest.raises(ValueError) as e:
        c.update(dict(values, yield_speed=0.2))     # a good key in the same call is not applied
    assert says in str(e.value)
    assert c.to_dict() == before


def test_make_control_law():
    assert isinstance(make_control_law("slot_tracking"), SlotTracking)
    assert isinstance(make_control_law("consensus"), Consensus)
    assert sorted(CONTROL_LAWS) == ["consensus", "mpc", "slot_tracking"]
    with pytest.raises(ValueError, match=r"unknown control law 'pid' \(known: consensus, mpc, slot_tracking\)"):
        make_control_law("pid")


# ------------------------------------------------------------------ one step, by hand

def test_slot_velocity_is_v_plus_w_cross_s():
    assert slot_velocity((-1.0, 1.0), Twist2D(0.3, 0.0, 0.2)) == pytest.approx((0.1, -0.2))
    assert slot_velocity((-1.0, 1.0), Twist2D(0.3, 0.1, 0.0)) == pytest.approx((0.3, 0.1))


def test_omni_command_is_the_desired_velocity_in_the_body_frame():
    config = ControllerConfig(omni=True, k_position=0.5, k_heading=2.0)
    # in the slot, leader driving a curve: exactly the feed-forward
    inp = ControlInput(Pose2D(-1.0, 1.0, 0.0), (-1.0, 1.0), Twist2D(0.3, 0.0, 0.2), [])
    assert tuple(SlotTracking().compute(inp, config)) == pytest.approx((0.1, -0.2, 0.2))
    # 0.4 m right of its slot, turned 90 deg left, leader still: u = (0, 0.2) in the leader frame
    # is straight ahead for the robot; and it turns back by 2.0 * pi/2
    inp = ControlInput(Pose2D(-1.0, 0.6, math.pi / 2), (-1.0, 1.0), Twist2D(0, 0, 0), [])
    assert tuple(SlotTracking().compute(inp, config)) == pytest.approx((0.2, 0.0, -math.pi))


def test_diff_drive_turns_in_place_towards_a_slot_beside_it():
    config = ControllerConfig(k_position=0.5, k_heading=2.0)
    inp = ControlInput(Pose2D(-1.0, 0.0, 0.0), (-1.0, 1.0), Twist2D(0, 0, 0), [])
    assert tuple(SlotTracking().compute(inp, config)) == pytest.approx((0.0, 0.0, math.pi))


def test_diff_drive_never_backs_up_fast():
    config = ControllerConfig(k_position=0.8, k_heading=2.0, max_reverse_vel=0.1)
    # slot 2 m behind, leader still: u = (-1.6, 0): turn round, backing up at most 0.1 m/s
    inp = ControlInput(Pose2D(0.0, 0.0, 0.0), (-2.0, 0.0), Twist2D(0, 0, 0), [])
    assert tuple(SlotTracking().compute(inp, config)) == pytest.approx((-0.1, 0.0, 2.0 * math.pi))
    # 3 cm past a still slot: |u| = 0.024 < k_position * slot_tolerance = 0.08, so it keeps
    # facing the leader's way and backs up the 3 cm
    inp = ControlInput(Pose2D(-1.97, 0.0, 0.0), (-2.0, 0.0), Twist2D(0, 0, 0), [])
    assert tuple(SlotTracking().compute(inp, config)) == pytest.approx((-0.024, 0.0, 0.0))


def test_consensus_adds_the_neighbour_term():
    config = ControllerConfig(omni=True, k_position=1.0, k_consensus=0.5, k_heading=0.0)
    # both followers 0.2 m behind their slots: the neighbour term cancels (same error)
    me = Pose2D(-1.2, 1.0, 0.0)
    same = [(Pose2D(-1.2, -1.0, 0.0), (-1.0, -1.0))]
    inp = ControlInput(me, (-1.0, 1.0), Twist2D(0, 0, 0), same)
    assert tuple(Consensus().compute(inp, config)) == pytest.approx((0.2, 0.0, 0.0))
    assert tuple(SlotTracking().compute(inp, config)) == pytest.approx((0.2, 0.0, 0.0))
    # the neighbour is in its slot: (p_j - p_i) - (s_j - s_i) = (0.2, 0) adds 0.5 * 0.2
    exact = [(Pose2D(-1.0, -1.0, 0.0), (-1.0, -1.0))]
    inp = ControlInput(me, (-1.0, 1.0), Twist2D(0, 0, 0), exact)
    assert tuple(Consensus().compute(inp, config)) == pytest.approx((0.3, 0.0, 0.0))


def test_integrate_drives_a_full_circle_back_to_the_start():
    pose = Pose2D(1.0, 2.0, 0.5)
    for _ in range(100):
        pose = integrate(pose, Twist2D(0.5, 0.0, 2 * math.pi / 10.0), 0.1)   # 10 s per turn
    assert tuple(pose) == pytest.approx((1.0, 2.0, 0.5), abs=1e-9)
    half = integrate(Pose2D(0, 0, 0), Twist2D(1.0, 0.0, math.pi), 1.0)        # radius 1/pi
    assert tuple(half) == pytest.approx((0.0, 2 / math.pi, math.pi), abs=1e-12)
    side = integrate(Pose2D(0, 0, math.pi / 2), Twist2D(0.0, 0.4, 0.0), 2.0)  # omni sideways
    assert tuple(side) == pytest.approx((-0.8, 0.0, math.pi / 2), abs=1e-12)


# ------------------------------------------------------------------ closed loop

@pytest.mark.parametrize("law", sorted(set(CONTROL_LAWS) - {"mpc"}))   # mpc: test_mpc_law.py (a QP a step)
@pytest.mark.parametrize("omni", [False, True])
@pytest.mark.parametrize("path,bound", [(straight, 0.02), (circle, 0.05)])
def test_closed_loop_converges_from_random_starts(law, omni, path, bound):
    rng = random.Random(7)
    config = ControllerConfig(omni=omni)
    worst_tail, worst_settle = 0.0, 0.0
    for trial in range(8):
        result = simulate(make_control_law(law), config, SLOTS, random_starts(rng, SLOTS), path, 45.0, DT)
        tail = [max(e) for t, e in zip(result.times, result.errors) if t >= 35.0]
        worst_tail = max(worst_tail, max(tail))
        # settled: the last time any follower was more than 0.1 m off its slot
        late = [t for t, e in zip(result.times, result.errors) if max(e) > 0.1]
        worst_settle = max(worst_settle, late[-1] if late else 0.0)
        if not omni:
            assert all(c.vy == 0.0 for step in result.commands for c in step)
            assert min(c.vx for step in result.commands for c in step) >= -config.max_reverse_vel - 1e-12
        assert max(math.hypot(c.vx, c.vy) for step in result.commands for c in step) <= 0.5 + 1e-12
    assert worst_tail < bound
    assert worst_settle < 30.0


@pytest.mark.parametrize("omni", [False, True])
def test_still_leader_followers_stop_in_their_slots_facing_its_way(omni):
    rng = random.Random(3)
    config = ControllerConfig(omni=omni)
    for trial in range(8):
        result = simulate(SlotTracking(), config, SLOTS, random_starts(rng, SLOTS), still, 30.0, DT)
        final = result.errors[-1]
        headings = [abs(f.theta) for f in result.followers[-1]]   # the leader faces theta = 0
        if omni:
            assert max(final) < 1e-3 and max(headings) < 1e-3
        else:
            # a diff-drive robot cannot step sideways: within slot_tolerance is in the slot
            assert max(final) <= config.slot_tolerance and max(headings) < 0.01
        speeds = [abs(c.vx) + abs(c.vy) + abs(c.wz) for c in result.commands[-1]]
        assert max(speeds) < 1e-3


def test_consensus_keeps_the_shape_between_followers_better_than_slot_tracking():
    # follower 1 starts 0.5 m left of its slot, the others in theirs, the leader stands still
    starts = [Pose2D(-0.8, 1.3, 0.0), Pose2D(-0.8, -0.8, 0.0), Pose2D(-1.6, 0.0, 0.0)]
    config = ControllerConfig(omni=True, k_consensus=0.5)

    def shape_error(result, step):
        """Largest |(p_i - p_j) - (s_i - s_j)| between followers (leader frame = world here)."""
        p = result.followers[step]
        return max(math.hypot((p[i].x - p[j].x) - (SLOTS[i][0] - SLOTS[j][0]),
                              (p[i].y - p[j].y) - (SLOTS[i][1] - SLOTS[j][1]))
                   for i in range(3) for j in range(i))

    consensus = simulate(Consensus(), config, SLOTS, starts, still, 6.0, DT)
    tracking = simulate(SlotTracking(), config, SLOTS, starts, still, 6.0, DT)
    one_second = int(round(1.0 / DT))
    # differences decay at k_position + 3 k_consensus = 2.3 /s instead of k_position = 0.8 /s
    # (measured 0.058 m against 0.246 m)
    assert shape_error(consensus, one_second) < 0.5 * shape_error(tracking, one_second)
    # the price: the others leave their slots for a while; all are back after 6 s
    assert max(consensus.errors[one_second][1:]) > 0.05
    assert max(tracking.errors[one_second][1:]) < 1e-9
    assert max(consensus.errors[-1]) < 0.005


# ------------------------------------------------------------------ filter, safety, energy

def test_filter_smooths_then_limits_velocity():
    config = ControllerConfig(max_linear_accel=100.0, max_angular_accel=100.0)
    f = CommandFilter(config)
    assert tuple(f.apply(Twist2D(1.0, 0.0, -1.0), DT)) == pytest.approx((0.3, 0.0, -0.3))
    assert tuple(f.apply(Twist2D(1.0, 0.0, -1.0), DT)) == pytest.approx((0.5, 0.0, -0.51))  # 0.51 m/s capped
    assert tuple(f.apply(Twist2D(1.0, 0.0, -1.0), DT)) == pytest.approx((0.5, 0.0, -0.657))
    f.reset()
    assert tuple(f.apply(Twist2D(0.1, 0.0, 0.0), DT)) == pytest.approx((0.03, 0.0, 0.0))


def test_a_robot_held_by_the_safety_layer_keeps_turning_at_its_full_rate():
    """A wall 0.5 m ahead: every cycle the safety layer stops the travel and lets the turn
    through. Told what was sent, the filter keeps the turn's rate; the robot turns away."""
    from mbot_follower.control_laws import safety_filter

    config = ControllerConfig(max_angular_accel=100.0)
    n = 360
    ranges = [0.5 if abs(-math.pi + (i + 0.5) * 2 * math.pi / n) < math.radians(40) else float("inf")
              for i in range(n)]
    f = CommandFilter(config)
    for _ in range(20):
        out, held = safety_filter(f.apply(Twist2D(0.3, 0.0, 1.0), DT), ranges, -math.pi, 2 * math.pi / n, config)
        assert held and out.vx == 0.0
        f.sent(out)
    assert out.wz == pytest.approx(1.0, abs=0.01)   # smoothed up to the full command, not 30 % of it


def test_filter_limits_acceleration_and_reads_the_config_live():
    config = ControllerConfig(smoothing=1.0)       # no smoothing: the limits alone
    f = CommandFilter(config)
    out = [f.apply(Twist2D(1.0, 0.0, 2.0), 0.1) for _ in range(5)]
    assert [c.vx for c in out] == pytest.approx([0.1, 0.2, 0.3, 0.4, 0.5])   # 1.0 m/s^2, then 0.5 m/s
    assert [c.wz for c in out] == pytest.approx([0.3, 0.6, 0.9, 1.2, 1.5])   # 3.0 rad/s^2, then 1.5
    config.update({"max_linear_vel": 0.2, "max_angular_vel": 0.5})           # rosparam set
    assert tuple(f.apply(Twist2D(1.0, 0.0, 2.0), 0.1)) == pytest.approx((0.2, 0.0, 0.5))
    # an omni command is limited as a vector: its direction stays
    f.reset()
    c = f.apply(Twist2D(1.0, 1.0, 0.0), 0.1)
    assert (c.vx, c.vy) == pytest.approx((0.1 / math.sqrt(2), 0.1 / math.sqrt(2)))
    with pytest.raises(ValueError, match="dt must be a finite time > 0"):
        f.apply(Twist2D(0, 0, 0), 0.0)
    with pytest.raises(ValueError, match="command must be finite"):
        f.apply(Twist2D(float("nan"), 0, 0), 0.1)


BEAMS = 360
ANGLE_MIN = -math.pi
INC = 2 * math.pi / BEAMS


def scan(readings, default=float("inf")):
    """A 360-beam scan, beam i at -180 + i deg; readings: bearing [deg] -> range [m]."""
    ranges = [default] * BEAMS
    for bearing, r in readings.items():
        ranges[(bearing + 180) % 360] = r
    return ranges


@pytest.mark.parametrize("readings,stop", [
    ({}, False),                                   # +Inf everywhere: nothing in range
    ({0: 0.5}, True),
    ({25: 0.79}, True),
    ({-29: 0.1}, True),
    ({0: 0.8}, False),                             # not closer than the distance
    ({35: 0.1, -35: 0.1, 180: 0.05}, False),       # outside +-30 deg
    ({0: float("-inf")}, True),                    # REP-117: too close to measure
    ({0: float("nan"), 10: float("nan")}, False),  # REP-117: no reading, ignored
])
def test_safety_stop_with_rep117_values(readings, stop):
    assert safety_stop(scan(readings), ANGLE_MIN, INC, 0.8, math.radians(30)) is stop


def test_safety_stop_wraps_angles_of_a_scan_from_0_to_2pi():
    ranges = [float("inf")] * 360
    ranges[355] = 0.3                              # 355 deg = -5 deg: ahead
    assert safety_stop(ranges, 0.0, INC, 0.8, math.radians(30)) is True


# ------------------------------------------------------------------ a way round an obstacle

def disc_scan(pose, centre, radius, beams=BEAMS):
    """A 360-beam scan (beam i at -180 + i deg of the robot's heading) of one disc in the world."""
    ranges = []
    for i in range(beams):
        a = pose.theta + ANGLE_MIN + i * INC
        dx, dy = math.cos(a), math.sin(a)
        fx, fy = pose.x - centre[0], pose.y - centre[1]
        b = fx * dx + fy * dy
        disc = b * b - (fx * fx + fy * fy - radius * radius)
        t = -b - math.sqrt(disc) if disc >= 0.0 else -1.0
        ranges.append(t if t > 0.0 else float("inf"))
    return ranges


def test_scan_points_keep_readings_between_range_min_and_reach():
    ranges = scan({0: 1.0, 90: 0.05, -90: 3.0, 180: float("nan"), 45: float("-inf")})
    points = scan_points(ranges, ANGLE_MIN, INC, 0.1, 2.0)
    assert points == [pytest.approx((1.0, 0.0))]


@pytest.mark.parametrize("point,goal,blocked", [
    ((1.0, 0.0), (2.0, 0.0), True),      # on the way
    ((1.0, 0.34), (2.0, 0.0), True),     # within the clearance of it
    ((1.0, 0.36), (2.0, 0.0), False),
    ((-0.5, 0.0), (2.0, 0.0), False),    # behind the robot
    ((2.5, 0.0), (2.0, 0.0), False),     # beyond the goal
    ((2.5, 0.0), (4.0, 0.0), False),     # beyond the horizon (2 m)
    ((0.0, 1.0), (0.0, 1.5), True),      # the way need not be straight ahead
])
def test_way_blocked(point, goal, blocked):
    assert way_blocked([point], goal[0], goal[1], 2.0, 0.35) is blocked


def test_detour_takes_the_smallest_clear_turn_and_keeps_to_its_side():
    step, most = math.radians(15), math.radians(90)
    # a robot 1 m ahead, a little to the left of the way: the smallest right turn is clear first
    points = [(1.0, 0.1)]
    (x, y), side = detour(points, 2.0, 0.0, 2.0, 0.35, step, most, prefer=1)
    assert side == -1 and math.degrees(math.atan2(y, x)) == pytest.approx(-15.0)
    assert math.hypot(x, y) == pytest.approx(2.0)          # as far away as the goal
    # right in the way: both sides are equally good, the preferred one wins
    assert detour([(1.0, 0.0)], 2.0, 0.0, 2.0, 0.35, step, most, prefer=-1)[1] == -1
    assert detour([(1.0, 0.0)], 2.0, 0.0, 2.0, 0.35, step, most, prefer=1)[1] == 1
    # a map that refuses the left side
    (x, y), side = detour([(1.0, 0.0)], 2.0, 0.0, 2.0, 0.35, step, most, prefer=1, is_free=lambda x, y: y < 0.0)
    assert side == -1
    # walled in on both sides within 90 degrees: no way round
    wall = [(0.5, 0.1 * k) for k in range(-10, 11)] + [(0.1 * k, 0.5) for k in range(6)] + \
        [(0.1 * k, -0.5) for k in range(6)]
    assert detour(wall, 2.0, 0.0, 2.0, 0.35, step, most) is None


def test_a_robot_steers_round_a_standing_robot_to_the_slot_beyond_it():
    """A diff-drive follower whose slot lies 3 m ahead, beyond a robot standing on the straight
    way (the situation after a loss): with the way round it reaches the slot and passes the
    standing robot with room to spare; its safety layer never has to stop it."""
    config = ControllerConfig()
    law, f = SlotTracking(), CommandFilter(config)
    pose, slot, other = Pose2D(0.0, 0.0, 0.0), (3.0, 0.0), (1.5, 0.05)
    side, nearest, held = 1, float("inf"), 0
    for _ in range(int(20.0 / DT)):
        ranges = disc_scan(pose, other, 0.15)
        points = scan_points(ranges, ANGLE_MIN, INC, 0.1, 2.35)
        goal = Pose2D(slot[0] - pose.x, slot[1] - pose.y, 0.0)
        c, s = math.cos(-pose.theta), math.sin(-pose.theta)
        gx, gy = c * goal.x - s * goal.y, s * goal.x + c * goal.y
        target = slot
        if way_blocked(points, gx, gy, 2.0, 0.35):
            (wx, wy), side = detour(points, gx, gy, 2.0, 0.35, math.radians(15), math.radians(90), side)
            c, s = math.cos(pose.theta), math.sin(pose.theta)
            target = (pose.x + c * wx - s * wy, pose.y + s * wx + c * wy)
        cmd = law.compute(ControlInput(pose, target, Twist2D(0.0, 0.0, 0.0), []), config)
        cmd, stopped = safety_filter(f.apply(cmd, DT), ranges, ANGLE_MIN, INC, config)
        held += stopped
        pose = integrate(pose, cmd, DT)
        nearest = min(nearest, math.hypot(pose.x - other[0], pose.y - other[1]))
    assert math.hypot(pose.x - slot[0], pose.y - slot[1]) < 0.1
    assert nearest > 0.45 and held == 0


def test_energy_rate():
    assert energy_rate(Twist2D(0.5, 0.0, 1.0), 4.0, 0.5) == pytest.approx(4.0 * 0.25 + 0.5 * 1.0)
    assert energy_rate(Twist2D(0.3, 0.4, 0.0), 2.0, 0.5) == pytest.approx(0.5)


# ------------------------------------------------------------------ the demo

@pytest.mark.parametrize("args,kind", [([], "slot_tracking, diff-drive"),
                                       (["--omni", "--law", "consensus"], "consensus, omni")])
def test_main_runs_without_plotting(args, kind, capsys):
    had_pyplot = "matplotlib.pyplot" in sys.modules
    assert main(args) == 0
    out = capsys.readouterr().out
    assert out.startswith(kind)
    assert float(out.split("final RMS slot error")[1].split()[0]) < 0.01
    assert ("matplotlib.pyplot" in sys.modules) == had_pyplot


@pytest.mark.parametrize("cmd, obstacle_at_deg, distance, stops", [
    (Twist2D(0.3, 0.0, 0.2), 0, 0.7, True),        # ahead, inside 0.8 m
    (Twist2D(0.3, 0.0, 0.2), 0, 0.9, False),       # ahead, beyond
    (Twist2D(0.3, 0.0, 0.2), 180, 0.3, False),     # behind a robot driving forwards
    (Twist2D(-0.1, 0.0, 0.0), 180, 0.7, True),     # behind a robot backing up
    (Twist2D(0.3, 0.0, 0.0), 45, 0.3, True),       # at its shoulder, in the lane it sweeps
    (Twist2D(0.3, 0.0, 0.0), 70, 0.4, False),      # beside it (0.38 m aside): a door jamb it passes
    (Twist2D(0.3, 0.0, 0.0), 100, 0.2, False),     # close, but behind its side: driving on moves away
    (Twist2D(0.3, 0.0, 0.0), 60, float("-inf"), True),  # too close to measure, on the front half
    (Twist2D(0.0, 0.3, 0.0), 90, 0.7, True),       # omni driving left, something left
    (Twist2D(0.0, 0.0, 1.0), 0, 0.2, False),       # turning on the spot is never stopped
])
def test_safety_filter_looks_where_the_robot_drives(cmd, obstacle_at_deg, distance, stops):
    from mbot_follower.control_laws import safety_filter
    n = 360
    ranges = [float("inf")] * n
    ranges[(obstacle_at_deg + 180) % n] = distance           # beams from -pi, 1 deg apart
    out, stopped = safety_filter(cmd, ranges, -math.pi, 2 * math.pi / n, ControllerConfig())
    assert stopped == stops
    if stops:
        assert (out.vx, out.vy, out.wz) == (0.0, 0.0, cmd.wz)
    else:
        assert out == cmd


def test_a_robot_drives_on_through_a_door_but_stops_before_its_jamb():
    """A door 0.9 m wide in a wall across the way, robot centred 0.2 m before it: the jambs lie
    beside its lane and it drives on. Shifted 0.3 m to the side, a jamb lies in its lane: stop."""
    from mbot_follower.control_laws import lane_blocked
    n = 720
    inc = 2 * math.pi / n

    def wall_with_door(offset):
        ranges = []
        for i in range(n):
            a = -math.pi + i * inc
            c = math.cos(a)
            if c <= 1e-9:
                ranges.append(float("inf"))
                continue
            r = 0.2 / c                      # the wall is 0.2 m ahead
            y = r * math.sin(a) + offset     # where the beam meets it, relative to the door centre
            ranges.append(r if abs(y) > 0.45 and r < 10.0 else float("inf"))
        return ranges

    assert not lane_blocked(wall_with_door(0.0), -math.pi, inc, 0.45, 0.25)
    assert lane_blocked(wall_with_door(0.3), -math.pi, inc, 0.45, 0.25)


def test_give_way_backs_away_after_being_held_the_one_further_back_first():
    from mbot_follower.control_laws import GiveWay
    n = 360
    ranges = [float("inf")] * n
    ranges[180 + 20] = 0.4                       # something 20 deg left of ahead, 0.4 m away
    scan = (ranges, -math.pi, 2 * math.pi / n)
    config = ControllerConfig()
    front, back = GiveWay(), GiveWay()           # rank 1: one slot lies farther back; rank 0: none
    t = 0.0
    assert front.step(t, True, *scan, rank=1, config=config) is None
    assert back.step(t, True, *scan, rank=0, config=config) is None
    t = 1.05                                     # after yield_after: only the one further back gives way
    assert front.step(t, True, *scan, rank=1, config=config) is None
    cmd = back.step(t, True, *scan, rank=0, config=config)
    assert cmd == Twist2D(-config.yield_speed, 0.0, 0.0)        # backs away from what is ahead
    assert back.step(t + 1.0, False, *scan, rank=0, config=config) == cmd   # for yield_time
    assert back.step(t + config.yield_time + 0.01, False, *scan, rank=0, config=config) is None
    assert front.step(t + 0.1, False, *scan, rank=1, config=config) is None  # freed: the clock restarts
    assert front.step(1.6, True, *scan, rank=1, config=config) is None


def test_give_way_of_an_omni_robot_moves_straight_away():
    from mbot_follower.control_laws import GiveWay
    n = 360
    ranges = [float("inf")] * n
    ranges[180 + 90] = 0.3                       # on its left
    config = ControllerConfig(omni=True)
    g = GiveWay()
    g.step(0.0, True, ranges, -math.pi, 2 * math.pi / n, rank=0, config=config)
    cmd = g.step(1.1, True, ranges, -math.pi, 2 * math.pi / n, rank=0, config=config)
    assert cmd.vx == pytest.approx(0.0, abs=1e-9) and cmd.vy == pytest.approx(-config.yield_speed)


def _reference_checks(ranges, angle_min, inc, config):
    """The laser checks beam by beam, as written before they were vectorised (numpy)."""
    import math as m

    from mbot_common.geometry import normalize_angle
    stop = lane = False
    for i, r in enumerate(ranges):
        a = normalize_angle(angle_min + i * inc)
        if abs(a) <= config.safety_half_angle and not m.isnan(r) and \
                (r == -m.inf or (m.isfinite(r) and r < config.safety_distance)):
            stop = True
        if not m.isnan(r) and abs(a) <= m.pi / 2 and (r == -m.inf or (
                m.isfinite(r) and 0.0 < r * m.cos(a) < config.safety_near_distance
                and abs(r * m.sin(a)) < config.safety_lane_half_width)):
            lane = True
    points = [(r * m.cos(angle_min + i * inc), r * m.sin(angle_min + i * inc))
              for i, r in enumerate(ranges) if 0.12 <= r <= 2.35]
    return stop, lane, points


def test_the_vectorised_laser_checks_agree_with_the_beam_by_beam_rules_on_random_scans():
    import random

    from mbot_follower.control_laws import ControllerConfig, lane_blocked, safety_stop, scan_points
    rng = random.Random(7)
    config = ControllerConfig()
    agreed = {"stop": 0, "lane": 0}
    for _ in range(300):
        n = rng.choice([90, 360, 361])
        angle_min = rng.uniform(-4.0, 1.0)
        inc = 2 * math.pi / n
        ranges = [rng.choice([math.inf, -math.inf, math.nan, rng.uniform(0.0, 1.2), rng.uniform(0.0, 9.0)])
                  if rng.random() < 0.02 else rng.uniform(0.3, 9.0) for _ in range(n)]
        stop, lane, points = _reference_checks(ranges, angle_min, inc, config)
        assert safety_stop(ranges, angle_min, inc, config.safety_distance, config.safety_half_angle) == stop
        assert lane_blocked(ranges, angle_min, inc, config.safety_near_distance, config.safety_lane_half_width) == lane
        got = scan_points(ranges, angle_min, inc, 0.12, 2.35)
        assert len(got) == len(points)
        assert all(abs(a[0] - b[0]) < 1e-9 and abs(a[1] - b[1]) < 1e-9 for a, b in zip(got, points))
        agreed["stop"] += stop
        agreed["lane"] += lane
    assert 10 < agreed["stop"] < 290 and 5 < agreed["lane"] < 295   # both answers were exercised
