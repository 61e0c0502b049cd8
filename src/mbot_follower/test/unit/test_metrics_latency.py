"""The control latency: each follower cycle's pose age at the moment the simulator applied its
command (the simulator's report, /stage/applied_commands), on synthetic streams with known answers."""
import math

import pytest

from mbot_follower.metrics import MetricsCollector, MetricsConfig, RunWriter, load_run, summarize

PERIOD = 0.05   # follower cycle [s]
STEP = 0.01     # physics step [s]
AGE = 0.04      # the pose's age when the command is computed [s]


def twist(k):
    """A distinct command per cycle, as the twist's six numbers."""
    return (0.1 + 0.001 * k, 0.0, 0.0, 0.0, 0.0, 0.3 - 0.002 * k)


ZERO = (0.0,) * 6


def cycles(n, start=1.0, cmd=twist):
    """n cycles of robot_1: (t, pose stamp, cmd)."""
    return [(start + PERIOD * k, start + PERIOD * k - AGE, cmd(k)) for k in range(n)]


def state(c, robot, t, pose_stamp, cmd):
    c.on_follower_state(robot, t, pose_stamp, True, 1, 0, 0.001, "slot", cmd=cmd)


def reports(applied, since, until, every=0.1):
    """The simulator's messages for [since, until): (since, stamp, commands) every `every` s;
    applied: [(robot, received, applied, cmd)]."""
    out, t = [], since
    while t < until - 1e-9:
        end = round(t + every, 9)
        out.append((t, end, [a for a in applied if t - 1e-9 <= a[2] < end - 1e-9]))
        t = end
    return out


def feed(c, messages):
    for since, until, commands in messages:
        c.on_applied_commands(since, until, commands)


def play(c, cs, messages, lag=0.0):
    """Feed robot_1's cycles and the reports in time order (a report when sim time reaches its
    stamp + lag)."""
    events = [(t, 1, (t, pose, cmd)) for t, pose, cmd in cs] + [(m[1] + lag, 0, m) for m in messages]
    for _, kind, item in sorted(events, key=lambda e: (e[0], e[1])):
        if kind == 1:
            state(c, "robot_1", *item)
        else:
            feed(c, [item])


def latencies(c, robot="robot_1"):
    return [(row.latency, row.applied) for row in c.run.controller if row.robot == robot]


def test_latency_is_the_pose_age_when_the_simulator_applied_the_command():
    c = MetricsCollector()
    cs = cycles(20)
    for t, pose, cmd in cs:
        state(c, "robot_1", t, pose, cmd)
    # received 3 ms after it was computed, applied at the next step (1 step later here)
    applied = [("robot_1", t + 0.003, t + STEP, cmd) for t, _, cmd in cs]
    applied.append(("robot_0", 1.2, 1.2, twist(99)))   # the leader's move_base: not a follower cycle
    feed(c, reports(applied, 1.0, 3.0))
    c.finish()
    assert [lat for lat, _ in latencies(c)] == pytest.approx([AGE + STEP] * 20)
    assert [a for _, a in latencies(c)] == [1.0] * 20
    fleet = summarize(c.run)["fleet"]
    assert fleet["latency_p95_s"] == pytest.approx(AGE + STEP)
    assert fleet["latency_method"] == "simulator" and fleet["commands_not_applied"] == 0
    assert [e.name for e in c.run.events if e.kind == "latency_method"] == ["simulator"]


def test_repeated_identical_twists_each_pair_with_the_first_application_at_or_after_them():
    """A follower holding its robot still sends zeros every cycle: each cycle takes the first zero
    applied at or after its own stamp, not an earlier one."""
    c = MetricsCollector()
    cs = cycles(10, cmd=lambda k: ZERO)
    delays = [STEP, 2 * STEP, STEP, 3 * STEP, STEP, STEP, 2 * STEP, STEP, STEP, STEP]
    applied = [("robot_1", t, t + d, cmd) for (t, _, cmd), d in zip(cs, delays)]
    for t, pose, cmd in cs:
        state(c, "robot_1", t, pose, cmd)
    feed(c, reports(applied, 1.0, 3.0))
    assert [lat for lat, _ in latencies(c)] == pytest.approx([AGE + d for d in delays])


def test_a_command_never_applied_is_counted_and_has_no_latency():
    """Cycle 4's command was replaced before a step (dropped): it is never in the report."""
    c = MetricsCollector(MetricsConfig(command_wait=0.5))
    cs = cycles(20)
    applied = [("robot_1", t, t + STEP, cmd) for k, (t, _, cmd) in enumerate(cs) if k != 4]
    messages = reports(applied, 1.0, 3.0)
    for t, pose, cmd in cs[:7]:
        state(c, "robot_1", t, pose, cmd)
    feed(c, messages[:3])   # up to 1.3 s: cycle 4 (1.2 s) may still come, so it and all after wait
    assert len(latencies(c)) == 4
    for t, pose, cmd in cs[7:]:
        state(c, "robot_1", t, pose, cmd)
    feed(c, messages[3:])   # past 1.2 + command_wait: it was not applied
    result = latencies(c)
    assert len(result) == 20
    assert math.isnan(result[4][0]) and result[4][1] == 0.0
    assert [lat for k, (lat, _) in enumerate(result) if k != 4] == pytest.approx([AGE + STEP] * 19)
    fleet = summarize(c.run)["fleet"]
    assert fleet["commands_not_applied"] == 1
    assert fleet["latency_max_s"] == pytest.approx(AGE + STEP)


