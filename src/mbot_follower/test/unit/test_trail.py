"""The leader's trail: points at least min_step apart, at most max_length long, walked back."""
import math

import pytest

from mbot_follower.trail import Trail


def test_points_closer_than_min_step_are_skipped():
    trail = Trail(min_step=0.1)
    for k in range(11):
        trail.add(0.03 * k, 0.0)                 # 0, 0.03, ... 0.30
    assert len(trail) == 3                       # 0.0, 0.12, 0.24
    assert trail.length() == pytest.approx(0.24)


def test_point_behind_walks_back_along_the_path():
    trail = Trail(min_step=0.05)
    for x in (0.0, 1.0, 2.0):
        trail.add(x, 0.0)
    for y in (1.0, 2.0):                         # then a left turn
        trail.add(2.0, y)
    assert trail.point_behind(0.0) == pytest.approx((2.0, 2.0))
    assert trail.point_behind(0.5) == pytest.approx((2.0, 1.5))
    assert trail.point_behind(2.0) == pytest.approx((2.0, 0.0))     # exactly at the corner
    assert trail.point_behind(2.25) == pytest.approx((1.75, 0.0))   # around the corner
    assert trail.point_behind(10.0) == (0.0, 0.0)                   # shorter: the oldest point


def test_old_path_is_dropped_beyond_max_length():
    trail = Trail(min_step=0.05, max_length=3.0)
    for k in range(101):
        trail.add(0.1 * k, 0.0)                  # 10 m of path
    assert trail.length() == pytest.approx(3.0)
    assert len(trail) == 31
    assert trail.point_behind(5.0) == pytest.approx((7.0, 0.0))
    trail.clear()
    assert len(trail) == 0 and trail.length() == 0.0


def test_errors_are_named():
    with pytest.raises(ValueError, match="the trail is empty"):
        Trail().point_behind(1.0)
    trail = Trail()
    trail.add(0.0, 0.0)
    with pytest.raises(ValueError, match="distance must be a finite number >= 0"):
        trail.point_behind(-1.0)
    with pytest.raises(ValueError, match="min_step must be a finite number > 0"):
        Trail(min_step=0.0)
    with pytest.raises(ValueError, match="max_length must be a finite number > 0"):
        Trail(max_length=float("inf"))
    with pytest.raises(ValueError, match="position must be finite"):
        trail.add(math.nan, 0.0)


def test_pursuit_point_leads_along_the_path_from_where_the_robot_is():
    trail = Trail(min_step=0.05)
    for x in (0.0, 1.0, 2.0, 3.0, 4.0):          # east along y = 0 ...
        trail.add(x, 0.0)
    for y in (1.0, 2.0, 3.0, 4.0):               # ... then north through a "door" at (4, 0)
        trail.add(4.0, y)
    # a robot beside the start follows the path 1 m on, not straight to the point near the leader
    assert trail.pursuit_point(0.5, -0.3, 1.0, 1.0) == pytest.approx((1.5, 0.0))
    # around the corner: 0.5 m before it, 1 m on is 0.5 m up the northern leg
    assert trail.pursuit_point(3.5, 0.1, 1.0, 1.0) == pytest.approx((4.0, 0.5))
    # never nearer the leader than `distance` of path: 1 m behind the newest point (4, 4)
    assert trail.pursuit_point(4.0, 2.8, 1.0, 1.0) == pytest.approx((4.0, 3.0))
    assert trail.pursuit_point(4.0, 3.9, 1.0, 1.0) == pytest.approx((4.0, 3.0))
    # a robot behind the oldest point is led to the path's start first
    assert trail.pursuit_point(-3.0, 0.0, 1.0, 1.0) == pytest.approx((1.0, 0.0))
    with pytest.raises(ValueError, match="lookahead"):
        trail.pursuit_point(0.0, 0.0, float("nan"), 1.0)
    with pytest.raises(ValueError, match="empty"):
        Trail().pursuit_point(0.0, 0.0, 1.0, 1.0)


# --- path slots ------------------------------------------------------------------------------

