"""The formation benchmark reads its times from the metrics collector's record (stamped with the
data's sim time), not from when its probe noticed a condition."""
import math

import pytest

from mbot_follower.formation_bench import moving_rms, start_poses, timings, worst
from mbot_follower.metrics import ControllerSample, Event, RobotSample, Run, Sample

NAN = float("nan")


def event(t, kind, name, detail=""):
    return Event(t, kind, name, detail, NAN, NAN)


def sample(t, formation, slot_max, slot_rms=None):
    """robot_1 slot_max off its slot (the leader robot_0 has no pose: it does not move)."""
    rms = slot_max if slot_rms is None else slot_rms
    robots = {"robot_1": RobotSample(NAN, NAN, NAN, slot_max, NAN, 0.0, 0.0)}
    return Sample(t, "NAVIGATING", "robot_0", formation, (), rms, slot_max, NAN, NAN, NAN, NAN, NAN, NAN, "", robots)


def recorded_run():
    """FORMING 10 -> 14.5 s; column at 50 s, within 0.3 m from 54.3 s on; robot_2 silent from
    80.0 s, lost at 81.1 s, slots re-planned at 81.1 s, slot RMS under 0.15 m from 84.0 s."""
    run = Run()
    run.events = [
        event(10.0, "state", "FORMING"),
        event(14.5, "state", "NAVIGATING"),
        event(50.0, "assignment", "column", "leader robot_0 spacing 1.5 m along_path slots robot_0(0,0) "
                                            "robot_1(-1.5,0) robot_2(-3,0)"),
        event(50.0, "switch", "column", "triangle"),
        event(81.1, "state", "DEGRADED"),
        event(81.1, "loss", "robot_2"),
        event(81.1, "assignment", "wedge", "leader robot_0 spacing 1.5 m slots robot_0(0,0) robot_1(-1.06,1.06)"),
    ]
    errors = {49.9: 0.01, 50.0: 1.8, 52.0: 0.9, 54.2: 0.31, 54.3: 0.29, 54.4: 0.2, 54.5: 0.2, 54.6: 0.2,
              54.7: 0.2, 54.8: 0.2, 54.9: 0.2}
    run.samples = [sample(t, "triangle" if t < 50.0 else "column", e) for t, e in sorted(errors.items())]
    for k in range(0, 61):  # 80.0 .. 86.0 s: RMS 0.4 until 84.0, then 0.1
        t = round(80.0 + 0.1 * k, 1)
        run.samples.append(sample(t, "wedge", 0.5, 0.4 if t < 84.0 else 0.1))
    for k in range(0, 101):  # the controllers' cycles at 20 Hz; robot_2's stop at 80.0 s
        t = round(76.0 + 0.05 * k, 2)
        run.controller += [ControllerSample(t, r, 0.02, 5.0, k, 0, "slot") for r in ("robot_1", "robot_2")
                           if r == "robot_1" or t <= 80.0]
    return run


def test_the_times_come_from_the_stamps_of_the_record():
    got = timings(recorded_run())
    assert got == {"converge_s": 4.5, "switch_s": 4.3, "degraded_s": 1.1, "recover_s": 4.0,
                   "rms_straight_m": None, "rms_route_m": None,   # no robot in these samples
                   "slot_p95_switch_m": 1.665}   # the samples 50.0-54.3 s: 1.8, 0.9, 0.31, 0.29 m


def test_the_switch_ends_only_in_the_new_formation_and_under_the_tolerance():
    run = recorded_run()
    # a sample under 0.3 m just before the switch does not count, nor one of another formation
    run.samples.insert(0, sample(49.0, "column", 0.1))
    assert timings(run)["switch_s"] == 4.3


def test_the_loss_is_timed_from_the_victims_last_cycle_before_it():
    run = recorded_run()
    run.controller = [c for c in run.controller if not (c.robot == "robot_2" and c.t > 79.5)]
    assert timings(run)["degraded_s"] == 1.6 and timings(run)["recover_s"] == 4.5
    run.controller = [c for c in run.controller if c.robot != "robot_2"]   # never heard: no time
    assert timings(run)["degraded_s"] is None and timings(run)["recover_s"] is None


