"""mbot_navigation.grid_paths: the optimum the navigation tests compare against."""
import math
import os
import sys

import numpy as np

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(PACKAGE_DIR, "src"))

from mbot_navigation import grid_paths  # noqa: E402
from mbot_navigation.grid_paths import Grid  # noqa: E402


def room(door=True):
    """10 x 10 m, 0.1 m cells, origin (0, 0), walls around and at x = 5 with a 1 m door at y in [4.5, 5.5)."""
    occ = np.zeros((100, 100), dtype=np.int16)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = 100
    occ[:, 50] = 100
    if door:
        occ[45:55, 50] = 0
    return Grid(occ, 0.1, 0.0, 0.0)


def test_clearance_is_the_distance_to_the_nearest_wall():
    c = grid_paths.clearance(room())
    assert c[20, 20] == np.float64(2.0)      # 20 cells from the bottom and left walls
    assert c[20, 49] == np.float64(0.1)      # next to the middle wall
    assert c[50, 50] == np.float64(0.5)      # in the door: 5 cells to the jambs at rows 44 and 55


def test_straight_and_diagonal_lengths():
    grid = room()
    free = grid_paths.clearance(grid) >= 0.15
    lengths = grid_paths.path_lengths_from(free, grid.resolution, (20, 20))
    assert math.isclose(lengths[20, 40], 2.0)
    assert math.isclose(lengths[40, 40], 20 * math.sqrt(2) * 0.1)
    # Through the door: (2.05, 2.05) -> (8.05, 2.05) goes up to the door (its lower jamb's cell
    # centre is at y = 4.45, so the centre passes above y = 4.6) and back down: at least two
    # straight legs to (5, 4.6), at most those plus the 8-connected grid's 8 % detour.
    through = grid_paths.shortest_path_length(grid, 0.15, (2.05, 2.05), (8.05, 2.05))
    legs = 2 * math.hypot(2.95, 4.6 - 2.05)
    assert legs < through < legs * 1.09


def test_unreachable_and_no_corner_cutting():
    grid = room(door=False)
    assert grid_paths.shortest_path_length(grid, 0.15, (2.05, 2.05), (8.05, 2.05)) == float("inf")
    # Two cells touching only at a corner are not connected.
    free = np.zeros((3, 3), dtype=bool)
    free[0, 0] = free[1, 1] = True
    lengths = grid_paths.path_lengths_from(free, 1.0, (0, 0))
    assert lengths[1, 1] == float("inf")


def test_world_cell_round_trip_and_polyline():
    grid = room()
    assert grid_paths.world_to_cell(grid, 2.05, 3.95) == (39, 20)
    assert grid_paths.world_to_cell(grid, -0.01, 1.0) is None
    x, y = grid_paths.cell_to_world(grid, 39, 20)
    assert math.isclose(x, 2.05) and math.isclose(y, 3.95)
    assert math.isclose(grid_paths.polyline_length([(0, 0), (3, 4), (3, 5)]), 6.0)
    assert grid_paths.polyline_length([(1, 1)]) == 0.0