from mbot_common.geometry import Pose2D, compose, normalize_angle  # noqa: E402
from mbot_follower.trail import HEADING_HALF_WINDOW, path_pose, path_slot  # noqa: E402

COLUMN = [(-1.0, 0.0), (-2.0, 0.0), (-3.0, 0.0)]


def _drive(trail, start, heading, length, step=0.02):
    """Record a straight drive of `length` m from start along heading; returns the end point."""
    x, y = start
    for k in range(1, int(round(length / step)) + 1):
        trail.add(start[0] + k * step * math.cos(heading), start[1] + k * step * math.sin(heading))
        x, y = start[0] + k * step * math.cos(heading), start[1] + k * step * math.sin(heading)
    return x, y


def test_right_after_start_path_slots_are_the_rigid_slots():
    head = Pose2D(1.5, -2.0, 0.7)
    trail = Trail()
    trail.start(head.x, head.y, head.theta)
    for offset in COLUMN + [(-1.5, 0.8), (-2.0, -1.2), (0.0, 1.0)]:
        rigid = compose(head, Pose2D(offset[0], offset[1], 0.0))
        slot = path_slot(head, trail, offset)
        assert slot.x == pytest.approx(rigid.x, abs=1e-9)
        assert slot.y == pytest.approx(rigid.y, abs=1e-9)
        assert normalize_angle(slot.theta - head.theta) == pytest.approx(0.0, abs=1e-9)


def test_on_a_straight_drive_path_slots_are_the_rigid_slots():
    theta = -2.3
    trail = Trail()
    trail.start(0.5, 0.25, theta)
    x, y = _drive(trail, (0.5, 0.25), theta, 1.7)   # shorter than the column: the tail is used too
    head = Pose2D(x + 0.01 * math.cos(theta), y + 0.01 * math.sin(theta), theta)  # between trail points
    for offset in COLUMN + [(-0.5, 0.4), (-2.5, -0.6)]:
        rigid = compose(head, Pose2D(offset[0], offset[1], 0.0))
        slot = path_slot(head, trail, offset)
        assert (slot.x, slot.y) == pytest.approx((rigid.x, rigid.y), abs=1e-9)
        assert normalize_angle(slot.theta - theta) == pytest.approx(0.0, abs=1e-9)


def _l_corner_trail():
    """From the origin facing +x, 1.5 m to (1.5, 0), a left turn, 2 m up to (1.5, 2)."""
    trail = Trail()
    trail.start(0.0, 0.0, 0.0)
    _drive(trail, (0.0, 0.0), 0.0, 1.5)
    _drive(trail, (1.5, 0.0), math.pi / 2, 2.0)
    return trail


def test_around_an_l_corner_slots_lie_on_the_path_at_their_arc_length():
    # Started at the origin facing +x, drove 1.5 m to (1.5, 0), turned left and drove 2 m up to
    # (1.5, 2): the leader faces +y. Arc lengths behind it: the corner at 2.0, the start at 3.5.
    trail = _l_corner_trail()
    head = Pose2D(1.5, 2.0, math.pi / 2)
    expected = {1.0: (1.5, 1.0, math.pi / 2), 2.5: (1.0, 0.0, 0.0), 3.0: (0.5, 0.0, 0.0),
                4.5: (-1.0, 0.0, 0.0)}   # 4.5: 1 m beyond the oldest point, along the tail heading
    for distance, (ex, ey, eth) in expected.items():
        slot = path_slot(head, trail, (-distance, 0.0))
        assert (slot.x, slot.y) == pytest.approx((ex, ey), abs=1e-9)
        assert normalize_angle(slot.theta - eth) == pytest.approx(0.0, abs=1e-9)
    # the rigid slot 2.5 m behind would be at (1.5, -0.5), 0.5 m off the path
    assert compose(head, Pose2D(-2.5, 0.0, 0.0))[:2] == pytest.approx((1.5, -0.5))


