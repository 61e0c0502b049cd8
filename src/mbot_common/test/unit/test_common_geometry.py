"""mbot_common.geometry: angle wrapping, quaternions and SE(2) pose algebra, checked against
hand-computed poses and against each other (compose / inverse / relative round trips)."""
import math
from collections import namedtuple

import pytest

from mbot_common.geometry import (Pose2D, Twist2D, angle_diff, compose, inverse, normalize_angle,
                                  quaternion_from_yaw, relative, transform_point, yaw_of)

Quaternion = namedtuple("Quaternion", "x y z w")  # stands in for geometry_msgs/Quaternion


def close(a, b, tol=1e-12):
    return all(abs(x - y) <= tol for x, y in zip(a, b))


def test_fields_have_the_agreed_names():
    assert Pose2D._fields == ("x", "y", "theta")
    assert Twist2D._fields == ("vx", "vy", "wz")


@pytest.mark.parametrize("angle, wrapped", [
    (0.0, 0.0), (math.pi, math.pi), (-math.pi, math.pi), (3 * math.pi, math.pi),
    (2 * math.pi, 0.0), (-0.5, -0.5), (7.0, 7.0 - 2 * math.pi), (-7.0, -7.0 + 2 * math.pi),
    (1e6, 1e6 - 2 * math.pi * round(1e6 / (2 * math.pi))),
])
def test_normalize_angle_wraps_to_minus_pi_exclusive_pi_inclusive(angle, wrapped):
    result = normalize_angle(angle)
    assert -math.pi < result <= math.pi
    assert result == pytest.approx(wrapped, abs=1e-9)


def test_normalize_angle_refuses_infinite_and_nan():
    for bad in (float("inf"), float("-inf"), float("nan")):
        with pytest.raises(ValueError, match="finite angle"):
            normalize_angle(bad)


def test_angle_diff_is_the_short_way_round():
    assert angle_diff(math.radians(170), math.radians(-170)) == pytest.approx(math.radians(-20))
    assert angle_diff(0.1, 0.3) == pytest.approx(-0.2)


@pytest.mark.parametrize("yaw", [0.0, 0.3, -1.2, 3.0, -3.0, math.pi])
def test_yaw_of_inverts_quaternion_from_yaw_for_objects_and_sequences(yaw):
    q = quaternion_from_yaw(yaw)
    assert math.hypot(*q) == pytest.approx(1.0)
    assert yaw_of(q) == pytest.approx(normalize_angle(yaw), abs=1e-12)
    assert yaw_of(Quaternion(*q)) == pytest.approx(normalize_angle(yaw), abs=1e-12)
    assert yaw_of(list(q)) == pytest.approx(normalize_angle(yaw), abs=1e-12)


def test_yaw_of_ignores_the_length_and_reads_roll_free_yaw():
    x, y, z, w = quaternion_from_yaw(0.7)
    assert yaw_of((2 * x, 2 * y, 2 * z, 2 * w)) == pytest.approx(0.7)
    # roll of pi about x, then yaw 0.5: q = q_yaw * q_roll; its ZYX yaw is still 0.5
    cz, sz = math.cos(0.25), math.sin(0.25)
    q_roll = (1.0, 0.0, 0.0, 0.0)  # (x, y, z, w) of a half turn about x
    q = (cz * q_roll[0] - sz * q_roll[1], sz * q_roll[0] + cz * q_roll[1],
         cz * q_roll[2] + sz * q_roll[3], cz * q_roll[3] - sz * q_roll[2])
    assert yaw_of(q) == pytest.approx(0.5)


def test_yaw_of_refuses_what_is_not_a_quaternion():
    with pytest.raises(ValueError, match="zero quaternion"):
        yaw_of((0.0, 0.0, 0.0, 0.0))
    with pytest.raises(ValueError, match="expected 4 values"):
        yaw_of((0.0, 0.0, 1.0))
    with pytest.raises(ValueError, match="expected a quaternion"):
        yaw_of(1.0)


def test_compose_by_hand():
    # a robot at (1, 2) facing +y; a point 1 m ahead and 0.5 m to its left is at (0.5, 3)
    a = Pose2D(1.0, 2.0, math.pi / 2)
    b = Pose2D(1.0, 0.5, math.pi / 2)
    assert close(compose(a, b), (0.5, 3.0, math.pi))
    assert close(transform_point(a, 1.0, 0.5), (0.5, 3.0))


def test_inverse_and_relative_round_trip():
    a = Pose2D(2.0, -1.0, 2.5)
    b = Pose2D(-0.3, 4.0, -2.9)
    assert close(compose(a, inverse(a)), (0.0, 0.0, 0.0))
    assert close(compose(inverse(a), a), (0.0, 0.0, 0.0))
    rel = relative(a, b)
    assert close(compose(a, rel), b)
    # relative by hand: b's offset rotated into a's frame
    dx, dy = b.x - a.x, b.y - a.y
    c, s = math.cos(a.theta), math.sin(a.theta)
    assert close(rel, (c * dx + s * dy, -s * dx + c * dy, normalize_angle(b.theta - a.theta)))


def test_follower_slot_behind_the_leader():
    # a slot 1 m behind and 1 m to the right of a leader at (3, 3) facing -x is at (4, 4)
    leader = Pose2D(3.0, 3.0, math.pi)
    slot = compose(leader, Pose2D(-1.0, -1.0, 0.0))
    assert close(slot, (4.0, 4.0, math.pi))
    assert isinstance(slot, Pose2D)
