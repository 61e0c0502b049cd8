"""Scenario files are read strictly, the timeline runs in order on events, criteria judge numbers."""
import glob
import math
import os

import pytest

from mbot_bringup.scenario import (CRITERIA, FORMATION_DEFAULTS, LAB_THRESHOLDS, Timeline, TimelineConfig, check,
                                   check_against_world, criteria_reasons,
                                   evaluate, load_scenario, loss_detection_times, scenario_window, summary_lines,
                                   takes_a_robot_out)
from mbot_common.strict_yaml import ConfigError
from mbot_follower.metrics import Event, RobotSample, Run, Sample, switch_done_times

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURES = os.path.join(HERE, "..", "fixtures", "scenarios")
SCENARIOS = os.path.join(HERE, "..", "..", "scenarios")


def fixture(name):
    return os.path.join(FIXTURES, name)


def expected_message(path):
    with open(path) as f:
        first = f.readline()
    assert first.startswith("# expect: "), "%s: the first line must be '# expect: <message>'" % path
    return first[len("# expect: "):].strip().replace("{file}", path)


# --- reading ---------------------------------------------------------------------------------

def test_every_key_and_action_is_read():
    s = load_scenario(fixture("valid_every_action.yaml"))
    assert (s.name, s.world, s.robots, s.mode, s.leader) == ("valid_every_action", "trio", 4, "formation", "leader")
    assert (s.formation, s.spacing, s.topology, s.controller, s.localization) == \
        ("triangle", 1.5, "chain", "consensus", "pf")
    assert (s.leader_max_vel, s.time_limit, s.end) == (0.3, 200.0, "formed")
    assert [st.action for st in s.timeline] == [
        "target", "formation", "formation", "spawn_obstacle", "spawn_obstacle", "remove_obstacle", "set_param",
        "fault", "kill_controller", "remove_robot", "spawn_robot", "screenshot"]
    assert s.timeline[0].arg == [5.0, 0.0, 0.0] and s.timeline[0].at == 0.0
    assert (s.timeline[1].after, s.timeline[1].delay) == ("navigating", 2.5)
    assert s.timeline[1].arg == {"name": "line", "spacing": 1.2}
    assert s.timeline[2].arg == {"name": "wedge", "spacing": 0.0}
    assert s.timeline[3].arg == {"name": "box_1", "shape": "box", "length": 0.5, "width": 0.4, "radius": 0.0,
                                 "pose": [2.0, 1.0, 0.0]}
    assert s.timeline[4].arg["radius"] == 0.2
    assert s.timeline[6].arg == {"name": "/follower_1/follower_controller/max_linear_vel", "value": 0.3}
    fault = s.timeline[7].arg
    assert (fault["robot"], fault["laser_dropout"], fault["sensor_latency"], fault["silenced"]) == (
        "follower_2", 0.2, 0.05, False)
    assert s.timeline[10].arg == {"name": "follower_2", "model": "mbot", "pose": [1.0, -3.0, 0.0]}
    # the defaults, with one changed, one removed and three added
    expected = dict(FORMATION_DEFAULTS, steady_navigating_slot_rms_m=0.2, switches=2, max_recovery_time_s=10)
    del expected["tf_success_rate"]
    assert s.criteria == expected
    assert s.criteria_why == {"steady_navigating_slot_rms_m": "a wider formation in a test of the reader"}
    assert criteria_reasons(fixture("valid_every_action.yaml")) == s.criteria_why


def test_dispatch_mode_counts_its_goals():
    s = load_scenario(fixture("valid_dispatch.yaml"))
    assert (s.mode, s.end, s.robots, s.formation) == ("dispatch", "goals_done", 5, "")
    assert s.timeline[0].arg[2] == [3.5, 4.0, 0.0]
    assert s.criteria == {"finished": True, "failed_steps": 0, "contacts": 0, "goals_reached": 4}


@pytest.mark.parametrize("path", sorted(glob.glob(os.path.join(FIXTURES, "invalid_*.yaml"))),
                         ids=lambda p: os.path.basename(p))
