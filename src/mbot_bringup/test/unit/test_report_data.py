"""The report's numbers (report_data) and plot helpers (report_plots) on plain data: criteria,
slots of an assignment, speeds, what is better in a comparison, robot colours."""
import importlib.util
import math
import os

import numpy as np
import pytest
from matplotlib.colors import to_rgb

from mbot_bringup.report_data import Criterion, LabCriteria, ReportError, Series, arrival_time, assignment_at, \
    assignments, compare_rows, evaluate, event_marks, format_value, parse_criteria, pause_spans, run_numbers, \
    slot_positions, speeds, switch_settling
from mbot_bringup.colors import robot_colors
from mbot_bringup.report_plots import error_limit, snapshot_indices, snapshot_labels
from mbot_follower.metrics import Event, Run, RobotSample, Sample, load_run, summarize

FIXTURE = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "fixtures", "run_trio")
NAN = float("nan")


def test_assignments_are_read_from_the_collectors_events():
    run = load_run(os.path.join(FIXTURE, "metrics"))
    assigned = assignments(run)
    assert [a.formation for a in assigned] == ["triangle", "triangle", "line", "line"]
    assert assigned[0].leader == "leader"
    assert assigned[0].slots["follower_1"] == (-2.16506, 1.25)
    assert assigned[-1].slots == {"follower_1": (0.0, 2.5), "follower_2": (0.0, -2.5), "leader": (0.0, 0.0)}
    assert assignment_at(assigned, 6171.44).formation == "triangle"
    assert assignment_at(assigned, 6171.45).formation == "line"
    assert assignment_at(assigned, 0.0) is None


def test_an_unreadable_assignment_names_the_file_and_the_time():
    run = Run()
    run.events.append(Event(3.5, "assignment", "line", "slots everywhere", NAN, NAN))
    with pytest.raises(ReportError, match=r"^x/events.csv: assignment at t = 3.50 s: expected"):
        assignments(run, "x/events.csv")


def test_slots_follow_the_leaders_pose():
    run = Run()
    run.events.append(Event(0.0, "assignment", "column", "leader L spacing 1 m slots L(0,0) a(-2,1)", NAN, NAN))
    a = assignments(run)[0]
    slots = slot_positions(a, (1.0, 2.0, math.pi / 2))   # leader at (1, 2) facing +y
    assert list(slots) == ["a"]                          # the leader has no slot ring
    assert slots["a"][0] == pytest.approx(0.0) and slots["a"][1] == pytest.approx(0.0)
    assert slot_positions(a, (NAN, 0.0, 0.0)) == {}


def test_criteria_pass_fail_and_missing_values():
    numbers = {"steady_navigating_slot_rms_m": 0.15, "leader_lateral_rms_m": 0.081, "latency_p95_s": None,
               "tf_success_rate": 0.99995, "contacts": 0, "arrived": False}
    result = dict((c.name, c.passed) for c in evaluate(numbers, LabCriteria().criteria()))
    assert result == {"steady_navigating_slot_rms_m": True, "leader_lateral_rms_m": False, "latency_p95_s": False,
                      "tf_success_rate": True, "contacts": True, "arrived": False}


def test_criteria_json_is_read_strictly():
    good = {"scenario": "s", "passed": False, "facts": {"finished": True},
            "criteria": [{"name": "contacts", "value": 2, "threshold": 0, "op": "<=", "passed": False}]}
    assert parse_criteria(good, "c.json") == ("s", False, [Criterion("contacts", 2, "<=", 0, False)],
                                              {"finished": True})
    bad = [({"scenario": "s", "passed": True}, "c.json: criteria: missing"),
           (dict(good, extra=1), "c.json: unknown key(s) extra"),
           (dict(good, criteria=[{"name": "x", "value": 1, "op": "<="}]), "c.json: criteria[0]: expected the keys"),
           (dict(good, criteria=[dict(good["criteria"][0], threshold="0")]),
            'c.json: criteria[0].threshold: expected a number or true/false, got "0"'),
           (dict(good, facts=[]), "c.json: facts: expected an object")]
    for data, message in bad:
        with pytest.raises(ReportError) as error:
            parse_criteria(data, "c.json")
        assert str(error.value).startswith(message)


def test_values_are_shown_in_the_unit_of_the_table():
    assert format_value("latency_p95_s", 0.1235) == "124"          # [ms]
    assert format_value("tf_success_rate", 0.98765) == "98.765"    # [%]
    assert format_value("steady_navigating_slot_rms_m", 0.12345) == "0.123"
    assert format_value("arrived", True) == "yes"
    assert format_value("leader_lateral_rms_m", None) == "-"
    assert format_value("my_own_criterion", 2.5) == "2.5"


