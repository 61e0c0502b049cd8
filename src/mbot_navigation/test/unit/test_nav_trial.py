"""The pure parts of the navigation trial benchmark (mbot_navigation.nav_trial)."""
import math
import os
import sys

import numpy as np

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(PACKAGE_DIR, "src"))

from mbot_navigation import grid_paths, nav_trial  # noqa: E402
from mbot_navigation.grid_paths import Grid  # noqa: E402


def two_rooms():
    """10 x 5 m, 0.1 m cells; a closed wall at x = 5 (no door): the right room is unreachable."""
    occ = np.zeros((50, 100), dtype=np.int16)
    occ[0, :] = occ[-1, :] = occ[:, 0] = occ[:, -1] = 100
    occ[:, 50] = 100
    return Grid(occ, 0.1, 0.0, 0.0)


def test_goals_are_reachable_clear_and_reproducible():
    grid = two_rooms()
    obstacles = [(2.5, 2.5, 0.5)]
    mask = nav_trial.candidate_cells(grid, (1.0, 1.0), clearance=0.5, obstacles=obstacles)
    clear = grid_paths.clearance(grid)
    rows, cols = np.nonzero(mask)
    assert len(rows) > 100
    assert clear[mask].min() >= 0.5
    xs, ys = zip(*(grid_paths.cell_to_world(grid, r, c) for r, c in zip(rows, cols)))
    assert max(xs) < 5.0  # only the left room
    assert min(math.hypot(x - 2.5, y - 2.5) for x, y in zip(xs, ys)) >= 1.0
    goals = nav_trial.sample_goals(grid, mask, 20, seed=3)
    assert goals == nav_trial.sample_goals(grid, mask, 20, seed=3)
    assert goals != nav_trial.sample_goals(grid, mask, 20, seed=4)
    for x, y, yaw in goals:
        assert mask[grid_paths.world_to_cell(grid, x, y)]
        assert -math.pi <= yaw < math.pi


def test_static_obstacles_of_the_trial_world():
    discs = nav_trial.static_obstacles(nav_trial.default_world())
    assert len(discs) == 1
    x, y, r = discs[0]
    assert (x, y) == (7.5, -7.5)
    assert math.isclose(r, 0.5)  # half the diagonal of 0.8 x 0.6


def test_summary_counts():
    outcomes = [{"succeeded": True, "contacts": 0}, {"succeeded": False, "contacts": 2},
                {"succeeded": True, "contacts": 1}]
    assert nav_trial.summary(outcomes, 123.456, 7.89) == {
        "runs": 3, "succeeded": 2, "contacts": 3, "sim_seconds": 123.5, "wall_seconds": 7.9}
