"""The metrics collector measures the numbers it promises, on synthetic runs with known answers."""
import json
import math

import numpy as np
import pytest

from mbot_follower.fleet_io import Assignment
from mbot_follower.metrics import (MetricsCollector, MetricsConfig, RunFileError, RunWriter,
                                   distance_to_polyline, load_run, main, summarize)

GT_HZ = 50   # ground-truth rate of the simulator [Hz]
WEDGE = {"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.5), "robot_2": (-1.0, -0.5)}


def wedge(slots=None, formation="wedge"):
    slots = slots or WEDGE
    return Assignment("robot_0", formation, 1.0, dict(slots), {r: "robot_0" for r in slots})


def drive(collector, t_from, t_to, poses, at=None):
    """Feed every robot's ground truth at GT_HZ for t in [t_from, t_to): poses(t) -> {robot: (x, y, theta)}.
    at(t), if given, runs first at every step (status, assignment, ... at that time)."""
    for i in range(int(round(t_from * GT_HZ)), int(round(t_to * GT_HZ))):
        t = i / float(GT_HZ)
        if at is not None:
            at(t)
        for robot, (x, y, theta) in poses(t).items():
            collector.on_pose(robot, t, x, y, theta)


def near(t, when):
    return abs(t - when) < 1e-9


def test_slot_errors_rms_p95_max_per_follower_and_fleet():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge())
    c.on_status(0.0, "NAVIGATING", "goal", [])
    # The leader drives along x at 0.5 m/s; robot_1 is 0.1 m left of its slot all the time;
    # robot_2's error grows 0.1 m per second (0.01 k at sample k).
    drive(c, 0.0, 10.0, lambda t: {"robot_0": (0.5 * t, 0.0, 0.0),
                                   "robot_1": (0.5 * t - 1.0, 0.6, 0.0),
                                   "robot_2": (0.5 * t - 1.0, -0.5 - 0.1 * t, 0.0)})
    s = summarize(c.run)
    assert s["samples"] == 100                       # 0.0 .. 9.9 s at 10 Hz
    r1, r2, fleet = s["robots"]["robot_1"], s["robots"]["robot_2"], s["fleet"]
    assert r1["slot_rms_m"] == pytest.approx(0.1)
    assert r1["slot_p95_m"] == pytest.approx(0.1)
    assert r1["slot_max_m"] == pytest.approx(0.1)
    e2 = [0.01 * k for k in range(100)]
    assert r2["slot_rms_m"] == pytest.approx(math.sqrt(sum(e * e for e in e2) / 100))   # 0.5730
    assert r2["slot_p95_m"] == pytest.approx(0.9405)  # between the 95th (0.94) and 96th (0.95) value
    assert r2["slot_max_m"] == pytest.approx(0.99)
    assert fleet["slot_rms_m"] == pytest.approx(math.sqrt((100 * 0.01 + sum(e * e for e in e2)) / 200))
    assert fleet["slot_max_m"] == pytest.approx(0.99)
    assert fleet["slot_samples"] == 200
    assert s["robots"]["robot_0"]["slot_samples"] == 0   # the leader has no slot error
    # A fit may move the shape, so it never explains less than the slots do.
    assert r2["fit_rms_m"] < r2["slot_rms_m"]
    # Distance: up to the last sample (9.9 s).
    assert s["robots"]["robot_0"]["distance_m"] == pytest.approx(0.5 * 9.9)
    assert s["robots"]["robot_2"]["distance_m"] == pytest.approx(math.hypot(0.5, 0.1) * 9.9)
    assert fleet["time_in_state_s"] == {"NAVIGATING": pytest.approx(9.9)}


def test_rotated_formation_has_plain_errors_but_no_fit_error():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge())
    turn = math.radians(30.0)
    rot = np.array([[math.cos(turn), -math.sin(turn)], [math.sin(turn), math.cos(turn)]])
    lead = np.array([2.0, 1.0])
    poses = {"robot_0": (2.0, 1.0, 0.0)}
    for r in ("robot_1", "robot_2"):   # the whole shape turned by 30 deg about the leader
        x, y = lead + rot @ np.array(WEDGE[r])
        poses[r] = (x, y, turn)
    drive(c, 0.0, 2.0, lambda t: poses)
    s = summarize(c.run)
    plain = 2.0 * math.hypot(1.0, 0.5) * math.sin(turn / 2.0)   # chord of a 30 deg turn: 0.5787 m
    assert s["fleet"]["slot_rms_m"] == pytest.approx(plain)
    assert s["fleet"]["slot_max_m"] == pytest.approx(plain)
    assert s["fleet"]["fit_rms_m"] < 1e-9
    assert s["fleet"]["fit_max_m"] < 1e-9
    last = c.run.samples[-1]
    assert last.edge_max < 1e-9
    assert last.heading_max == pytest.approx(turn)


def test_distance_to_polyline():
    plan = [(0.0, 0.0), (5.0, 0.0), (5.0, 5.0)]
    assert distance_to_polyline(2.0, 0.3, plan) == pytest.approx(0.3)
    assert distance_to_polyline(6.0, 2.0, plan) == pytest.approx(1.0)
    assert distance_to_polyline(6.0, -1.0, plan) == pytest.approx(math.sqrt(2.0))   # the corner
    assert distance_to_polyline(-3.0, 4.0, plan) == pytest.approx(5.0)             # the start
    assert distance_to_polyline(1.0, 1.0, [(1.0, 4.0)]) == pytest.approx(3.0)       # one point
    assert distance_to_polyline(1.0, 1.0, [(0.0, 0.0), (0.0, 0.0), (2.0, 0.0)]) == pytest.approx(1.0)
    with pytest.raises(ValueError, match="no points"):
        distance_to_polyline(0.0, 0.0, [])


