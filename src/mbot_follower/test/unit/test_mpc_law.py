"""The predictive law (mpc_law.py) without ROS: its solutions keep the limits and the distance
constraints, it converges and tracks a turn better than slot tracking, it falls back (and counts
it) when the QP cannot be solved or takes too long, and bad settings are refused by name."""
import math

import numpy as np
import pytest

from mbot_common.geometry import Pose2D, Twist2D
from mbot_follower.control_laws import (CommandFilter, ControlInput, ControllerConfig, SlotTracking, curve_twist,
                                        integrate, make_control_law, simulate)
from mbot_follower.mpc_law import MpcError, MpcLaw, thin_points

DT = 0.05
SLOTS = [(-0.8, 0.8), (-0.8, -0.8), (-1.6, 0.0)]
TOL = 1e-6


def config(**values):
    # correctness, not speed: the time budget is the benchmark's (a busy machine must not fail these)
    values.setdefault("mpc_time_budget", 30.0)
    return ControllerConfig(**values)


def check_limits(law, cfg, previous):
    """The planned inputs keep the velocity and acceleration limits (hard constraints)."""
    inputs, dt, omni = law._solution
    period = dt / cfg.mpc_step
    assert len(inputs) == cfg.mpc_horizon
    w = inputs[:, -1]
    assert np.all(np.abs(w) <= cfg.max_angular_vel + TOL)
    prev = np.array([previous.vx, previous.vy, previous.wz] if omni else [previous.vx, previous.wz])
    change = np.diff(np.vstack([prev, inputs]), axis=0)
    steps = np.full(len(inputs), dt)
    steps[0] = period
    assert np.all(np.abs(change[:, -1]) <= cfg.max_angular_accel * steps + TOL)
    if omni:
        assert np.all(np.hypot(inputs[:, 0], inputs[:, 1]) <= cfg.max_linear_vel + TOL)
        assert np.all(np.hypot(change[:, 0], change[:, 1]) <= cfg.max_linear_accel * steps + TOL)
    else:
        assert np.all(inputs[:, 0] <= cfg.max_linear_vel + TOL)
        assert np.all(inputs[:, 0] >= -cfg.max_reverse_vel - TOL)
        assert np.all(np.abs(change[:, 0]) <= cfg.max_linear_accel * steps + TOL)


@pytest.mark.parametrize("omni", [False, True])
@pytest.mark.parametrize("seed", range(6))
def test_solution_keeps_velocity_and_acceleration_limits(omni, seed):
    rng = np.random.RandomState(seed)
    cfg = config(omni=omni)
    law = MpcLaw()
    pose = Pose2D(rng.uniform(-3, 1), rng.uniform(-2, 2), rng.uniform(-math.pi, math.pi))
    previous = Twist2D(rng.uniform(-0.1, 0.4), rng.uniform(-0.2, 0.2) if omni else 0.0, rng.uniform(-1, 1))
    twist = Twist2D(rng.uniform(0, 0.35), 0.0, rng.uniform(-0.3, 0.3))
    cmd = law.compute(ControlInput(pose, (-1.0, 0.5), twist, [], DT, previous), cfg)
    assert law.fallbacks == 0, law.reasons
    check_limits(law, cfg, previous)
    inputs = law._solution[0]
    assert tuple(cmd) == pytest.approx((inputs[0][0], inputs[0][1], inputs[0][2]) if omni else
                                       (inputs[0][0], 0.0, inputs[0][1]))
    assert law.prediction.shape == (cfg.mpc_horizon + 1, 3)