def test_speed_over_a_window_removes_the_jitter_of_sampled_poses():
    # 0.3 m/s along x, sampled at 10 Hz; each sample holds a pose up to 0.1 s old (as the
    # collector's samples do when poses arrive late)
    t = np.arange(0.0, 10.0, 0.1)
    age = np.where(np.arange(len(t)) % 3 == 0, 0.1, 0.0)
    x = 0.3 * (t - age)
    short = speeds(t, x, np.zeros_like(t), 0.25, 1.0)            # over the neighbours: 0.2 s
    smooth = speeds(t, x, np.zeros_like(t), 1.0, 1.0)
    assert np.nanmax(np.abs(short[2:-2] - 0.3)) == pytest.approx(0.15)   # 0.15 or 0.45 m/s
    assert np.nanmax(np.abs(smooth[6:-6] - 0.3)) < 0.035         # over 1 s: within ~10 %
    gap = speeds([0.0, 0.1, 5.0, 5.1], [0.0, 0.03, 0.0, 0.03], [0.0] * 4, 1.0, 1.0)
    assert math.isnan(gap[0]) is False and math.isnan(gap[2]) is False
    assert gap[1] == pytest.approx(0.3) and gap[3] == pytest.approx(0.3)   # never across the 4.9 s gap


def sample(t, state, slot_rms, leader_x=0.0):
    robots = {"L": RobotSample(leader_x, 0.0, 0.0, NAN, NAN, leader_x, 0.0),
              "f": RobotSample(leader_x - 1.0, 0.0, 0.0, slot_rms, slot_rms, leader_x, 0.0)}
    return Sample(t, state, "L", "line", (), slot_rms, slot_rms, slot_rms, slot_rms, 0.0, 0.0, 0.0, 0.5, "L f",
                  robots)


def test_a_switch_settles_when_the_slot_rms_stays_under_the_recovery_bound():
    run = Run()
    run.robots = ["L", "f"]
    rms = [0.05] * 10 + [1.0, 0.8, 0.5, 0.2, 0.1, 0.12, 0.3] + [0.1] * 12
    run.samples = [sample(0.1 * k, "NAVIGATING", v) for k, v in enumerate(rms)]
    run.events = [Event(0.0, "state", "NAVIGATING", "", NAN, NAN), Event(1.0, "switch", "line", "column", NAN, NAN)]
    settled = switch_settling(run)
    assert len(settled) == 1
    # under 0.15 m from 1.7 s on for the 1 s hold (1.4 s is under, but 1.6 s is not)
    assert run.samples[17].t == pytest.approx(1.7)
    assert settled[0]["settle_s"] == pytest.approx(0.7)
    assert settled[0]["peak_rms_m"] == 1.0
    assert run_numbers(run, summarize(run))["switch_settle_max_s"] == pytest.approx(0.7)
    assert [m.label for m in event_marks(run)] == ["switch column > line"]


def test_compare_says_which_run_is_better():
    a = {"slot_rms_m": 0.2, "tf_success_rate": 0.999, "latency_p95_s": 0.1, "arrived": True, "distance_m": 10.0}
    b = {"slot_rms_m": 0.1, "tf_success_rate": 0.998, "latency_p95_s": 0.1002, "arrived": False, "distance_m": 12.0}
    rows = dict((key, (diff, better)) for key, _, _, diff, better in compare_rows(a, b))
    assert rows["slot_rms_m"] == (pytest.approx(-0.1), "B")          # lower is better
    assert rows["tf_success_rate"] == (pytest.approx(-0.001), "A")   # higher is better
    assert rows["latency_p95_s"][1] == "same"                         # 0.2 ms apart: the same when shown in ms
    assert rows["arrived"] == (None, "A")
    assert rows["distance_m"] == (pytest.approx(2.0), "")             # neither is better
    assert "contacts" not in rows                                     # neither run has it


def test_robots_have_the_colours_of_their_simulator_markers():
    colors = robot_colors(["b", "a", "c", "new"], ["a", "b", "c"])
    # /stage/markers: robot i of the world has hue i / 6: red, yellow, green (here 80 % as bright)
    assert colors["a"] == pytest.approx((0.8, 0.2, 0.2))
    assert colors["b"] == pytest.approx((0.6, 0.6, 0.0))
    assert colors["c"] == pytest.approx((0.2, 0.8, 0.2))
    assert colors["new"] == pytest.approx((0.0, 0.6, 0.6))          # the 4th: cyan
    many = robot_colors(["r%d" % i for i in range(12)], [])
    assert len(set(many.values())) == 12