def test_leader_lateral_error_counts_while_navigating_on_the_current_plan():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}, "column"))
    c.on_plan("robot_0", 0.0, [(0.0, 0.0), (5.0, 0.0), (5.0, 5.0)])
    c.on_plan("robot_1", 0.0, [(0.0, 3.0), (5.0, 3.0)])   # not the leader's: never used
    c.on_status(0.0, "NAVIGATING", "goal", [])

    def at(t):
        if near(t, 4.0):
            c.on_status(t, "ARRIVED", "at the target", [])

    # 0.2 m left of the first leg for 2 s, 0.5 m for 2 s; then ARRIVED far away (not counted).
    drive(c, 0.0, 6.0, lambda t: {"robot_0": (0.5 * t, 0.2 if t < 2.0 else 0.5, 0.0) if t < 4.0 else (9.0, 9.0, 0.0),
                                  "robot_1": (0.5 * t - 1.0, 0.0, 0.0)}, at)
    s = summarize(c.run)
    assert s["fleet"]["leader_lateral_rms_m"] == pytest.approx(math.sqrt((0.2 ** 2 + 0.5 ** 2) / 2))
    assert s["fleet"]["leader_lateral_max_m"] == pytest.approx(0.5)
    assert c.run.samples[-1].leader_lateral == pytest.approx(math.hypot(4.0, 4.0))  # recorded, not counted
    c.on_plan("robot_0", 5.9, [])   # an empty plan clears it (from its time: the leader's last pose is at 5.98 s)
    assert math.isnan(c.sample(6.0).leader_lateral)


def test_a_new_goal_forgets_the_old_goals_plan():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}, "column"))
    c.on_status(0.0, "NAVIGATING", "goal", [])
    c.on_plan("robot_0", 0.0, [(0.0, 0.0), (5.0, 0.0)])
    c.on_status(1.0, "ARRIVED", "at the target", [])
    c.on_status(2.0, "FORMING", "a new target", [])
    c.on_status(3.0, "NAVIGATING", "formation reached", [])

    def at(t):
        if near(t, 5.0):   # the new goal's plan comes late (a busy nav node)
            c.on_plan("robot_0", t, [(0.0, 2.0), (0.0, 9.0)])

    # the leader drives north on the new goal's way, 2 m away from the old plan
    drive(c, 3.0, 7.0, lambda t: {"robot_0": (0.0, 2.0 + 0.5 * (t - 3.0), 1.57), "robot_1": (0.0, 1.0, 1.57)}, at)
    lateral = [s.leader_lateral for s in c.run.samples]
    assert all(math.isnan(v) for v in lateral[:19])        # 3.0 .. 4.9 s: no plan for this goal yet
    assert max(lateral[21:]) < 1e-9                         # on the new plan
    assert summarize(c.run)["fleet"]["leader_lateral_max_m"] < 1e-9


def test_a_sample_uses_the_assignment_and_status_in_force_at_its_time():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge())
    c.on_status(0.0, "NAVIGATING", "goal", [])
    still = {"robot_0": (0.0, 0.0, 0.0), "robot_1": (-1.0, 0.5, 0.0), "robot_2": (-1.0, -0.5, 0.0)}
    drive(c, 0.0, 1.98, lambda t: still)            # in their wedge slots: the sample at 1.9 s is the last
    # robot_1 is lost at 2.05 s: the new assignment (robot_2 in robot_1's slot) and then the status
    # arrive before the pose that takes the sample at 2.0 s
    c.on_assignment(2.05, wedge({"robot_0": (0.0, 0.0), "robot_2": (-1.0, 0.5)}))
    c.on_status(2.05, "DEGRADED", "lost robot_1", ["robot_1"])
    drive(c, 2.0, 2.2, lambda t: still)
    at_2, at_21 = c.run.samples[-2], c.run.samples[-1]
    assert (at_2.t, at_2.state, at_2.formation, at_2.lost) == (2.0, "NAVIGATING", "wedge", ())
    assert at_2.robots["robot_2"].slot_error == pytest.approx(0.0)     # still its old slot
    assert (at_21.t, at_21.state, at_21.lost) == (pytest.approx(2.1), "DEGRADED", ("robot_1",))
    assert at_21.robots["robot_2"].slot_error == pytest.approx(1.0)    # the new slot, 1 m away
    assert math.isnan(at_21.robots["robot_1"].slot_error)


def test_an_assignment_counts_once_the_status_of_its_time_has_come():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge())
    c.on_status(0.0, "NAVIGATING", "goal", [])
    still = {"robot_0": (0.0, 0.0, 0.0), "robot_1": (-1.0, 0.5, 0.0), "robot_2": (-1.0, -0.5, 0.0)}
    drive(c, 0.0, 1.98, lambda t: still, at=lambda t: c.on_status(t, "NAVIGATING", "goal", []))
    # robot_1 is lost at 2.0 s: the new assignment arrives, then the poses that take the sample
    # at 2.0 s, and only then the status of that decision (it comes on another topic)
    c.on_assignment(2.0, wedge({"robot_0": (0.0, 0.0), "robot_2": (-1.0, 0.5)}))
    drive(c, 2.0, 2.06, lambda t: still)
    at_2 = c.run.samples[-1]
    assert (at_2.t, at_2.state, at_2.formation) == (2.0, "NAVIGATING", "wedge")
    assert at_2.robots["robot_2"].slot_error == pytest.approx(0.0)     # its old slot: no 1 m error
    c.on_status(2.0, "DEGRADED", "lost robot_1", ["robot_1"])
    drive(c, 2.06, 2.2, lambda t: still, at=lambda t: c.on_status(t, "DEGRADED", "lost robot_1", ["robot_1"]))
    at_21 = c.run.samples[-1]
    assert (at_21.t, at_21.state) == (pytest.approx(2.1), "DEGRADED")
    assert at_21.robots["robot_2"].slot_error == pytest.approx(1.0)    # now the new slot