@pytest.mark.parametrize("omni", [False, True])
def test_obstacle_half_planes_hold_on_the_way_to_the_slot(omni):
    """A laser point (a box) on the straight way to a still slot 2 m ahead: the robot drives at
    it, round it and on to its slot. Every QP solution without slack (most of them) keeps its
    half-planes: its positions keep mpc_obstacle_distance from the box; the robot does too
    (within the linearisation's centimetre)."""
    cfg = config(omni=omni)
    law = MpcLaw()
    limit = CommandFilter(cfg)
    limit.previous = Twist2D(0.3, 0.0, 0.0)
    box = np.array([[1.0, 0.02], [1.0, -0.05], [1.05, 0.0]])
    pose = Pose2D(0.0, 0.0, 0.0)
    closest, kept = [], 0
    for _ in range(240):
        previous = limit.previous
        relaxed = law.relaxed
        cmd = law.compute(ControlInput(pose, (2.0, 0.0), Twist2D(0, 0, 0), [], DT, previous, box), cfg)
        assert law.fallbacks == 0, law.reasons
        check_limits(law, cfg, previous)
        if law.relaxed == relaxed:
            kept += 1
            planned = law.linear_prediction
            gap = np.min(np.hypot(planned[:, None, 0] - box[None, :, 0], planned[:, None, 1] - box[None, :, 1]))
            # closer than the distance already (the linearisation's millimetres): not closer than now
            need = min(cfg.mpc_obstacle_distance, np.min(np.hypot(box[:, 0] - pose.x, box[:, 1] - pose.y)) - 1e-3)
            assert gap >= need - 1e-3   # slack up to 1 mm counts as kept
        pose = integrate(pose, limit.apply(cmd, DT, smooth=False), DT)
        closest.append(np.min(np.hypot(box[:, 0] - pose.x, box[:, 1] - pose.y)))
    assert kept >= 200
    assert min(closest) >= cfg.mpc_obstacle_distance - 0.01
    assert min(closest) < cfg.mpc_obstacle_distance + 0.05   # it came close: the constraint was active
    assert math.hypot(pose.x - 2.0, pose.y) < 0.05            # and it reached the slot behind the box


def test_teammate_prediction_half_planes_hold():
    """A teammate predicted to cross the robot's way: every planned position keeps
    mpc_robot_distance from the teammate's position at the same step."""
    cfg = config()
    law = MpcLaw()
    n = cfg.mpc_horizon
    dt = DT * cfg.mpc_step
    # the teammate drives from (0.8, -0.6) north at 0.4 m/s, across the robot's way east
    mate = np.array([(0.8, -0.6 + 0.4 * k * dt) for k in range(n + 1)])
    inp = ControlInput(Pose2D(0.0, 0.0, 0.0), (2.0, 0.0), Twist2D(0, 0, 0), [], DT, Twist2D(0.4, 0, 0), (), [mate])
    law.compute(inp, cfg)
    assert law.fallbacks == 0, law.reasons
    assert law.relaxed == 0
    gaps = np.hypot(*(law.linear_prediction - mate[1:]).T)
    assert gaps.min() >= cfg.mpc_robot_distance - 1e-3
    # without the teammate the plan would pass closer (the constraint shaped it)
    free = MpcLaw()
    free.compute(inp._replace(teammates=()), cfg)
    assert np.hypot(*(free.prediction[1:, :2] - mate[1:]).T).min() < cfg.mpc_robot_distance


@pytest.mark.parametrize("omni", [False, True])
def test_straight_line_converges_to_the_slot(omni):
    cfg = config(omni=omni)
    starts = [Pose2D(-2.0, 1.5, 0.5), Pose2D(-1.0, -2.0, -1.0), Pose2D(-2.5, 0.3, 2.0)]
    law = make_control_law("mpc")
    result = simulate(law, cfg, SLOTS, starts, lambda t: Twist2D(0.3, 0.0, 0.0), 30.0, DT)
    errors = np.array(result.errors)
    assert law.fallbacks == 0, law.reasons
    assert errors[-int(10 / DT):].max() < 0.02
    settled = next(i for i, e in enumerate(errors) if e.max() < 0.1) * DT
    assert settled < 20.0


@pytest.mark.parametrize("omni", [False, True])
def test_turn_error_below_slot_tracking(omni):
    """The leader drives straight, a left curve (radius 2 m), straight again; the followers start
    in their slots. The MPC's slot error RMS is below slot tracking's (it plans within the limits
    instead of being smoothed, and aims at where the slot will be)."""
    cfg = config(omni=omni)
    starts = [Pose2D(x, y, 0.0) for x, y in SLOTS]
    rms = {}
    for name in ("slot_tracking", "mpc"):
        law = make_control_law(name)
        errors = np.array(simulate(law, cfg, SLOTS, starts, curve_twist, 36.0, DT).errors)
        rms[name] = math.sqrt(float(np.mean(errors ** 2)))
    assert rms["mpc"] < 0.9 * rms["slot_tracking"], rms


