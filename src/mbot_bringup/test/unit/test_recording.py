"""Recording computes rates in sim time, distances and the JSON the report reads."""
import json
import math

import pytest

from mbot_bringup.recording import Recording


def test_rates_and_distance():
    rec = Recording(world="empty", sample_period=0.1)
    for k in range(101):            # 50 Hz ground truth for 2 s along x at 0.5 m/s
        t = k * 0.02
        rec.add_pose("robot_0", t, 0.5 * t, 0.0, 0.0)
    for k in range(21):             # 10 Hz scans
        rec.add_scan("robot_0", k * 0.1, [float("inf"), 2.0, float("nan"), 1.25])
    tr = rec.robots["robot_0"]
    assert tr.rate("ground_truth") == pytest.approx(50.0)
    assert tr.rate("scan") == pytest.approx(10.0)
    assert tr.rate("odom") == 0.0
    assert len(tr.t) == 21          # sampled at 10 Hz
    assert tr.distance() == pytest.approx(1.0)
    assert tr.min_range == 1.25
    assert rec.sim_seconds() == pytest.approx(2.0)


def test_json_round_trip(tmp_path):
    rec = Recording(world="office")
    rec.add_pose("a", 0.0, 1.0, 2.0, 0.5)
    rec.add_contact(1.5, "a", "map", 1.0, 2.1)
    path = tmp_path / "rec.json"
    rec.save(str(path))
    data = json.loads(path.read_text())
    assert data["robots"]["a"]["x"] == [1.0]
    assert data["robots"]["a"]["min_range"] is None
    assert data["contacts"][0]["b"] == "map"
    lines = rec.summary_lines()
    assert lines[-2] == "contacts: 1"
    assert "a <-> map" in lines[-1]
    assert math.isinf(rec.robots["a"].min_range)