def test_the_lateral_error_uses_the_plan_of_the_leaders_pose_time():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}, "column"))
    c.on_status(0.0, "NAVIGATING", "goal", [])
    c.on_plan("robot_0", 0.0, [(0.0, 0.0), (9.0, 0.0)])
    drive(c, 0.0, 1.0, lambda t: {"robot_0": (0.5 * t, 0.0, 0.0), "robot_1": (0.5 * t - 1.0, 0.0, 0.0)})
    # the leader's ground truth lags (a busy collector): its plans of 1.5 s and 2 s, starting where
    # it is then, arrive while its newest pose is still the one of 0.98 s (x = 0.49 m)
    c.on_plan("robot_0", 1.5, [(0.75, 0.0), (9.0, 0.0)])
    c.on_plan("robot_0", 2.0, [(1.0, 0.0), (9.0, 0.0)])
    assert c.sample(1.1).leader_lateral == pytest.approx(0.0)   # the plan of 0 s: on it
    c.on_pose("robot_0", 2.0, 1.0, 0.3, 0.0)                     # then a pose of 2 s, 0.3 m aside
    assert c.sample(2.0).leader_lateral == pytest.approx(0.3)


def test_latency_tf_success_rate_and_cycle_time():
    """Without the simulator's report (a real robot) the latency is the pose's age."""
    c = MetricsCollector()
    for k in range(20):
        t = 1.0 + 0.05 * k
        age = 0.2 if k == 7 else 0.04          # one slow cycle
        c.on_follower_state("robot_1", t, t - age, True, 10 * (k + 1), k // 4, 0.001 * (k + 1), "slot")
    c.on_follower_state("robot_1", 2.0, 0.0, False, 200, 5, 0.0005, "idle")   # no pose: no latency
    c.on_follower_state("robot_2", 2.0, 1.97, True, 100, 0, 0.002, "slot")
    c.finish()
    s = summarize(c.run)
    r1 = s["robots"]["robot_1"]
    assert r1["latency_p50_s"] == pytest.approx(0.04)
    assert r1["latency_p95_s"] == pytest.approx(0.04 + 0.05 * 0.16)   # 19 x 0.04 and one 0.2
    assert r1["latency_max_s"] == pytest.approx(0.2)
    assert r1["tf_success_rate"] == pytest.approx(1.0 - 5.0 / 200.0)  # the newest counters
    cycles_ms = [1.0 * (k + 1) for k in range(20)] + [0.5]
    assert r1["cycle_time_p99_ms"] == pytest.approx(np.percentile(cycles_ms, 99))
    assert r1["cycle_time_p99_ms"] == pytest.approx(19.8)
    fleet = s["fleet"]
    assert fleet["tf_success_rate"] == pytest.approx(1.0 - 5.0 / 300.0)
    assert fleet["latency_max_s"] == pytest.approx(0.2)
    assert s["robots"]["robot_2"]["latency_p50_s"] == pytest.approx(0.03)
    assert fleet["latency_method"] == "pose_age" and fleet["commands_not_applied"] == 0


def loss_and_rejoin_run(config=None):
    """robot_2 is lost at 5.0 s (DEGRADED at 5.3 s, re-planned: robot_1 must move 0.5 m to its new
    slot, which takes it 2.5 s) and rejoins at 9.0 s. The leader stands at the origin."""
    c = MetricsCollector(config)
    c.on_assignment(0.0, wedge())
    c.on_status(0.0, "NAVIGATING", "goal", [])
    column = {"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}

    def at(t):
        if near(t, 5.0):
            c.on_status(t, "NAVIGATING", "", ["robot_2"])
        if near(t, 5.3):
            c.on_status(t, "DEGRADED", "lost robot_2", ["robot_2"])
            c.on_assignment(t, wedge(column, "column"))
        if near(t, 9.0):
            c.on_status(t, "NAVIGATING", "robot_2 rejoined", [])
            c.on_assignment(t, wedge(dict(column, robot_2=(-2.0, 0.0)), "column"))

    def poses(t):
        y1 = 0.5 if t < 5.3 else max(0.0, 0.5 * (1.0 - (t - 5.3) / 2.5))
        if t < 5.0:
            p2 = (-1.0, -0.5, 0.0)
        elif t < 9.0:
            p2 = (-3.0, -3.0, 0.0)   # wandering while lost: far from any slot, must not count
        else:
            p2 = (-2.0, 0.0, 0.0)
        return {"robot_0": (0.0, 0.0, 0.0), "robot_1": (-1.0, y1, 0.0), "robot_2": p2}

    drive(c, 0.0, 10.0, poses, at)
    return c


def test_loss_recovery_time_to_degraded_and_exclusion_while_lost():
    c = loss_and_rejoin_run()
    s = summarize(c.run)
    (rec,) = s["recoveries"]
    assert rec["robot"] == "robot_2"
    assert rec["t_s"] == pytest.approx(5.0)
    assert rec["time_to_degraded_s"] == pytest.approx(0.3)
    # robot_1's error 0.5 (1 - (t - 5.3) / 2.5) is under 0.15 m from t > 7.05 s: first sample 7.1 s.
    assert rec["recovery_time_s"] == pytest.approx(2.1)
    # robot_2 counts 5.0 s before the loss and 1.0 s after the rejoin, always in its slot.
    assert s["robots"]["robot_2"]["slot_samples"] == 60
    assert s["robots"]["robot_2"]["slot_max_m"] == pytest.approx(0.0)
    assert s["fleet"]["slot_max_m"] == pytest.approx(0.5)
    assert s["fleet"]["switches"] == 1
    assert s["fleet"]["losses"] == 1 and s["fleet"]["rejoins"] == 1
    assert s["fleet"]["time_in_state_s"]["DEGRADED"] == pytest.approx(3.7)
    assert s["fleet"]["time_in_state_s"]["NAVIGATING"] == pytest.approx(5.3 + 0.9)
    assert [e.kind for e in c.run.events] == ["assignment", "state", "loss", "state", "assignment",
                                              "switch", "state", "rejoin", "assignment"]


def test_recovery_needs_the_hold_and_an_already_degraded_fleet_takes_no_time():
    # Needing 3 s under the bound, robot_1 (under it from 7.1 s) is never "recovered" before the
    # run ends at 9.9 s (the window would need samples up to 10.1 s).
    s = summarize(loss_and_rejoin_run(MetricsConfig(recovered_hold=3.0)).run)
    assert s["recoveries"][0]["recovery_time_s"] is None
    c = MetricsCollector()
    c.on_status(1.0, "DEGRADED", "lost robot_3", ["robot_3"])
    c.on_status(2.0, "DEGRADED", "lost robot_2 too", ["robot_3", "robot_2"])
    rec = summarize(c.run)["recoveries"]
    assert [(r["robot"], r["time_to_degraded_s"], r["recovery_time_s"]) for r in rec] == [
        ("robot_3", 0.0, None), ("robot_2", 0.0, None)]


def test_steady_rms_in_navigating_while_moving_and_in_arrived():
    c = MetricsCollector()
    c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}, "column"))

    def at(t):
        for when, state in ((0.0, "FORMING"), (2.0, "NAVIGATING"), (6.0, "ARRIVED")):
            if near(t, when):
                c.on_status(t, state, "", [])

    def poses(t):
        lx = 0.5 * min(max(t - 2.0, 0.0), 4.0)               # drives from 2 s to 6 s
        error = 0.3 if t < 2.0 else (0.2 if t < 6.0 else 0.05)
        return {"robot_0": (lx, 0.0, 0.0), "robot_1": (lx - 1.0, error, 0.0)}

    drive(c, 0.0, 8.0, poses, at)
    s = summarize(c.run)["fleet"]
    assert s["steady_navigating_slot_rms_m"] == pytest.approx(0.2)
    assert s["steady_arrived_slot_rms_m"] == pytest.approx(0.05)
    assert s["slot_rms_m"] == pytest.approx(math.sqrt((20 * 0.09 + 40 * 0.04 + 20 * 0.05 ** 2) / 80))
    assert s["time_in_state_s"] == {"FORMING": pytest.approx(2.0), "NAVIGATING": pytest.approx(4.0),
                                    "ARRIVED": pytest.approx(1.9)}