def test_a_robot_lost_for_a_moment_and_back_is_not_the_loss_measured():
    # a follower's controller starved as the fleet starts: lost at 5.0 s, back at 5.4 s
    run = recorded_run()
    startup = [event(5.0, "loss", "robot_2"),
               event(5.0, "assignment", "wedge", "leader robot_0 slots robot_0(0,0) robot_1(-1,1)"),
               event(5.4, "rejoin", "robot_2")]
    run.events[:0] = startup
    run.controller.insert(0, ControllerSample(3.6, "robot_2", 0.02, 5.0, 0, 0, "slot"))
    assert timings(run) == timings(recorded_run())


def test_a_step_missing_from_the_record_reads_none():
    run = recorded_run()
    run.events = [e for e in run.events if e.kind not in ("loss", "switch")]
    got = timings(run)
    assert got["converge_s"] == 4.5
    assert got["switch_s"] is None and got["degraded_s"] is None and got["recover_s"] is None


def test_the_re_plan_must_drop_the_victim_not_a_robot_whose_name_starts_like_it():
    run = recorded_run()
    run.events[-1] = event(81.1, "assignment", "wedge", "leader robot_0 spacing 1.5 m slots robot_0(0,0) robot_2(-1,1)")
    run.events.append(event(81.6, "assignment", "wedge", "leader robot_0 spacing 1.5 m slots robot_0(0,0) "
                                                         "robot_20(-1,1)"))
    assert timings(run)["degraded_s"] == 1.6


def test_a_row_is_the_worst_value_over_the_runs():
    runs = [{"succeeded": True, "contacts": 0, "switch_s": 4.3, "converge_s": None, "overruns": 3, "late_starts": 1},
            {"succeeded": False, "contacts": 2, "switch_s": 6.1, "converge_s": 7.0, "overruns": 5, "late_starts": None}]
    row = worst(runs)
    assert (row["overruns"], row["late_starts"]) == (8, 1)   # beside cycle_p99_ms: counted over the runs
    assert row["runs"] == 2 and row["succeeded"] == 1 and row["contacts"] == 2
    assert row["switch_s"] == 6.1 and row["converge_s"] == 7.0 and row["recover_s"] is None


def test_the_start_poses_are_seeded_and_apart():
    for n in (3, 5, 10):
        poses = start_poses(n, seed=4)
        assert [name for name, _ in poses] == ["robot_%d" % i for i in range(n)]
        for i, (_, a) in enumerate(poses):
            for _, b in poses[i + 1:]:
                assert math.hypot(a.x - b.x, a.y - b.y) >= 0.6
        assert start_poses(n, seed=4) == poses   # seeded


def moving_sample(t, state, leader_x, errors):
    robots = {"robot_0": RobotSample(leader_x, 0.0, 0.0, NAN, NAN, 0.0, 0.0)}
    robots.update({r: RobotSample(leader_x - 1.5, 0.0, 0.0, e, e, 0.0, 0.0) for r, e in errors.items()})
    return Sample(t, state, "robot_0", "triangle", (), NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, "", robots)


def test_the_slot_rms_comes_from_the_record_while_the_leader_moves():
    """Straight run: NAVIGATING at 14.5 s, measured from 17.5 s until the switch at 50 s; only
    samples in which the fleet navigates and the leader moves >= 0.1 m/s count."""
    run = recorded_run()
    x = 0.0
    run.samples = []
    for k in range(0, 400):   # 10 Hz from 10 s to 50 s
        t = round(10.0 + 0.1 * k, 1)
        state = "FORMING" if t < 14.5 else "NAVIGATING"
        stopped = 30.0 <= t < 31.0               # the leader stands: errors ignored
        x += 0.0 if (stopped or state == "FORMING") else 0.05
        if t < 17.5 or stopped:
            errors = {"robot_1": 1.0, "robot_2": 1.0}
        else:
            errors = {"robot_1": 0.03, "robot_2": 0.04}
        run.samples.append(moving_sample(t, state, x, errors))
    run.samples.append(moving_sample(50.0, "NAVIGATING", x + 0.05, {"robot_1": 2.0, "robot_2": 2.0}))  # the switch
    got = timings(run, route=(20.0, 25.0))
    assert math.isclose(got["rms_straight_m"], 0.0354, abs_tol=1e-4)   # sqrt((0.03^2 + 0.04^2) / 2)
    assert math.isclose(got["rms_route_m"], 0.0354, abs_tol=1e-4)
    # a false loss's re-planned slots in the window count: the record shows what the fleet did
    run.samples[300] = moving_sample(40.0, "DEGRADED", run.samples[300].robots["robot_0"].x, {"robot_1": 1.8})
    assert timings(run)["rms_straight_m"] > 0.05
    assert moving_rms(run, 30.0, 31.0) is None   # the leader stood still