def test_infeasible_problem_falls_back_to_slot_tracking_and_counts():
    """The last command 0.5 m/s while the limit is now 0.1 m/s and the deceleration 0.1 m/s^2:
    no first command keeps both, the QP is infeasible, slot tracking commands, counted."""
    cfg = config(max_linear_vel=0.1, max_linear_accel=0.1)
    law = MpcLaw()
    inp = ControlInput(Pose2D(-1.5, 0.2, 0.1), (-1.0, 0.5), Twist2D(0.1, 0, 0), [], DT, Twist2D(0.5, 0.0, 0.0))
    cmd = law.compute(inp, cfg)
    assert law.fallbacks == 1 and law.solves == 1
    assert sum(law.reasons.values()) == 1
    assert law.last_reason == "infeasible" or law.last_reason.startswith("solver"), law.reasons
    assert tuple(cmd) == pytest.approx(tuple(SlotTracking().compute(inp, cfg)))
    assert law.stats()["fallbacks"] == 1
    assert law.prediction is not None   # the teammates still get a prediction (slot tracking's)
    # feasible again: solved, the count stays
    law.compute(inp._replace(previous=Twist2D(0.1, 0.0, 0.0)), cfg)
    assert law.fallbacks == 1 and law.solves == 2 and law.last_reason is None


def test_past_the_time_budget_falls_back_and_counts():
    cfg = config(mpc_time_budget=1e-9)
    law = MpcLaw()
    inp = ControlInput(Pose2D(-1.5, 0.2, 0.1), (-1.0, 0.5), Twist2D(0.2, 0, 0), [], DT, Twist2D(0.1, 0, 0))
    cmd = law.compute(inp, cfg)
    assert law.reasons == {"time": 1} and law.fallbacks == 1
    assert tuple(cmd) == pytest.approx(tuple(SlotTracking().compute(inp, cfg)))
    assert law.stats()["solve_ms_p50"] > 0.0   # the solve was timed


@pytest.mark.parametrize("values,says", [
    ({"mpc_horizon": 0}, "mpc_horizon: expected a whole number in [1, 100], got 0"),
    ({"mpc_horizon": 12.5}, "mpc_horizon: expected a whole number in [1, 100], got 12.5"),
    ({"mpc_step": True}, "mpc_step: expected a whole number in [1, 20], got True"),
    ({"mpc_time_budget": float("nan")}, "mpc_time_budget: expected a finite number > 0, got nan"),
    ({"mpc_q_position": 0}, "mpc_q_position: expected a finite number > 0, got 0.0"),
    ({"mpc_robot_distance": -0.1}, "mpc_robot_distance: expected a finite number >= 0, got -0.1"),
])
def test_bad_settings_refused_by_name(values, says):
    cfg = ControllerConfig()
    with pytest.raises(ValueError) as error:
        cfg.update(values)
    assert says in str(error.value)
    assert cfg.mpc_horizon == 15 and cfg.mpc_time_budget == 0.02   # nothing changed


def test_bad_input_to_the_law_is_a_clear_error():
    law = MpcLaw()
    good = ControlInput(Pose2D(-1.0, 0.0, 0.0), (-1.0, 0.5), Twist2D(0.2, 0, 0), [], DT, None)
    cfg = config()
    cfg.mpc_horizon = 0   # set around update()'s checks: the law checks again
    with pytest.raises(MpcError, match=r"mpc_horizon must be a whole number >= 1, got 0"):
        law.compute(good, cfg)
    cfg = config()
    with pytest.raises(MpcError, match=r"pose, slot and leader twist must be finite"):
        law.compute(good._replace(pose=Pose2D(float("nan"), 0.0, 0.0)), cfg)
    with pytest.raises(MpcError, match=r"control period dt must be a finite time > 0"):
        law.compute(good._replace(dt=None), cfg)
    cfg.mpc_time_budget = float("nan")
    with pytest.raises(MpcError, match=r"mpc_time_budget must be a finite number >= 0, got nan"):
        law.compute(good, cfg)
    assert law.solves == 0   # refused before any solve


def test_thin_points():
    points = [(1.0, 0.0), (1.01, 0.01), (0.5, 0.01), (0.0, 2.0), (-3.0, 0.0), (0.0, -0.4)]
    kept = thin_points(points, reach=1.5, cell=0.05)
    assert sorted(map(tuple, np.round(kept, 3))) == [(0.0, -0.4), (0.5, 0.01), (1.0, 0.0)]
    assert thin_points([], reach=1.0).shape == (0, 2)