def test_a_follower_whose_controller_fell_silent_leaves_the_steady_rms():
    """robot_2's controller stops at 4 s (killed) and the robot stands while the leader drives on:
    its growing error is the time the coordinator takes to declare it lost, not the formation's
    steady error. It counts until its controller has been silent for controller_silence."""
    c = MetricsCollector(MetricsConfig(controller_silence=0.5))
    c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0), "robot_2": (-2.0, 0.0)},
                               "column"))

    def at(t):
        if near(t, 0.0):
            c.on_status(t, "NAVIGATING", "", [])
        for r in ("robot_1", "robot_2"):
            if r == "robot_1" or t < 4.0 - 1e-9:
                c.on_follower_state(r, t, t, True, 1, 0, 0.001, "track")

    def poses(t):
        lx = 0.5 * t
        return {"robot_0": (lx, 0.0, 0.0), "robot_1": (lx - 1.0, 0.1, 0.0),
                "robot_2": (min(lx, 2.0) - 2.0, 0.1, 0.0)}   # stands from 4 s on

    drive(c, 0.0, 8.0, poses, at)
    c.finish()
    s = summarize(c.run)["fleet"]
    # robot_2 counts until its controller has been silent 0.5 s: off by at most ~0.2 m then,
    # while it ends 2 m from its slot.
    assert s["slot_max_m"] > 1.9
    assert s["steady_navigating_slot_rms_m"] < 0.13
    c.run.config = MetricsConfig(controller_silence=100.0)   # never silent: all of its error counts
    assert summarize(c.run)["fleet"]["steady_navigating_slot_rms_m"] > 0.5