def test_each_invalid_file_is_one_line_naming_the_key(path):
    with pytest.raises(ConfigError) as error:
        load_scenario(path)
    message = str(error.value)
    assert "\n" not in message
    assert expected_message(path) in message


def test_the_shipped_scenarios_read():
    names = sorted(os.path.basename(p)[:-5] for p in glob.glob(os.path.join(SCENARIOS, "*.yaml")))
    for name in ("triangle_trio", "office_route", "corridor_switch", "people", "follower_loss", "leader_loss",
                 "dispatch", "fleet10"):
        assert name in names
    for name in names:
        s = load_scenario(os.path.join(SCENARIOS, name + ".yaml"))
        assert s.description, "%s: say what the scenario shows" % name
        # every threshold looser than the lab's says why, and the lab's stay the defaults
        looser = [n for n, v in s.criteria.items() if n in LAB_THRESHOLDS and not isinstance(v, bool)
                  and (v < LAB_THRESHOLDS[n] if CRITERIA[n][0] == ">=" else v > LAB_THRESHOLDS[n])]
        assert sorted(s.criteria_why) == sorted(looser), name
        assert criteria_reasons(s.path) == s.criteria_why
    assert load_scenario(os.path.join(SCENARIOS, "triangle_trio.yaml")).criteria["latency_p95_s"] == \
        FORMATION_DEFAULTS["latency_p95_s"] == LAB_THRESHOLDS["latency_p95_s"]


def test_the_scenario_is_checked_against_the_run_robots():
    s = load_scenario(fixture("valid_every_action.yaml"))
    check_against_world(s, ["leader", "follower_1", "follower_2", "robot_3"])
    with pytest.raises(ConfigError) as error:
        check_against_world(s, ["leader", "follower_2", "robot_2", "robot_3"])
    assert 'timeline[8].do.kill_controller: no robot "follower_1" in the run' in str(error.value)
    with pytest.raises(ConfigError) as error:      # a line takes 2 robots or more, a triangle 3
        check_against_world(s, ["leader", "follower_1"])
    assert "formation: formation 'triangle' takes at least 3 robots, got 2" in str(error.value)
    d = load_scenario(fixture("valid_dispatch.yaml"))
    check_against_world(d, ["robot_0", "robot_1"])   # 3 goals for 2 robots: the dispatcher queues them


# --- the timeline ----------------------------------------------------------------------------

def timeline_of(name, settle=2.0):
    return Timeline(load_scenario(fixture(name)), TimelineConfig(settle=settle))


def test_steps_run_in_order_each_when_its_condition_holds():
    t = timeline_of("valid_every_action.yaml")
    assert [s.index for s in t.due(0.0)] == [0]
    assert t.due(10.0) == []                      # step 1 waits for navigating
    t.observe("navigating", 12.0)
    assert t.due(13.0) == []                      # ... and 2.5 s more
    assert [s.index for s in t.due(14.5)] == [1]
    t.observe("formed", 20.0)
    # formed came after step 1 ran: step 2 runs; steps 3.. wait for 30 s
    assert [s.index for s in t.due(20.0)] == [2]
    assert t.due(29.9) == []
    # late: everything whose time has come runs at once, in order
    assert [s.index for s in t.due(50.0)] == [3, 4, 5, 6, 7, 8, 9, 10]
    assert t.next_step().index == 11


def test_after_waits_for_the_next_event_not_an_old_one():
    t = timeline_of("valid_every_action.yaml")
    t.observe("navigating", 0.0)                  # at the time step 0 runs: before it, so not for step 1
    t.due(0.0)
    assert t.due(5.0) == []
    t.observe("navigating", 0.1)
    t.observe("formed", 1.0)                      # before step 1 runs: does not count for step 2
    assert [s.index for s in t.due(2.6)] == [1]
    assert t.due(5.0) == []
    t.observe("formed", 6.0)
    assert [s.index for s in t.due(6.0)] == [2]