def test_the_office_row_runs_the_office_world_with_the_runs_seed(tmp_path):
    """The office route's world: the office's three robots where the world file has them, its
    crate and person, the map path absolute, the run's seed, as fast as possible."""
    from mbot_common.paths import find_maps_directory
    from mbot_common.world import load_world
    from mbot_follower.formation_bench import office_world_yaml

    path = tmp_path / "world.yaml"
    path.write_text(office_world_yaml(7, find_maps_directory()))
    world, office = load_world(str(path)), load_world(find_maps_directory() + "/office.world.yaml")
    assert world.seed == 7 and world.real_time_factor == 0.0
    assert world.robots == office.robots and world.obstacles == office.obstacles
    assert world.map_data.width == office.map_data.width


def test_the_office_row_is_timed_from_the_record():
    """FORMING 10 -> 14.5 s (converge 4.5 s); the route's RMS over its window only."""
    from mbot_follower.formation_bench import office_timings

    run = recorded_run()
    x = 0.0
    run.samples = []
    for k in range(0, 400):   # 10 Hz from 10 s to 50 s
        t = round(10.0 + 0.1 * k, 1)
        x += 0.05 if t >= 14.5 else 0.0
        errors = {"robot_1": 0.1, "robot_2": 0.1} if 20.0 <= t < 40.0 else {"robot_1": 1.0, "robot_2": 1.0}
        run.samples.append(moving_sample(t, "FORMING" if t < 14.5 else "NAVIGATING", x, errors))
    got = office_timings(run, (20.0, 40.0))
    assert got["converge_s"] == 4.5
    assert math.isclose(got["rms_route_m"], 0.1)
    assert math.isclose(got["slot_p95_switch_m"], 0.1)   # the office row's p95: over the route
    assert got["switch_s"] is None   # no switch in this record
    assert office_timings(Run(), (20.0, 40.0)) == {"converge_s": None, "switch_s": None, "rms_route_m": None,
                                                   "slot_p95_switch_m": None}


def test_the_law_rows_mpc_figures_and_clearance():
    """The worst robot's solve times, solves and fallbacks summed; the row's clearance is the
    lowest of its runs, its slot p95 the highest; an unknown law is refused by name."""
    from mbot_follower.formation_bench import main, mpc_figures, worst

    stats = {"robot_1": {"solves": 100, "fallbacks": 2, "solve_ms_p50": 3.0, "solve_ms_p99": 12.0},
             "robot_2": {"solves": 90, "fallbacks": 0, "solve_ms_p50": 4.0, "solve_ms_p99": 9.0}}
    got = mpc_figures(stats)
    assert got == {"mpc_solves": 190, "mpc_fallbacks": 2, "mpc_solve_p50_ms": 4.0, "mpc_solve_p99_ms": 12.0}
    assert mpc_figures({}) == {}
    runs = [dict(got, succeeded=True, contacts=0, min_clearance_m=0.4, slot_p95_switch_m=0.2),
            dict(got, succeeded=True, contacts=0, min_clearance_m=0.2, slot_p95_switch_m=0.1)]
    row = worst(runs)
    assert row["min_clearance_m"] == 0.2 and row["slot_p95_switch_m"] == 0.2
    assert row["mpc_solves"] == 380 and row["mpc_fallbacks"] == 4 and row["mpc_solve_p99_ms"] == 12.0
    assert "mpc_solves" not in worst([{"succeeded": True, "contacts": 0}])
    with pytest.raises(SystemExit, match=r"--laws: pid: expected control laws of consensus, mpc, slot_tracking"):
        main(["--laws", "slot_tracking,pid"])
