"""Shape errors: plain slot errors, errors after the best rigid fit, edge and heading errors."""
import math

import numpy as np
import pytest

from mbot_follower.formations import make_formation
from mbot_follower.shape import ShapeErrors, rigid_fit, shape_errors


def rotation(angle):
    c, s = math.cos(angle), math.sin(angle)
    return np.array([[c, -s], [s, c]])


def test_rigid_fit_recovers_rotation_and_translation():
    desired = make_formation("diamond", 6, 1.0).offsets
    r_true, t_true = rotation(0.7), np.array([3.0, -2.0])
    actual = desired @ r_true.T + t_true
    r, t, fitted = rigid_fit(actual, desired)
    np.testing.assert_allclose(r, r_true, atol=1e-12)
    np.testing.assert_allclose(t, t_true, atol=1e-12)
    np.testing.assert_allclose(fitted, actual, atol=1e-12)
    assert np.linalg.det(r) == pytest.approx(1.0)


def test_rigid_fit_never_mirrors():
    desired = np.array([[0.0, 0.0], [-1.0, 1.0], [-1.0, -0.5]])
    mirrored = desired * np.array([1.0, -1.0])     # no rotation makes this
    r, _, fitted = rigid_fit(mirrored, desired)
    assert np.linalg.det(r) == pytest.approx(1.0)
    assert np.max(np.hypot(*(fitted - mirrored).T)) > 0.3


def test_rotated_but_well_formed_formation_has_no_fit_error():
    desired = make_formation("wedge", 5, 1.0).offsets
    # the whole formation turned 30 deg about the leader: slots are missed by up to ~1 m
    actual = desired @ rotation(math.radians(30)).T
    e = shape_errors(actual, desired)
    assert isinstance(e, ShapeErrors)
    assert e.fit_rms < 1e-9 and e.fit_max < 1e-9 and e.edge_max < 1e-9
    far = np.hypot(*desired[1:].T)
    # a point at distance d turned by 30 deg moves 2 d sin(15 deg)
    assert e.max == pytest.approx(2 * np.max(far) * math.sin(math.radians(15)))
    assert e.rms == pytest.approx(math.sqrt(np.mean((2 * far * math.sin(math.radians(15))) ** 2)))
    assert e.heading_max == 0.0


def test_one_follower_off_by_known_amounts():
    desired = make_formation("column", 3, 1.0).offsets     # (0,0), (-1,0), (-2,0)
    actual = desired.copy()
    actual[2] = [-2.0, 0.3]                                # last robot 0.3 m to the left
    e = shape_errors(actual, desired, headings=[0.1, 0.1 + 0.2, 0.1 - 3.0], leader_heading=None)
    assert e.max == pytest.approx(0.3)
    assert e.rms == pytest.approx(math.sqrt(0.3 ** 2 / 2))
    assert e.edge_max == pytest.approx(math.hypot(1.0, 0.3) - 1.0)   # robot 1 <-> robot 2
    assert 0.0 < e.fit_max < 0.3                  # the fit shares the error among the robots
    assert e.heading_max == pytest.approx(3.0)
    # headings wrap: 3.0 rad off one way is 2 pi - 3.0 off the other
    e = shape_errors(actual, desired, headings=[0.0, 0.0, 3.5], leader_heading=0.0)
    assert e.heading_max == pytest.approx(2 * math.pi - 3.5)


def test_heading_errors_against_each_followers_own_slot_heading():
    # a column bent by 90 deg: the leader faces +y, the last follower is still on the +x leg
    actual = np.array([[0.0, 0.0], [0.0, -1.0], [-1.0, -1.0]])
    headings = [math.pi / 2, math.pi / 2 + 0.05, -0.02]
    bent = shape_errors(actual, actual, headings=headings, desired_headings=[math.pi / 2, math.pi / 2, 0.0])
    assert bent.heading_max == pytest.approx(0.05)
    # against the leader's heading the last robot is 90 deg off
    assert shape_errors(actual, actual, headings=headings).heading_max == pytest.approx(math.pi / 2 + 0.02)
    with pytest.raises(ValueError, match="2 desired_headings for 3 robots"):
        shape_errors(actual, actual, headings=headings, desired_headings=[0.0, 0.0])
    with pytest.raises(ValueError, match="not both"):
        shape_errors(actual, actual, headings=headings, leader_heading=0.0, desired_headings=[0.0] * 3)
    with pytest.raises(ValueError, match="desired_headings given without the robots' headings"):
        shape_errors(actual, actual, desired_headings=[0.0] * 3)


def test_leader_only_and_bad_input():
    assert shape_errors([[1.0, 2.0]], [[0.0, 0.0]]) == ShapeErrors(0.0, 0.0, 0.0, 0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="actual has 2 points, desired 3"):
        shape_errors([[0, 0], [1, 0]], [[0, 0], [1, 0], [2, 0]])
    with pytest.raises(ValueError, match="2 headings for 3 robots"):
        shape_errors(np.zeros((3, 2)), np.zeros((3, 2)), headings=[0.0, 0.0])
    with pytest.raises(ValueError, match="every coordinate must be finite"):
        rigid_fit([[0, float("inf")]], [[0, 0]])
