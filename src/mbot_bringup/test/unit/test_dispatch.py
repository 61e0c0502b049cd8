"""Central dispatch: the least total path length, measured through the map, not across walls."""
import itertools

import numpy as np
import pytest

from mbot_bringup.dispatch import DispatchError, assign_goals, dispatch, path_length_table
from mbot_common.paths import resolve_world
from mbot_common.world import load_world

RES = 0.1  # [m/cell]


def room_with_wall():
    """A 4 m x 4 m free grid with a wall along x = 2 m from y = 0 up to y = 3.5 m (a gap at the top)."""
    free = np.ones((40, 40), dtype=bool)
    free[0:35, 20] = False
    return free


def test_path_lengths_go_around_the_wall():
    free = room_with_wall()
    table = path_length_table(free, RES, (0.0, 0.0), robots=[(1.55, 0.55), (3.55, 2.55)], goals=[(2.55, 0.55)])
    # robot 0 is 1 m from the goal in a straight line but must go round the wall's end at y = 3.5 m
    assert table[0, 0] > 6.0
    # robot 1 is 1 m across and 2 m up from it, with nothing between: 1 m diagonal + 1 m straight
    assert table[1, 0] == pytest.approx(1.0 + np.sqrt(2.0), abs=0.1)
    chosen = assign_goals(table)
    assert chosen == {0: 1}      # the robot across the wall is nearer by path


def test_assignment_is_the_least_total_of_all_permutations():
    rng = np.random.RandomState(4)
    for _ in range(30):
        robots = rng.randint(2, 6)
        goals = rng.randint(1, robots + 1)
        table = rng.uniform(0.5, 20.0, size=(robots, goals))
        chosen = assign_goals(table)
        total = sum(table[i, j] for j, i in chosen.items())
        best = min(sum(table[p[j], j] for j in range(goals)) for p in itertools.permutations(range(robots), goals))
        assert total == pytest.approx(best)
        assert sorted(chosen) == list(range(goals)) and len(set(chosen.values())) == goals


def test_unreachable_and_too_many_goals_are_refused():
    with pytest.raises(DispatchError) as error:
        assign_goals(np.ones((2, 3)))
    assert "3 goals for 2 robots" in str(error.value)
    with pytest.raises(DispatchError) as error:
        assign_goals(np.array([[1.0, np.inf], [2.0, np.inf]]))
    assert "goal 1: no robot can reach it" in str(error.value)
    # a robot that can reach only one goal gets it; the other goes to the robot that can reach both
    assert assign_goals(np.array([[1.0, np.inf], [5.0, 2.0]])) == {0: 0, 1: 1}


def test_warehouse_goals_go_to_the_robots_nearest_by_path():
    world = load_world(resolve_world("warehouse"))
    robots = [(r.pose.x, r.pose.y) for r in world.robots]      # (-1, -8), (-2.5, -8), (0.5, -8)
    goals = [(-2.0, -3.0), (1.0, -3.0), (-5.0, -3.0)]          # aisles at x = -5, -2, 1
    chosen, table = dispatch(world.map_data, world.map_data.occupancy, robots, goals)
    assert chosen == {0: 0, 1: 2, 2: 1}     # west robot to the west aisle, east robot to the east one
    # an open way: the 8-connected grid's length of the straight line (1 m diagonal, 4 m straight)
    assert table[0, 0] == pytest.approx(4.0 + np.sqrt(2.0), abs=0.1)