def test_error_axes_show_the_limit_and_the_typical_error():
    assert error_limit(np.array([0.01, 0.02, NAN, 2.5]), 0.15) == pytest.approx(0.6)   # 4 x the limit
    assert error_limit(np.array([1.0, 1.0, 1.2]), 0.15) == pytest.approx(1.5)         # 1.5 x the median
    assert error_limit(np.array([0.2, 0.4]), None) == pytest.approx(0.45)


def test_snapshots_fall_where_the_fleet_moves():
    run = load_run(os.path.join(FIXTURE, "metrics"))
    series = Series(run)
    chosen = snapshot_indices(series, run)
    times = [series.t[i] for i in chosen]
    # the first samples after the target and the arrival (samples at 5 Hz, 0.05 s after the events)
    assert times[0] == pytest.approx(0.15) and times[-1] == pytest.approx(51.75)
    assert any(0.0 <= t - 19.0 < 0.2 for t in times)               # the switch (the first sample after it)
    assert any(19.5 < t < 25.0 for t in times)                     # the followers moving out while the leader waits
    assert 8 <= len(chosen) <= 13


def test_snapshots_reach_the_last_arrival_of_a_route_of_several_targets():
    """Two targets: ARRIVED at 10 s, then the fleet drives on and arrives again at 30 s; the
    snapshots cover the second leg too, none within a second of another."""
    run = load_run(os.path.join(FIXTURE, "metrics"))
    first = arrival_time(run)
    run.events.append(Event(first - 30.0, "state", "ARRIVED", "an earlier target", NAN, NAN))
    series = Series(run)
    times = [series.t[i] for i in snapshot_indices(series, run)]
    assert arrival_time(run) == pytest.approx(first - 30.0)
    assert arrival_time(run, last=True) == pytest.approx(first)
    assert times[-1] == pytest.approx(51.75)
    assert min(b - a for a, b in zip(times, times[1:])) >= 1.0 - 1e-9


def test_snapshots_at_one_place_share_one_time_label():
    labels = snapshot_labels([(5.0, -3.5), (5.1, -3.5), (7.0, 0.0), (5.0, -3.3), (7.7, 3.5), (7.7, 3.5)],
                             [14.2, 16.0, 40.0, 22.4, 60.0, 60.2], 0.6)
    assert labels == [((5.0, -3.5), "14, 16, 22 s"), ((7.0, 0.0), "40 s"), ((7.7, 3.5), "60 s")]


def test_events_to_mark_on_the_time_axes():
    # the events as the collector writes them (mbot_follower.metrics.records.Event); a pause is
    # its own start / end events, the state stays NAVIGATING
    run = Run()
    run.events = [Event(5.0, "contact", "follower_1", "map", 1.0, 2.0),
                  Event(1.0, "state", "NAVIGATING", "formation reached", NAN, NAN),
                  Event(2.0, "pause", "start", "paused: obstacle in front of the leader leader", NAN, NAN),
                  Event(2.8, "pause", "end", "resuming: the way is free", NAN, NAN),
                  Event(3.0, "loss", "follower_2", "", NAN, NAN),
                  Event(4.0, "rejoin", "follower_2", "", NAN, NAN),
                  Event(4.5, "assignment", "line", "leader L spacing 1 m slots L(0,0)", NAN, NAN),
                  Event(6.0, "fault", "follower_1", "drive_frozen", NAN, NAN),
                  Event(7.0, "pause", "start", "paused: scan of leader is 0.5 s old", NAN, NAN)]
    assert [(m.t, m.kind, m.label) for m in event_marks(run)] == [
        (2.0, "pause", "pause: obstacle in front of the leader leader"), (3.0, "loss", "lost follower_2"),
        (4.0, "rejoin", "follower_2 back"), (5.0, "contact", "contact follower_1-map"),
        (6.0, "fault", "fault follower_1"), (7.0, "pause", "pause: scan of leader is 0.5 s old")]
    # the second pause is still on when the run ends at 9 s
    assert pause_spans(run, 9.0) == [(2.0, 2.8, "obstacle in front of the leader leader"),
                                     (7.0, 9.0, "scan of leader is 0.5 s old")]


