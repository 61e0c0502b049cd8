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
    outcomes = [{"succeeded": True, "sim_seconds": 10.0}, {"succeeded": False, "sim_seconds": 150.0},
                {"succeeded": True, "sim_seconds": 31.0}]
    assert nav_trial.summary(outcomes, 3, 123.456, 7.89, robots=3) == {
        "runs": 3, "succeeded": 2, "contacts": 3, "sim_seconds": 123.5, "wall_seconds": 7.9, "robots": 3,
        "mean_goal_s": 20.5}  # the failed run's time does not count
    assert nav_trial.summary([{"succeeded": False, "sim_seconds": 150.0}], 0, 1.0, 1.0)["mean_goal_s"] is None


def test_judge_needs_the_action_the_time_and_the_true_position():
    goal = (2.0, 3.0)
    assert nav_trial.judge(True, 40.0, 150.0, (2.05, 3.05), goal, 0.1) == (True, "")
    # the nav node said SUCCEEDED, but the ground truth is 0.15 m off: its localization was wrong
    ok, why = nav_trial.judge(True, 40.0, 150.0, (2.15, 3.0), goal, 0.1)
    assert not ok and "0.150 m" in why
    assert nav_trial.judge(True, 40.0, 150.0, (2.15, 3.0), goal, 0.2)[0]  # the tolerance given is used
    assert nav_trial.judge(True, 150.0, 150.0, goal, goal, 0.1)[0]  # ends at the timeout: still in time
    assert nav_trial.judge(True, 150.1, 150.0, goal, goal, 0.1) == (False, "timeout")  # ends after it
    assert nav_trial.judge(False, 40.0, 150.0, goal, goal, 0.1) == (False, "not SUCCEEDED")


def test_split_runs():
    assert nav_trial.split_runs(100, 3) == [34, 33, 33]
    assert nav_trial.split_runs(9, 3) == [3, 3, 3]
    assert nav_trial.split_runs(100, 1) == [100]
    assert sum(nav_trial.split_runs(7, 4)) == 7


def test_pick_goal_keeps_away_from_the_other_robots_goals():
    planned = (1.0, 1.0, 0.5)
    spares = iter([(1.5, 1.0, 0.1), (3.0, 1.0, 0.2), (5.0, 5.0, 0.3)])
    assert nav_trial.pick_goal(planned, spares, [(4.0, 4.0)], 1.0) == (planned, False)
    # planned is 0.5 m from a claim: the first spare that is 1 m clear of every claim replaces it
    goal, replaced = nav_trial.pick_goal(planned, spares, [(1.0, 1.5), (3.5, 1.0)], 1.0)
    assert replaced and goal == (5.0, 5.0, 0.3)
    try:
        nav_trial.pick_goal(planned, iter([]), [(1.0, 1.0)], 1.0)
    except ValueError as e:
        assert "1.00 m" in str(e)
    else:
        raise AssertionError("no ValueError when the spares run out")