def test_clearance_contacts_and_stale_poses():
    c = MetricsCollector(MetricsConfig(robot_radius=0.15))
    c.on_pose("robot_3", 0.0, 0.0, 0.6, 0.0)   # heard once: stale after 1 s, then never counted

    def at(t):
        if near(t, 3.0):
            c.on_contact(t, "robot_1", "map", 1.0, 2.0)
        if near(t, 4.5):
            c.on_contact(t, "robot_1", "box_1", 0.25, 0.5)

    # robot_1 passes robot_2 0.5 m away at 4.0 s (clearance 0.5 - 2 x 0.15 = 0.2 m); it passes
    # robot_3's old position 0.1 m away at the same time.
    drive(c, 0.0, 8.0, lambda t: {"robot_1": (-2.0 + 0.5 * t, 0.5, 0.0), "robot_2": (0.0, 0.0, 0.0)}, at)
    s = summarize(c.run)
    assert s["fleet"]["min_clearance_m"] == pytest.approx(0.2)
    assert s["fleet"]["min_clearance_t_s"] == pytest.approx(4.0)
    assert s["fleet"]["min_clearance_pair"] == "robot_1 robot_2"
    assert c.run.samples[5].min_clearance == pytest.approx(0.6 - 0.3)   # robot_3 still fresh at 0.5 s
    assert s["fleet"]["contacts"] == 2
    assert s["contact_list"] == [
        {"t_s": 3.0, "body_a": "robot_1", "body_b": "map", "x_m": 1.0, "y_m": 2.0},
        {"t_s": 4.5, "body_a": "robot_1", "body_b": "box_1", "x_m": 0.25, "y_m": 0.5}]
    assert math.isnan(c.run.samples[-1].robots["robot_3"].x)


def test_a_sample_waits_for_a_late_stream_and_uses_each_robots_pose_at_its_time():
    # robot_2's poses arrive 0.5 s (sim) late, as a starved subscriber thread delivers them
    c = MetricsCollector()
    c.on_assignment(0.0, wedge())
    c.on_status(0.0, "NAVIGATING", "goal", [])
    late = []
    for i in range(0, 5 * GT_HZ):
        t = i / float(GT_HZ)
        c.on_pose("robot_0", t, 0.5 * t, 0.0, 0.0)
        c.on_pose("robot_1", t, 0.5 * t - 1.0, 0.5, 0.0)
        late.append((t, 0.5 * t - 1.0, -0.5))
        if t >= 0.5:
            lt, lx, ly = late.pop(0)
            c.on_pose("robot_2", lt, lx, ly, 0.0)
    # every sample has every robot, on its slot (robot_2's pose of the sample's time, not its newest)
    assert len(c.run.samples) >= 40
    for sample in c.run.samples:
        assert set(sample.robots) == {"robot_0", "robot_1", "robot_2"}
        assert sample.slot_max == pytest.approx(0.0, abs=1e-9), sample.t
    # a stream that stops (a removed robot) holds the samples back hold_back seconds, no longer
    n = len(c.run.samples)
    for i in range(5 * GT_HZ, 12 * GT_HZ):
        t = i / float(GT_HZ)
        c.on_pose("robot_0", t, 0.5 * t, 0.0, 0.0)
        c.on_pose("robot_1", t, 0.5 * t - 1.0, 0.5, 0.0)
    assert c.run.samples[-1].t >= 11.5 and len(c.run.samples) > n
    assert math.isnan(c.run.samples[-1].robots["robot_2"].x)


def test_energy_integral_of_power_and_distance_without_teleports():
    c = MetricsCollector(MetricsConfig(stale_after=1.0))

    def at(t):
        if t <= 10.0 and abs(t * 20 - round(t * 20)) < 1e-9:     # 20 Hz: 2 W, then 4 W from 5 s
            c.on_power("robot_1", t, 2.0 if t < 5.0 else 4.0)
        if near(t, 20.0):   # after a 10 s silence the last value holds for stale_after only
            c.on_power("robot_1", t, 0.0)

    def poses(t):
        x = 0.5 * t if t < 12.0 else 0.5 * t + 10.0            # a 10 m teleport at 12 s
        return {"robot_1": (x, 0.0, 0.0)}

    drive(c, 0.0, 21.0, poses, at)
    s = summarize(c.run)
    assert c.energy["robot_1"] == pytest.approx(2.0 * 5.0 + 4.0 * 5.0 + 4.0 * 1.0)
    assert s["robots"]["robot_1"]["energy_j"] == pytest.approx(34.0)   # the last sample is at 20.9 s
    # The 0.02 s step with the teleport is not travel: 0.5 m/s x 20.9 s less 0.01 m.
    assert s["robots"]["robot_1"]["distance_m"] == pytest.approx(0.5 * 20.9 - 0.01)
    assert s["fleet"]["energy_j"] == pytest.approx(34.0)


