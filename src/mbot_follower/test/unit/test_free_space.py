"""Free space on an occupancy grid grown by a clearance."""
import numpy as np
import pytest

from mbot_follower.free_space import FreeSpace


def room():
    """5 m x 4 m at 0.1 m/cell, origin (-1, -2): a wall at x in [1.0, 1.1) for y < 1.0 and one
    unknown cell at (-0.45, 1.55)."""
    grid = np.zeros((40, 50), dtype=np.int8)
    grid[:30, 20] = 100          # column 20 = x in [1.0, 1.1); rows 0..29 = y in [-2, 1)
    grid[35, 5] = -1             # row 35 = y in [1.5, 1.6), column 5 = x in [-0.5, -0.4)
    return grid


def test_clearance_grows_obstacles_by_cell_centre_distance():
    space = FreeSpace(room(), 0.1, (-1.0, -2.0), clearance=0.3)
    assert not space.is_free(1.05, 0.0)          # in the wall
    assert not space.is_free(0.75, 0.0)          # cell centre 0.3 m from the wall's: blocked
    assert space.is_free(0.65, 0.0)              # 0.4 m: free
    assert not space.is_free(1.35, 0.0) and space.is_free(1.45, 0.0)   # the other side
    assert not space.is_free(1.05, 1.25)         # past the wall's end, 0.3 m from its last cell
    assert space.is_free(1.05, 1.35)
    # 7 columns x 30 rows along the wall, 5 + 5 + 1 cells round its end (dx^2 + dy^2 <= 9),
    # the unknown cell
    assert np.count_nonzero(~space.free) == 7 * 30 + 11 + 1


def test_outside_and_unknown_are_not_free():
    space = FreeSpace(room(), 0.1, (-1.0, -2.0), clearance=0.0)
    assert space.is_free(-0.95, -1.95) and space.is_free(3.95, 1.95)   # corner cells
    assert not space.is_free(-1.01, 0.0) and not space.is_free(4.0, 0.0)
    assert not space.is_free(0.0, 2.0) and not space.is_free(float("nan"), 0.0)
    assert not space.is_free(-0.45, 1.55)        # unknown
    assert space.is_free(-0.35, 1.55)            # unknown cells do not grow
    assert space.is_free(0.95, 0.0)              # clearance 0: only the wall itself


def test_segment_free():
    space = FreeSpace(room(), 0.1, (-1.0, -2.0), clearance=0.2)
    assert space.segment_free(0.0, 0.0, 0.0, 1.5)
    assert not space.segment_free(0.0, 0.0, 2.0, 0.0)        # through the wall
    assert space.segment_free(0.0, 1.5, 2.0, 1.5)            # round its end
    assert not space.segment_free(0.0, 1.1, 2.0, 1.1)        # too close to its end
    assert not space.segment_free(0.0, 0.0, 0.0, 5.0)        # leaves the map
    assert space.segment_free(0.55, 0.0, 0.55, 0.0)          # a point


def test_empty_grid_and_bad_input():
    assert FreeSpace(np.zeros((3, 3), dtype=np.int8), 1.0, (0, 0), 5.0).free.all()
    with pytest.raises(ValueError, match="occupancy must be a non-empty 2-D array"):
        FreeSpace(np.zeros(5, dtype=np.int8), 0.1, (0, 0), 0.2)
    with pytest.raises(ValueError, match="occupancy must hold integers"):
        FreeSpace(np.zeros((2, 2)), 0.1, (0, 0), 0.2)
    with pytest.raises(ValueError, match="resolution must be a finite number > 0"):
        FreeSpace(room(), 0.0, (0, 0), 0.2)
    with pytest.raises(ValueError, match="clearance must be a finite number >= 0"):
        FreeSpace(room(), 0.1, (0, 0), -0.1)
    with pytest.raises(ValueError, match="origin_xy must be two finite numbers"):
        FreeSpace(room(), 0.1, (0, 0, 0), 0.2)