def test_the_run_ends_on_the_end_event_after_the_last_step_and_settles():
    t = timeline_of("valid_dispatch.yaml", settle=2.0)
    t.due(0.0)
    t.observe("goals_done", 40.0)
    assert [s.index for s in t.due(40.0)] == [1]
    assert not t.finished(41.0)                  # the goals_done at 40 s was the first dispatch's
    t.observe("goals_done", 55.0)
    assert t.end_time() == 55.0
    assert not t.finished(56.9)
    assert t.finished(57.0)
    assert not t.timed_out(300.0) and t.timed_out(300.1)


def test_an_unknown_event_is_a_programming_error():
    with pytest.raises(ValueError):
        timeline_of("valid_dispatch.yaml").observe("landed", 1.0)


# --- criteria --------------------------------------------------------------------------------

def sample(t, slot_max, state="NAVIGATING"):
    return Sample(t, state, "leader", "line", (), slot_max, slot_max, float("nan"), float("nan"), float("nan"),
                  float("nan"), float("nan"), float("nan"), "", {})


def run_with_switch():
    """A run whose followers reach the new slots (max error < 0.3 m) 4.0 s after a switch at 10 s,
    after a first dip under 0.3 m that does not hold 0.5 s."""
    run = Run()
    errors = {10.0: 1.2, 11.0: 0.9, 12.0: 0.25, 12.1: 0.35, 13.0: 0.5, 14.0: 0.29, 14.2: 0.2, 14.4: 0.1,
              14.6: 0.1, 15.0: 0.1}
    nan = float("nan")
    run.samples = [sample(t, e)._replace(robots={"f1": RobotSample(nan, nan, nan, e, nan, 0.0, 0.0)})
                   for t, e in sorted(errors.items())]
    run.events = [Event(10.0, "switch", "line", "triangle", float("nan"), float("nan"))]
    return run


def test_the_switch_time_criterion_is_the_metrics_switch_rule():
    run = run_with_switch()
    value = evaluate({"max_switch_time_s": 6.0}, summary_of(), run, FACTS)[0]["value"]
    assert value == pytest.approx(4.0) == switch_done_times(run)[0]["switch_time_s"]
    never = run_with_switch()
    never.samples = [s._replace(robots={"f1": s.robots["f1"]._replace(slot_error=0.5)}) for s in never.samples]
    assert evaluate({"max_switch_time_s": 6.0}, summary_of(), never, FACTS)[0]["value"] is None


def summary_of(**fleet):
    base = {"steady_navigating_slot_rms_m": 0.05, "leader_lateral_rms_m": 0.02, "latency_p95_s": 0.08,
            "tf_success_rate": 1.0, "contacts": 0, "switches": 1}
    base.update(fleet)
    return {"duration_s": 60.0, "fleet": base,
            "recoveries": [{"robot": "f1", "t_s": 5.0, "time_to_degraded_s": 1.05, "recovery_time_s": None}]}


FACTS = {"finished": True, "arrived": True, "failed_steps": 0, "goals_reached": 0, "lost_at_end": 0}


def test_criteria_pass_and_fail_on_the_numbers():
    criteria = dict(FORMATION_DEFAULTS, max_switch_time_s=5.0, max_time_to_degraded_s=1.0, duration_s=60.0)
    results = evaluate(criteria, summary_of(leader_lateral_rms_m=0.09, contacts=1), run_with_switch(), FACTS)
    by_name = {c["name"]: c for c in results}
    assert [c["name"] for c in results] == [n for n in CRITERIA if n in criteria]
    assert set(results[0]) == {"name", "value", "threshold", "op", "passed"}
    assert by_name["leader_lateral_rms_m"]["passed"] is False          # 0.09 > 0.08
    assert by_name["contacts"] == {"name": "contacts", "value": 1, "threshold": 0, "op": "<=", "passed": False}
    assert by_name["steady_navigating_slot_rms_m"]["passed"] is True
    assert by_name["tf_success_rate"]["op"] == ">=" and by_name["tf_success_rate"]["passed"] is True
    assert by_name["max_switch_time_s"]["value"] == pytest.approx(4.0) and by_name["max_switch_time_s"]["passed"]
    assert by_name["max_time_to_degraded_s"]["value"] == 1.05 and not by_name["max_time_to_degraded_s"]["passed"]
    assert by_name["duration_s"]["passed"] is True                      # 60 <= 60
    assert by_name["arrived"]["passed"] is True
    lines = summary_lines("x", results)
    assert lines[-1] == "FAILED: max_time_to_degraded_s, leader_lateral_rms_m, contacts" or \
        lines[-1].startswith("FAILED: ")
    assert sum(1 for line in lines if line.strip().startswith("FAIL ")) == 3