def test_files_read_back_into_the_same_run_and_summary(tmp_path):
    c = loss_and_rejoin_run()
    c.on_contact(6.0, "robot_1", "robot_0", -0.5, 0.1)
    c.on_follower_state("robot_1", 6.0, 5.96, True, 40, 1, 0.0012, "slot")
    writer = RunWriter(str(tmp_path / "run"))
    writer.write(c.run, summarize(c.run))
    # More samples and a robot that appears later (new columns): the files grow and stay whole.
    # robot_1 and robot_2 fall silent at 10 s: the samples wait hold_back (5 s) for them.
    c.on_assignment(10.0, wedge(dict(WEDGE, robot_9=(-2.0, 0.0)), "wedge"))
    c.on_status(10.0, "NAVIGATING", "robot_9 joined", [])   # the coordinator's status of that decision
    drive(c, 10.0, 15.0, lambda t: {"robot_0": (0.0, 0.0, 0.0), "robot_9": (-2.0, 0.1, 0.0)})
    assert len(c.run.samples) == 100
    drive(c, 15.0, 16.0, lambda t: {"robot_0": (0.0, 0.0, 0.0), "robot_9": (-2.0, 0.1, 0.0)})
    c.on_follower_state("robot_9", 16.0, 15.9, True, 3, 0, 0.001, "slot")
    live = summarize(c.run)
    writer.write(c.run, live)

    back = load_run(str(tmp_path / "run"))
    assert back.robots == c.run.robots == ["robot_0", "robot_1", "robot_2", "robot_9"]
    assert len(back.samples) == len(c.run.samples) == 160
    assert "robot_9" not in back.samples[0].robots and "robot_9" in back.samples[-1].robots
    # Compared as text: exact floats, and NaN (no data) reads back as NaN.
    assert [str(s) for s in back.samples] == [str(s) for s in c.run.samples]
    assert [str(e) for e in back.events] == [str(e) for e in c.run.events]
    assert back.controller == c.run.controller
    assert summarize(back) == live
    with open(str(tmp_path / "run" / "metrics.json")) as f:
        assert json.load(f) == live
    assert live["fleet"]["contacts"] == 1 and live["robots"]["robot_9"]["slot_samples"] == 60
    assert live["robots"]["robot_9"]["slot_rms_m"] == pytest.approx(0.1)


def test_offline_main_prints_the_summary(tmp_path, capsys):
    c = loss_and_rejoin_run()
    RunWriter(str(tmp_path)).write(c.run, summarize(c.run))
    assert main([str(tmp_path)]) == 0
    printed = json.loads(capsys.readouterr().out)
    assert printed["recoveries"][0]["recovery_time_s"] == pytest.approx(2.1)


def test_bad_config_and_bad_files_name_the_problem(tmp_path):
    with pytest.raises(ValueError, match="rate: expected a finite number > 0, got 0"):
        MetricsConfig(rate=0)
    with pytest.raises(ValueError, match="robot_radius: .* got True"):
        MetricsConfig(robot_radius=True)
    with pytest.raises(RunFileError, match="metrics.csv: missing"):
        load_run(str(tmp_path))
    c = loss_and_rejoin_run()
    RunWriter(str(tmp_path)).write(c.run, summarize(c.run))
    path = tmp_path / "metrics.csv"
    lines = path.read_text().splitlines()
    path.write_text("\n".join(lines[:3] + [lines[3].replace("0.", "zero.", 1)] + lines[4:]) + "\n")
    with pytest.raises(RunFileError, match=r"metrics.csv: line 4: t_s: expected a number, got 'zero.2'"):
        load_run(str(tmp_path))
    (tmp_path / "events.csv").write_text("t,kind\n")
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(RunFileError, match="events.csv: line 1: expected the columns t_s,kind,name"):
        load_run(str(tmp_path))
    (tmp_path / "metrics.json").write_text('{"config": {"rate": 10.0, "colour": 1}}')
    with pytest.raises(RunFileError, match="metrics.json: config: unknown key.s. colour"):
        load_run(str(tmp_path))
    with pytest.raises(OSError, match="cannot create it"):
        RunWriter(str(tmp_path / "metrics.csv" / "sub"))


def test_a_row_the_collector_is_still_writing_is_not_read_but_a_short_complete_row_is_an_error(tmp_path):
    # scenario_check read metrics.csv while the collector appended: "line 9116: 13 cells, expected 38".
    c = loss_and_rejoin_run()
    RunWriter(str(tmp_path)).write(c.run, summarize(c.run))
    path = tmp_path / "metrics.csv"
    text = path.read_text()
    rows = len(load_run(str(tmp_path)).samples)
    path.write_text(text + "12.3,0.1,")                     # the next row, half written
    assert len(load_run(str(tmp_path)).samples) == rows
    path.write_text(text + "12.3,0.1,\n")                   # the same cells, but a finished line
    with pytest.raises(RunFileError, match=r"metrics.csv: line %d: 3 cells, expected" % (rows + 2)):
        load_run(str(tmp_path))


def test_a_slot_in_a_wall_leaves_the_steady_rms_until_it_has_been_free_for_free_hold(tmp_path):
    """A column passes a wall: the follower's slot (1 m behind the leader) crosses a block that
    fills x in [0.5, 1.5), y in [-1.5, -0.5); with 0.25 m clearance the slot is blocked for x in
    [0.25, 1.75), i.e. from about 2.5 s to 5.5 s. The follower drives around it 0.8 m off its
    slot, is still 0.4 m off until 7 s, then 0.1 m. The steady RMS counts it again free_hold (3 s) after
    its slot is free, so only the 0.1 m samples."""
    from mbot_follower.free_space import FreeSpace

    grid = np.zeros((40, 100), dtype=np.int8)       # 0.1 m cells, origin (-2, -2): x in [-2, 8), y in [-2, 2)
    grid[5:15, 25:35] = 100
    free = FreeSpace(grid, 0.1, (-2.0, -2.0), 0.25)
    c = MetricsCollector(MetricsConfig(free_hold=3.0), free)
    c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}, "column"))
    c.on_status(0.0, "NAVIGATING", "", [])

    def poses(t):
        lx = 0.5 * t
        error = 0.8 if not free.is_free(lx - 1.0, -1.0) else (0.4 if 5.0 <= t < 7.0 else 0.1)
        return {"robot_0": (lx, -1.0, 0.0), "robot_1": (lx - 1.0, -1.0 - error, 0.0)}

    drive(c, 0.0, 14.0, poses)
    s = summarize(c.run)["fleet"]
    track = [(x.t, x.robots["robot_1"]) for x in c.run.samples]
    blocked = [t for t, rs in track if rs.slot_free == 0.0]
    assert blocked[0] == pytest.approx(2.5, abs=0.25) and blocked[-1] == pytest.approx(5.5, abs=0.25)  # cell edges
    assert all(rs.slot_free == 1.0 for t, rs in track if t < blocked[0] or t > blocked[-1])
    assert s["steady_navigating_slot_rms_m"] == pytest.approx(0.1)
    assert s["slot_rms_m"] > 0.35
    assert s["slot_blocked_share"] == pytest.approx(len(blocked) / (len(track) - 1.0))

    writer = RunWriter(str(tmp_path / "run"))
    writer.write(c.run, summarize(c.run))
    back = load_run(str(tmp_path / "run"))
    assert [x.robots["robot_1"].slot_free for x in back.samples] == [rs.slot_free for _, rs in track]
    assert summarize(back) == summarize(c.run)