def test_the_two_topics_may_arrive_in_any_order():
    cs = cycles(20)
    applied = [("robot_1", t + 0.004, t + 2 * STEP, cmd) for t, _, cmd in cs]
    messages = reports(applied, 1.0, 3.0)
    expected = [AGE + 2 * STEP] * 20

    report_first = MetricsCollector()
    feed(report_first, messages)
    for t, pose, cmd in cs:
        state(report_first, "robot_1", t, pose, cmd)
    assert [lat for lat, _ in latencies(report_first)] == pytest.approx(expected)

    interleaved = MetricsCollector()   # each report before the cycles it covers have all arrived
    for k, (t, pose, cmd) in enumerate(cs):
        if k % 2 == 0 and k // 2 < len(messages):
            feed(interleaved, [messages[k // 2 + 1]] if k // 2 + 1 < len(messages) else [])
            if k == 0:
                feed(interleaved, [messages[0]])
        state(interleaved, "robot_1", t, pose, cmd)
    feed(interleaved, [m for m in messages[11:]])
    interleaved.finish()
    assert [lat for lat, _ in latencies(interleaved)] == pytest.approx(expected)
    assert summarize(interleaved.run)["fleet"]["commands_not_applied"] == 0


def test_without_the_simulators_report_the_latency_is_the_pose_age_and_says_so_once():
    c = MetricsCollector(MetricsConfig(command_wait=1.0))
    cs = cycles(40)
    for t, pose, cmd in cs[:15]:
        state(c, "robot_1", t, pose, cmd)
    assert latencies(c) == []   # 0.7 s: the report may still come
    for t, pose, cmd in cs[15:]:
        state(c, "robot_1", t, pose, cmd)
    c.finish()
    assert [lat for lat, _ in latencies(c)] == pytest.approx([AGE] * 40)
    assert all(math.isnan(a) for _, a in latencies(c))
    assert [e.name for e in c.run.events if e.kind == "latency_method"] == ["pose_age"]
    fleet = summarize(c.run)["fleet"]
    assert fleet["latency_method"] == "pose_age" and fleet["commands_not_applied"] == 0


def test_a_cycle_the_report_did_not_cover_is_not_counted_as_not_applied():
    """The report starts at 1.5 s (the collector subscribed late) and pauses in [2.0, 2.2): the
    commands in those spans are unknown, not dropped."""
    c = MetricsCollector(MetricsConfig(command_wait=1.0))
    cs = cycles(30)
    applied = [("robot_1", t, t + STEP, cmd) for t, _, cmd in cs]
    play(c, cs, reports(applied, 1.5, 2.0) + reports(applied, 2.2, 3.0))
    c.finish()
    result = dict(zip([round(t, 3) for t, _, _ in cs], latencies(c)))
    assert len(result) == 30
    for t, (lat, applied_flag) in result.items():
        covered = 1.5 <= t + STEP < 2.0 or 2.2 <= t + STEP
        if covered:
            assert (lat, applied_flag) == (pytest.approx(AGE + STEP), 1.0), t
        else:
            assert math.isnan(lat) and math.isnan(applied_flag), t
    assert summarize(c.run)["fleet"]["commands_not_applied"] == 0


def test_applied_flags_round_trip_through_the_files_and_old_files_still_load(tmp_path):
    c = MetricsCollector(MetricsConfig(command_wait=0.5))
    cs = cycles(20)
    applied = [("robot_1", t, t + STEP, cmd) for k, (t, _, cmd) in enumerate(cs) if k != 3]
    play(c, cs, reports(applied, 1.0, 3.0), lag=0.3)
    c.finish()
    summary = summarize(c.run)
    RunWriter(str(tmp_path)).write(c.run, summary)
    back = load_run(str(tmp_path))
    assert [str(r) for r in back.controller] == [str(r) for r in c.run.controller]
    assert summarize(back) == summary and summary["fleet"]["commands_not_applied"] == 1
    # a record written before the `applied` column: applied unknown
    path = tmp_path / "controller.csv"
    lines = path.read_text().splitlines()
    path.write_text("\n".join(",".join(line.split(",")[:9]) for line in lines) + "\n")
    assert all(math.isnan(r.applied) for r in load_run(str(tmp_path)).controller)
