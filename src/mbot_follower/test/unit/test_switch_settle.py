"""One rule says when a formation switch is done (metrics.settle): the coordinator applies it
online, switch_done_times() to a recorded run, and on the same data both give the same times."""
import math

import pytest

from mbot_common.geometry import Pose2D
from mbot_follower.metrics import (SWITCH_HOLD, SWITCH_TOLERANCE, Event, RobotSample, Run, Sample, SwitchSettle,
                                   switch_done_times)
from test_coordinator_events import STEP, Fleet

NAN = float("nan")


def test_the_shape_must_hold_for_the_hold_and_the_time_is_when_it_was_reached():
    settle = SwitchSettle()
    assert (SWITCH_TOLERANCE, SWITCH_HOLD) == (0.3, 0.5)
    assert not settle.update(1.0, {"a": 0.25, "b": 0.5})
    assert not settle.update(1.1, {"a": 0.25, "b": 0.29})   # reached here ...
    assert not settle.update(1.3, {"a": 0.31, "b": 0.1})    # ... but not held
    for t in (1.4, 1.6, 1.8):
        assert not settle.update(t, {"a": 0.2, "b": 0.1})
    assert settle.update(1.9, {"a": 0.2, "b": 0.1})        # 0.5 s after 1.4 s
    assert (settle.reached_at, settle.done_at) == (1.4, 1.9)
    assert settle.update(2.0, {"a": 5.0})                   # done stays done until reset()
    settle.reset()
    assert not settle.done and settle.reached_at is None


def test_blocked_followers_are_left_out_and_nothing_measured_is_not_within():
    settle = SwitchSettle()
    assert settle.within({"a": 0.1, "b": 2.0}, blocked=["b"])
    assert settle.within({"b": 2.0}, blocked=["b"])        # every slot blocked: nobody to wait for
    assert settle.within({})                                # the leader alone
    assert not settle.within({"a": NAN})


@pytest.mark.parametrize("kwargs", [{"tolerance": 0.0}, {"tolerance": float("nan")}, {"hold": -1.0},
                                    {"hold": True}, {"tolerance": "0.3"}])
def test_a_bad_rule_is_refused_naming_the_value(kwargs):
    with pytest.raises(ValueError) as error:
        SwitchSettle(**kwargs)
    assert list(kwargs)[0] in str(error.value)


def sample(t, formation, errors, free=None):
    robots = {r: RobotSample(NAN, NAN, NAN, e, NAN, 0.0, 0.0, (free or {}).get(r, NAN)) for r, e in errors.items()}
    return Sample(t, "NAVIGATING", "L", formation, (), NAN, NAN, NAN, NAN, NAN, NAN, NAN, NAN, "", robots)


def test_a_recorded_run_is_judged_per_switch_in_its_new_formation_leaving_out_blocked_slots():
    run = Run()
    run.events = [Event(10.0, "switch", "column", "triangle", NAN, NAN),
                  Event(10.9, "switch_done", "column", "", NAN, NAN),
                  Event(20.0, "switch", "triangle", "column", NAN, NAN)]
    run.samples = [sample(10.0, "triangle", {"a": 0.1, "b": 0.1}),   # the old assignment still: not counted
                   sample(10.1, "column", {"a": 0.1, "b": 2.0}, free={"b": 0.0})]   # b's slot in a wall
    run.samples += [sample(round(10.2 + 0.1 * k, 1), "column", {"a": 0.1, "b": 2.0}, free={"b": 0.0})
                    for k in range(5)]
    # the triangle: never within before the end
    run.samples += [sample(round(20.0 + 0.1 * k, 1), "triangle", {"a": 0.1, "b": 0.4}) for k in range(30)]
    times = switch_done_times(run)
    assert [(d["formation"], d["previous"], d["t_s"]) for d in times] == [
        ("column", "triangle", 10.0), ("triangle", "column", 20.0)]
    assert times[0]["switch_time_s"] == pytest.approx(0.1) and times[0]["done_s"] == pytest.approx(0.6)
    assert times[0]["coordinator_done_s"] == pytest.approx(0.9)
    assert times[1]["switch_time_s"] is None and times[1]["done_s"] is None
    assert times[1]["coordinator_done_s"] is None


class MovingFleet(Fleet):
    """The coordinator node and the metrics collector of test_coordinator_events, with followers
    that drive to their slots at 0.3 m/s (straight, facing the leader's way) and whose poses (the
    same as the coordinator's) also go to the collector as ground truth."""

    def __init__(self, monkeypatch):
        Fleet.__init__(self, monkeypatch)
        self.at = {"robot_1": Pose2D(-1.5, 1.0, 0.0), "robot_2": Pose2D(-1.5, -1.0, 0.0)}

    def look_up(self, now_ros):
        core = self.node.core
        poses = dict(self.at, robot_0=self.leader)
        slots = core.slot_poses(poses)
        for r, p in self.at.items():
            if r in slots:
                dx, dy = slots[r].x - p.x, slots[r].y - p.y
                f = min(1.0, 0.3 * STEP / max(math.hypot(dx, dy), 1e-9))
                self.at[r] = Pose2D(p.x + f * dx, p.y + f * dy, 0.0)
        poses = dict(self.at, robot_0=self.leader)
        for r, p in poses.items():
            self.node.last_heard_pose[r] = self.node.last_heard_controller[r] = self.t
            self.metrics.collector.on_pose(r, self.t, p.x, p.y, p.theta)
        return poses


def test_online_and_offline_give_the_same_switch_times_on_the_same_data(monkeypatch):
    fleet = MovingFleet(monkeypatch)
    n = fleet.node
    assert n._set_goal(Pose2D(20.0, 0.0, 0.0))[0]
    fleet.run(3.0)
    assert n.core.state() == "NAVIGATING"
    t_switch = fleet.t
    assert n._switch("line", 0.0)[0]
    fleet.run(1.0)
    assert n.core.switching                       # the followers drive 1 m sideways at 0.3 m/s
    fleet.run(8.0)
    assert not n.core.switching
    settle = n.core._switch_settle
    online = (settle.reached_at - t_switch, settle.done_at - t_switch)
    assert 2.5 < online[0] < 5.0                   # the time it takes to drive there, not a moment
    assert online[1] == pytest.approx(online[0] + SWITCH_HOLD, abs=STEP + 1e-6)
    switched = [e for e in n.core.events if e[1] == "switched"]
    assert switched[-1][2] == "line reached in %.1f s" % online[0]

    line = [d for d in switch_done_times(fleet.metrics.collector.run) if d["formation"] == "line"]
    assert len(line) == 1 and line[0]["t_s"] == pytest.approx(t_switch)
    assert line[0]["switch_time_s"] == pytest.approx(online[0], abs=1e-6)   # from the samples
    assert line[0]["done_s"] == pytest.approx(online[1], abs=1e-6)
    assert line[0]["coordinator_done_s"] == pytest.approx(online[1], abs=1e-6)   # the recorded event