def test_a_run_recorded_before_slot_free_reads_as_unknown(tmp_path):
    c = loss_and_rejoin_run()
    RunWriter(str(tmp_path)).write(c.run, summarize(c.run))
    path = tmp_path / "metrics.csv"
    rows = [line.split(",") for line in path.read_text().splitlines()]
    keep = [i for i, name in enumerate(rows[0]) if not name.endswith("/slot_free")]
    path.write_text("\n".join(",".join(row[i] for i in keep) for row in rows) + "\n")
    back = load_run(str(tmp_path))
    assert len(back.samples) == len(c.run.samples)
    assert all(math.isnan(rs.slot_free) for s in back.samples for rs in s.robots.values())
    assert summarize(back)["fleet"]["steady_navigating_slot_rms_m"] == \
        summarize(c.run)["fleet"]["steady_navigating_slot_rms_m"]


def l_path(s):
    """(x, y, theta) at arc length s [m] of an L: 1.5 m along +x from (0, 0), then along +y
    (s < 0: straight on behind the start)."""
    return (s, 0.0, 0.0) if s <= 1.5 else (1.5, s - 1.5, math.pi / 2)


@pytest.mark.parametrize("along_path", [True, False])
def test_a_column_on_its_path_slots_around_a_corner_has_no_slot_error(along_path):
    column = {"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0), "robot_2": (-2.0, 0.0)}
    c = MetricsCollector()
    c.on_assignment(0.0, Assignment("robot_0", "column", 1.0, column, {r: "robot_0" for r in column},
                                    along_path))
    c.on_status(0.0, "NAVIGATING", "goal", [])
    # the leader drives the L at 1 m/s; each follower exactly where the leader was 1 m / 2 m before
    drive(c, 0.0, 3.0, lambda t: {r: l_path(t + x) for r, (x, _) in column.items()})
    s = summarize(c.run)
    last = c.run.samples[-1]            # t = 2.9: the leader at (1.5, 1.4), robot_2 at (0.9, 0)
    assert last.t == pytest.approx(2.9) and last.robots["robot_2"].x == pytest.approx(0.9)
    if along_path:
        assert s["fleet"]["slot_max_m"] < 1e-9
        assert s["fleet"]["steady_navigating_slot_rms_m"] < 1e-9
        assert last.heading_max < 1e-9  # each robot faces the way of the path where it is
    else:
        # rigid slots swing around the corner: robot_2's is at (1.5, -0.6), 0.85 m away
        assert last.robots["robot_2"].slot_error == pytest.approx(math.hypot(0.6, 0.6))
        assert last.heading_max == pytest.approx(math.pi / 2)


def test_overruns_and_late_starts_are_summed_from_each_controllers_newest_counters_and_kept_in_the_files(tmp_path):
    c = MetricsCollector()
    c.on_follower_state("robot_1", 1.0, 0.95, True, 10, 0, 0.08, "slot", 1, 0)
    c.on_follower_state("robot_1", 1.05, 1.0, True, 11, 0, 0.03, "slot", 1, 2)
    c.on_follower_state("robot_2", 1.0, 0.95, True, 10, 0, 0.09, "slot", 4, 1)
    c.finish()
    s = summarize(c.run)
    assert (s["fleet"]["cycle_overruns"], s["fleet"]["cycle_late_starts"]) == (5, 3)
    assert (s["robots"]["robot_1"]["cycle_overruns"], s["robots"]["robot_1"]["cycle_late_starts"]) == (1, 2)
    RunWriter(str(tmp_path)).write(c.run, s)
    assert [(r.overruns, r.late_starts) for r in load_run(str(tmp_path)).controller] == [(1, 0), (1, 2), (4, 1)]
    # a record written before the counters existed still loads (as zeros)
    path = tmp_path / "controller.csv"
    lines = path.read_text().splitlines()
    path.write_text("\n".join(",".join(line.split(",")[:7]) for line in lines) + "\n")
    assert [(r.overruns, r.late_starts) for r in load_run(str(tmp_path)).controller] == [(0, 0)] * 3
    path.write_text("t_s,robot,latency_s\n")
    with pytest.raises(RunFileError, match="expected the columns t_s,robot,latency_s,cycle_time_ms"):
        load_run(str(tmp_path))


def test_a_slot_beside_a_spawned_box_is_blocked_as_beside_a_wall(tmp_path):
    """A column drives east along y = 0 with no map walls near; at 1 s a 0.4 x 0.4 m box is
    spawned at (3, 0), its long side across the way. The follower's slot (1 m behind the leader)
    comes within slot_clearance (0.25 m) of the box for x in [2.55, 3.45], i.e. t in [7.1, 8.9] at
    0.5 m/s; the follower drives around it 0.8 m off its slot (7.2-9 s), else 0.1 m. The box is
    an event, the slot's samples beside it are blocked, and the steady RMS counts the follower
    again free_hold (3 s) after its slot is clear: only the 0.1 m samples. Removed at 11 s, the
    box blocks nothing more. Without the box in the rule the steady RMS would count the detour."""
    from mbot_follower.free_space import FreeSpace
    from mbot_follower.metrics.obstacles import Obstacle, blocks, distance

    box = Obstacle("box_1", "box", 3.0, 0.0, 0.0, 0.4, 0.4, 0.0)
    assert distance(box, 3.0, 0.0) == 0.0 and distance(box, 3.45, 0.0) == pytest.approx(0.25)
    assert distance(Obstacle("b", "box", 0.0, 0.0, math.pi / 2, 1.0, 0.2, 0.0), 0.0, 0.6) == pytest.approx(0.1)
    assert distance(Obstacle("c", "cylinder", 0.0, 0.0, 0.0, 0.0, 0.0, 0.3), 0.0, 1.0) == pytest.approx(0.7)
    assert blocks([box], 3.0, 0.44, 0.25) and not blocks([box], 3.0, 0.46, 0.25)

    def run(with_box):
        free = FreeSpace(np.zeros((40, 200), dtype=np.int8), 0.1, (-2.0, -2.0), 0.25)   # no walls
        c = MetricsCollector(MetricsConfig(free_hold=3.0), free)
        c.on_assignment(0.0, wedge({"robot_0": (0.0, 0.0), "robot_1": (-1.0, 0.0)}, "column"))
        c.on_status(0.0, "NAVIGATING", "", [])

        def events(t):
            if with_box and near(t, 1.0):
                c.on_obstacles(t, [box])
            if with_box and near(t, 11.0):
                c.on_obstacles(t, [])

        def poses(t):
            lx = 0.5 * t
            error = 0.8 if 7.2 <= t < 9.0 else 0.1   # around the box (its edge 0.2 m + the robot)
            return {"robot_0": (lx, 0.0, 0.0), "robot_1": (lx - 1.0, error, 0.0)}

        drive(c, 0.0, 16.0, poses, at=events)
        return c

    c = run(with_box=True)
    s = summarize(c.run)["fleet"]
    assert [(e.t, e.kind, e.name, e.x, e.y) for e in c.run.events if e.kind.startswith("obstacle")] == \
        [(1.0, "obstacle", "box_1", 3.0, 0.0), (11.0, "obstacle_removed", "box_1", 3.0, 0.0)]
    assert [e.detail for e in c.run.events if e.kind == "obstacle"] == ["box 0.4 x 0.4 m, yaw 0 rad"]
    blocked = [x.t for x in c.run.samples if x.robots["robot_1"].slot_free == 0.0]
    assert blocked[0] == pytest.approx(7.1, abs=0.11) and blocked[-1] == pytest.approx(8.9, abs=0.11)
    assert s["steady_navigating_slot_rms_m"] == pytest.approx(0.1)
    assert s["slot_blocked_share"] > 0.1
    without = summarize(run(with_box=False).run)["fleet"]
    assert without["steady_navigating_slot_rms_m"] > 0.25 and without["slot_blocked_share"] == 0.0

    # the events survive the files, and the summary read back is the same
    RunWriter(str(tmp_path / "run")).write(c.run, summarize(c.run))
    back = load_run(str(tmp_path / "run"))
    assert [e for e in back.events if e.kind.startswith("obstacle")] == \
        [e for e in c.run.events if e.kind.startswith("obstacle")]
    assert summarize(back) == summarize(c.run)


def test_static_obstacles_are_read_from_the_simulators_markers():
    """/stage/markers: a CUBE and a CYLINDER in namespace "obstacles" are a box and a cylinder;
    moving obstacles, robots, names and the DELETEALL marker are not obstacles."""
    from types import SimpleNamespace as NS

    from mbot_follower.metrics.obstacles import Obstacle, from_markers

    def marker(ns, kind, text, x, y, yaw, sx, sy, action=0):
        q = NS(x=0.0, y=0.0, z=math.sin(yaw / 2.0), w=math.cos(yaw / 2.0))
        return NS(ns=ns, action=action, type=kind, text=text, pose=NS(position=NS(x=x, y=y, z=0.25), orientation=q),
                  scale=NS(x=sx, y=sy, z=0.5))

    markers = [marker("", 0, "", 0, 0, 0, 0, 0, action=3), marker("obstacles", 1, "crate_1", 7.5, -7.5, 0.3, 0.8, 0.6),
               marker("obstacles", 3, "post", 1.0, 2.0, 0.0, 0.6, 0.6),
               marker("moving_obstacles", 3, "person_1", -8.0, -3.0, 0.0, 0.5, 0.5),
               marker("robots", 3, "", 0.0, 0.0, 0.0, 0.3, 0.3), marker("robot_names", 9, "leader", 0, 0.35, 0, 0, 0)]
    box, post = from_markers(markers)
    assert box == Obstacle("crate_1", "box", 7.5, -7.5, pytest.approx(0.3), 0.8, 0.6, 0.0)
    assert post == Obstacle("post", "cylinder", 1.0, 2.0, 0.0, 0.0, 0.0, 0.3)
