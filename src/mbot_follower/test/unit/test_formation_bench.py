"""The formation benchmark reads its times from the metrics collector's record (stamped with the
data's sim time), not from when its probe noticed a condition."""
import math

from mbot_follower.formation_bench import start_poses, timings, worst
from mbot_follower.metrics import ControllerSample, Event, Run, Sample

NAN = float("nan")


def event(t, kind, name, detail=""):
    return Event(t, kind, name, detail, NAN, NAN)


def sample(t, formation, slot_max, slot_rms=None):
    rms = slot_max if slot_rms is None else slot_rms
    return Sample(t, "NAVIGATING", "robot_0", formation, (), rms, slot_max, NAN, NAN, NAN, NAN, NAN, NAN, "", {})


def recorded_run():
    """FORMING 10 -> 14.5 s; column at 50 s, within 0.3 m from 54.3 s; robot_2 silent from
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
    errors = {49.9: 0.01, 50.0: 1.8, 52.0: 0.9, 54.2: 0.31, 54.3: 0.29, 54.4: 0.2}
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
    assert got == {"converge_s": 4.5, "switch_s": 4.3, "degraded_s": 1.1, "recover_s": 4.0}


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
    runs = [{"succeeded": True, "contacts": 0, "switch_s": 4.3, "converge_s": None},
            {"succeeded": False, "contacts": 2, "switch_s": 6.1, "converge_s": 7.0}]
    row = worst(runs)
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