def test_a_criterion_without_data_fails():
    results = evaluate({"max_recovery_time_s": 10.0, "latency_p95_s": 0.12}, summary_of(latency_p95_s=None),
                       run_with_switch(), FACTS)
    assert [(c["name"], c["value"], c["passed"]) for c in results] == [
        ("latency_p95_s", None, False), ("max_recovery_time_s", None, False)]   # recovery never happened
    assert not check("<=", float("nan"), 1.0)
    assert check("==", False, False) and not check("==", True, False)
    assert math.isclose(evaluate({"tf_success_rate": 0.9999}, summary_of(tf_success_rate=0.99995),
                                 Run(), FACTS)[0]["value"], 0.99995)


def test_loss_detection_is_timed_from_the_step_to_degraded():
    t = timeline_of("valid_every_action.yaml")
    t.due(0.0)
    t.observe("navigating", 1.0)
    t.due(3.5)
    t.observe("formed", 5.0)
    assert [s.index for s in t.due(50.0)][-3:] == [8, 9, 10]   # the kill and the removal run at 50 s
    t.observe("degraded", 51.25)
    times = loss_detection_times(t)
    assert times == [pytest.approx(1.25), pytest.approx(1.25)]
    facts = dict(FACTS, loss_detection_s=times)
    result = evaluate({"max_loss_detection_s": 2.0}, summary_of(), Run(), facts)[0]
    assert result["value"] == pytest.approx(1.25) and result["passed"]
    never = evaluate({"max_loss_detection_s": 2.0}, summary_of(), Run(), dict(FACTS, loss_detection_s=[1.0, None]))
    assert never[0]["value"] is None and not never[0]["passed"]


def test_loss_detection_is_timed_from_when_the_step_s_call_returned():
    """On a loaded machine the simulator answered remove_robot 1.35 s of sim time after the call
    (scenario leader_loss, 2.45 s measured from the step): the robot is out when the call returns."""
    t = timeline_of("valid_every_action.yaml")
    t.due(0.0)
    t.observe("navigating", 1.0)
    t.due(3.5)
    t.observe("formed", 5.0)
    kill, remove = [s for s in t.due(50.0) if takes_a_robot_out(s)]
    t.done(kill, 50.1)
    t.done(remove, 51.35)
    t.observe("degraded", 52.6)
    assert loss_detection_times(t) == [pytest.approx(2.5), pytest.approx(1.25)]
    t.done(remove, 53.0)                                # DEGRADED before the call returned
    assert loss_detection_times(t)[1] == 0.0


def test_a_fault_that_freezes_or_silences_a_robot_is_timed_as_a_loss():
    """scenarios/faults.yaml: the laser dropout is no loss; follower_1's motors failing with its
    silence is, timed from the step to DEGRADED like a kill. A frozen drive alone counts too
    (the fleet should notice it), a fault without either does not."""
    t = Timeline(load_scenario(os.path.join(SCENARIOS, "faults.yaml")))
    assert [takes_a_robot_out(s) for s in t.steps] == [False, False, True]
    t.due(0.0)
    t.observe("navigating", 6.0)
    assert [s.index for s in t.due(8.0)] == [1]        # follower_2's laser
    assert loss_detection_times(t) == []
    assert [s.index for s in t.due(16.0)] == [2]       # follower_1's motors and its silence
    assert loss_detection_times(t) == [None]           # not (yet) noticed: fails max_loss_detection_s
    t.observe("degraded", 17.25)
    assert loss_detection_times(t) == [pytest.approx(1.25)]
    step = t.steps[2]
    arg = dict(step.arg)
    for frozen, silenced, out in ((True, False, True), (False, True, True), (False, False, False)):
        step.arg = dict(arg, drive_frozen=frozen, silenced=silenced)
        assert takes_a_robot_out(step) == out