def test_at_the_corner_the_heading_is_between_the_two_legs():
    trail = _l_corner_trail()
    corner = path_pose(Pose2D(1.5, 2.0, math.pi / 2), trail, 2.0)
    assert corner[:2] == pytest.approx((1.5, 0.0), abs=1e-9)
    assert corner.theta == pytest.approx(math.pi / 4, abs=1e-9)   # the chord across the corner
    # HEADING_HALF_WINDOW away from the corner the leg's own heading is back
    after = path_pose(Pose2D(1.5, 2.0, math.pi / 2), trail, 2.0 - HEADING_HALF_WINDOW)
    assert after.theta == pytest.approx(math.pi / 2, abs=1e-9)


def test_lateral_offset_is_to_the_left_of_the_path_direction():
    trail = _l_corner_trail()
    head = Pose2D(1.5, 2.0, math.pi / 2)
    left = path_slot(head, trail, (-1.0, 0.5))     # on the +y leg: left is -x
    assert left[:2] == pytest.approx((1.0, 1.0), abs=1e-9)
    right = path_slot(head, trail, (-3.0, -0.5))   # on the +x leg: right is -y
    assert right[:2] == pytest.approx((0.5, -0.5), abs=1e-9)
    assert normalize_angle(right.theta) == pytest.approx(0.0, abs=1e-9)


def test_slots_ahead_of_or_beside_the_leader_stay_rigid():
    trail = _l_corner_trail()
    head = Pose2D(1.5, 2.0, math.pi / 2)
    assert path_slot(head, trail, (0.0, 1.0)) == pytest.approx(compose(head, Pose2D(0.0, 1.0, 0.0)))
    assert path_slot(head, trail, (0.0, 0.0)) == pytest.approx(head)


def test_trimmed_trail_goes_on_along_its_oldest_step():
    trail = Trail(min_step=0.05, max_length=1.0)
    trail.start(0.0, 0.0, 0.0)
    _drive(trail, (0.0, 0.0), math.pi / 2, 3.0)   # the start and its heading (+x) are dropped
    assert trail.tail_heading == pytest.approx(math.pi / 2)
    slot = path_slot(Pose2D(0.0, 3.0, math.pi / 2), trail, (-2.0, 0.0))
    assert slot[:2] == pytest.approx((0.0, 1.0), abs=1e-9)


@pytest.mark.parametrize("args, name", [
    (((0.0, float("nan"), 0.0), (-1.0, 0.0)), "head"),
    (((0.0, 0.0), (-1.0, 0.0)), "head"),
    ((None, (-1.0, 0.0)), "head"),
    (((0.0, 0.0, 0.0), (-1.0,)), "offset"),
    (((0.0, 0.0, 0.0), (-1.0, float("inf"))), "offset"),
    (((0.0, 0.0, 0.0), "ab"), "offset"),
])
def test_path_slot_refuses_bad_input_naming_it(args, name):
    trail = Trail()
    trail.start(0.0, 0.0, 0.0)
    with pytest.raises(ValueError, match="path_slot: %s" % name):
        path_slot(args[0], trail, args[1])


def test_path_pose_refuses_bad_distance_and_trail():
    trail = Trail()
    trail.start(0.0, 0.0, 0.0)
    for bad in (-0.1, float("nan"), True, "1"):
        with pytest.raises(ValueError, match="path_pose: distance"):
            path_pose((0.0, 0.0, 0.0), trail, bad)
    with pytest.raises(ValueError, match="path_pose: trail"):
        path_pose((0.0, 0.0, 0.0), [(0.0, 0.0)], 1.0)
    with pytest.raises(ValueError, match="Trail.start: x, y and heading"):
        trail.start(0.0, 0.0, float("nan"))


def test_a_path_shorter_than_the_slot_distance_has_no_pursuit_point():
    # the leader has just set off: every point of its path is nearer to it than a slot 2 m
    # behind, and pursuing one would take the follower ahead of those in front of it
    trail = Trail(min_step=0.05)
    for x in (0.0, 0.5, 1.0, 1.5):
        trail.add(x, 0.0)
    assert trail.pursuit_point(-1.0, 0.5, 0.6, 2.0) is None
    trail.add(2.0, 0.0)   # 2 m of path now
    assert trail.pursuit_point(-1.0, 0.5, 0.6, 2.0) == pytest.approx((0.0, 0.0))
