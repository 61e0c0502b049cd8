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