def test_the_criteria_window_leaves_out_start_up_and_shut_down():
    from mbot_follower.metrics import ControllerSample, summarize

    run = Run()
    run.robots = ["leader", "f1"]
    run.samples = [sample(t, 0.1) for t in (1.0, 5.0, 10.0, 20.0)]
    run.events = [Event(0.5, "state", "IDLE", "", float("nan"), float("nan")),
                  Event(0.6, "assignment", "line", "", float("nan"), float("nan")),
                  Event(6.0, "state", "NAVIGATING", "", float("nan"), float("nan")),
                  Event(19.0, "contact", "f1", "wall", 0.0, 0.0)]
    # f1 failed 3 lookups while starting (before 4 s) and 1 after the end (after 12 s), 1 in between
    run.controller = [ControllerSample(2.0, "f1", 0.05, 1.0, 10, 3, "hold"),
                      ControllerSample(5.0, "f1", 0.05, 1.0, 110, 3, "slot"),
                      ControllerSample(10.0, "f1", 0.05, 1.0, 210, 4, "slot"),
                      ControllerSample(15.0, "f1", 0.05, 1.0, 310, 5, "slot")]
    window = scenario_window(run, 4.0, 12.0)
    assert [s.t for s in window.samples] == [5.0, 10.0]
    assert [(e.t, e.kind, e.name) for e in window.events] == [(4.0, "state", "IDLE"), (4.0, "assignment", "line"),
                                                              (6.0, "state", "NAVIGATING")]
    summary = summarize(window)
    assert summary["fleet"]["tf_success_rate"] == pytest.approx(1.0 - 1.0 / 200.0)   # (210 - 10) lookups, 1 failure
    assert summary["fleet"]["contacts"] == 0 and summarize(run)["fleet"]["contacts"] == 1
    assert summary["fleet"]["time_in_state_s"] == {"IDLE": 2.0, "NAVIGATING": 4.0}


def test_run_dir_is_emptied_only_when_an_earlier_run_wrote_it(tmp_path):
    from mbot_bringup.scenario_runner import prepare_run_dir

    other = tmp_path / "notes"
    other.mkdir()
    (other / "thesis.tex").write_text("keep me")
    with pytest.raises(ConfigError, match="not empty and not a run dir"):
        prepare_run_dir(str(other))
    assert (other / "thesis.tex").read_text() == "keep me"

    earlier = tmp_path / "run"
    earlier.mkdir()
    (earlier / "scenario.yaml").write_text("world: office\n")
    (earlier / "run.bag").write_text("old")
    prepare_run_dir(str(earlier))
    assert earlier.is_dir() and os.listdir(str(earlier)) == []

    prepare_run_dir(str(tmp_path / "new" / "run"))
    assert (tmp_path / "new" / "run").is_dir()


def test_a_dispatch_round_counts_only_the_results_of_its_own_goals():
    # The last result of round 1 set round 2 off in the same sim instant (t = 36.76): by time it
    # counted for round 2 as well, which then ended one goal early (seen once beside a stressed
    # suite: 9 of 10 goals reached).
    from mbot_bringup.scenario_runner import SUCCEEDED, round_ended

    results = [(36.76, "robot_4", SUCCEEDED, "dispatcher-5")]  # round 1's last
    round_2 = {"dispatcher-6", "dispatcher-7"}
    assert round_ended(results, round_2) == []
    results += [(50.0, "robot_0", SUCCEEDED, "dispatcher-6"), (51.0, "robot_1", 4, "dispatcher-7")]  # 4: ABORTED
    assert [x[3] for x in round_ended(results, round_2)] == ["dispatcher-6", "dispatcher-7"]
    assert round_ended(results + [(52.0, "robot_2", 1, "dispatcher-8")], {"dispatcher-8"}) == []  # 1: ACTIVE