def _coordinator_fleet_module():
    """mbot_follower's test_coordinator_events (the coordinator node wired to the metrics
    collector node, no master), loaded by its path: the record below is what it writes."""
    path = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..", "mbot_follower", "test",
                        "unit", "test_coordinator_events.py")
    spec = importlib.util.spec_from_file_location("coordinator_events_for_the_report", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def test_a_leader_pause_from_the_coordinators_record_is_a_shaded_span_and_a_row_with_its_reason(monkeypatch,
                                                                                                tmp_path):
    from mbot_common.geometry import Pose2D
    from mbot_follower.metrics import RunWriter
    from mbot_bringup.report import timeline_table
    from mbot_bringup.report_plots import STYLE, mark_events, pyplot
    fleet = _coordinator_fleet_module().Fleet(monkeypatch)
    assert fleet.node._set_goal(Pose2D(20.0, 0.0, 0.0))[0]
    fleet.run(2.0)
    fleet.obstacle = True                    # close in front of the leader: the coordinator pauses
    fleet.run(0.3)
    fleet.obstacle = False
    fleet.run(1.5)                           # the pause ends after pause_time
    RunWriter(str(tmp_path)).write(fleet.metrics.collector.run, {})
    run = load_run(str(tmp_path))            # events.csv read back, as the report reads it
    end = max(e.t for e in run.events)
    spans = pause_spans(run, end)
    assert len(spans) == 1
    start, stop, reason = spans[0]
    assert reason == "obstacle in front of the leader robot_0"
    assert stop - start == pytest.approx(fleet.node.core.config.pause_time, abs=0.1 + 1e-6)
    assert [(m.t, m.label) for m in event_marks(run) if m.kind == "pause"] == [
        (start, "pause: obstacle in front of the leader robot_0")]
    # the "What happened" table: the start with its reason, the end with the length
    page = timeline_table(type("Inputs", (), {"run": run})())
    t0 = next(e.t for e in run.events if e.kind == "state" and e.name == "FORMING")
    assert ('<tr class="pause"><td class="l">leader paused</td><td class="l">obstacle in front of the leader '
            'robot_0</td><td>%.2f</td></tr>' % (start - t0)) in page
    assert ('<td class="l">pause ends</td><td class="l">after %.2f s; resuming: ' % (stop - start)) in page
    # the plots: one span from start to end in the pause colour
    plt = pyplot()
    fig, ax = plt.subplots()
    ax.set_xlim(0.0, end - t0)
    mark_events(ax, run, t0)
    shaded = [p for p in ax.patches if p.get_facecolor()[:3] == pytest.approx(to_rgb(STYLE.mark_colors["pause"]))]
    assert len(shaded) == 1
    xs = shaded[0].get_patch_transform().transform(shaded[0].get_path().vertices)[:, 0]   # data x
    assert min(xs) == pytest.approx(start - t0) and max(xs) == pytest.approx(stop - t0)
    plt.close(fig)


def test_a_column_along_the_path_has_its_slots_on_the_leaders_path():
    from mbot_bringup.report_data import leader_trail
    from mbot_follower.fleet_io import Assignment
    from mbot_follower.metrics import MetricsCollector

    def l_path(s):   # 1.5 m along +x from (0, 0), then along +y
        return (s, 0.0, 0.0) if s <= 1.5 else (1.5, s - 1.5, math.pi / 2)

    column = {"L": (0.0, 0.0), "a": (-1.0, 0.0), "b": (-2.0, 0.0)}
    c = MetricsCollector()
    c.on_assignment(0.0, Assignment("L", "column", 1.0, column, {r: "L" for r in column}, True))
    c.on_status(0.0, "NAVIGATING", "goal", [])
    for k in range(150):                  # the leader drives the L at 1 m/s, the column on its path
        t = k / 50.0
        for r, (x, _) in column.items():
            c.on_pose(r, t, *l_path(t + x))
    a = assignments(c.run)[0]
    assert a.along_path and a.slots == column
    series = Series(c.run)
    i = len(series.t) - 1                 # t = 2.9 s: a at (1.5, 0.4), b at (0.9, 0) before the corner
    leader = series.pose("L", i)
    trail = leader_trail(series, a, i)
    on_path = slot_positions(a, leader, trail)
    for r in ("a", "b"):
        assert on_path[r] == pytest.approx(series.pose(r, i)[:2], abs=1e-9)
    # the one definition (trail.LeaderTrail): the collector's path of the same samples, alike
    assert (trail.since, trail.length()) == (c._trail.since, pytest.approx(c._trail.length(), abs=1e-9))
    assert trail.point_behind(trail.length()) == c._trail.point_behind(c._trail.length()) == (0.0, 0.0)
    rigid = slot_positions(a, leader)      # no trail: rigid slots, b's 0.85 m off
    assert math.hypot(rigid["b"][0] - 0.9, rigid["b"][1]) == pytest.approx(math.hypot(0.6, 0.6))
