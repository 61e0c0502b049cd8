"""Central dispatch: the least total path length, measured through the map, not across walls."""
import itertools

import numpy as np
import pytest

from mbot_bringup.dispatch import DispatchConfig, DispatchError, DispatchQueue, best_pairs, path_length_table
from mbot_follower.free_space import FreeSpace
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
    assert best_pairs(table) == [(1, 0)]      # the robot across the wall is nearer by path


def test_assignment_is_the_least_total_of_all_permutations():
    rng = np.random.RandomState(4)
    for _ in range(30):
        robots = rng.randint(2, 6)
        goals = rng.randint(1, robots + 1)
        table = rng.uniform(0.5, 20.0, size=(robots, goals))
        pairs = best_pairs(table)
        total = sum(table[i, j] for i, j in pairs)
        best = min(sum(table[p[j], j] for j in range(goals)) for p in itertools.permutations(range(robots), goals))
        assert total == pytest.approx(best)
        assert sorted(j for _, j in pairs) == list(range(goals)) and len(set(i for i, _ in pairs)) == goals


def test_an_unreachable_pair_is_never_chosen():
    # a robot that can reach only one goal gets it; the other goes to the robot that can reach both
    assert sorted(best_pairs(np.array([[1.0, np.inf], [5.0, 2.0]]))) == [(0, 0), (1, 1)]
    # a goal nobody reaches gets no robot
    assert sorted(best_pairs(np.array([[1.0, np.inf], [2.0, np.inf]]))) in ([(0, 0)], [(1, 0)])


def test_warehouse_goals_go_to_the_robots_nearest_by_path():
    world = load_world(resolve_world("warehouse"))
    m = world.map_data
    space = FreeSpace(m.occupancy, m.resolution, m.origin[:2], DispatchConfig().robot_radius + DispatchConfig().margin)
    robots = {r.name: (r.pose.x, r.pose.y) for r in world.robots}   # (-1, -8), (-2.5, -8), (0.5, -8)
    names = [r.name for r in world.robots]

    def costs(free, goals):
        return path_length_table(space.free, m.resolution, m.origin[:2], [robots[r] for r in free],
                                 [(g.x, g.y) for g in goals])
    q = DispatchQueue(names)
    q.add([(-2.0, -3.0, 0.0), (1.0, -3.0, 0.0), (-5.0, -3.0, 0.0)])   # aisles at x = -5, -2, 1
    given = {g.id: (r, cost) for r, g, cost in q.assign(names, costs)}
    # west robot to the west aisle, east robot to the east one
    assert {j: r for j, (r, _) in given.items()} == {0: names[0], 1: names[2], 2: names[1]}
    # an open way: the 8-connected grid's length of the straight line (1 m diagonal, 4 m straight)
    assert given[0][1] == pytest.approx(4.0 + np.sqrt(2.0), abs=0.1)


# --- the queue: goals at any time, more than robots, failures ------------------------------------

def line_costs(positions):
    """costs(robots, goals) for robots on a line at `positions` {robot: x}: |x - goal.x|."""
    def costs(robots, goals):
        return np.array([[abs(positions[r] - g.x) for g in goals] for r in robots])
    return costs


def test_the_oldest_goals_go_first_and_the_rest_wait_for_a_free_robot():
    q = DispatchQueue(["a", "b"])
    q.add([(10.0, 0.0, 0.0), (20.0, 0.0, 0.0), (0.5, 0.0, 0.0)])   # the third is the nearest to both
    costs = line_costs({"a": 0.0, "b": 19.0})
    given = q.assign(q.free_robots({"a", "b"}), costs)
    assert sorted((r, g.id) for r, g, _ in given) == [("a", 0), ("b", 1)]   # not goal 2, though nearer
    assert [g.id for g in q.pending] == [2]
    assert q.assign(q.free_robots({"a", "b"}), costs) == []     # nobody free
    assert q.done("b", True) is None
    given = q.assign(q.free_robots({"a", "b"}), costs)
    assert [(r, g.id) for r, g, _ in given] == [("b", 2)] and not q.pending


def test_hungarian_minimises_the_total_and_round_robin_takes_turns():
    costs = line_costs({"a": 0.0, "b": 10.0, "c": 20.0})
    goals = [(19.0, 0.0, 0.0), (1.0, 0.0, 0.0), (11.0, 0.0, 0.0)]
    q = DispatchQueue(["a", "b", "c"], "hungarian")
    q.add(goals)
    assert {r: g.id for r, g, _ in q.assign(["a", "b", "c"], costs)} == {"c": 0, "a": 1, "b": 2}
    q = DispatchQueue(["a", "b", "c"], "round_robin")
    q.add(goals)
    assert {r: g.id for r, g, _ in q.assign(["a", "b", "c"], costs)} == {"a": 0, "b": 1, "c": 2}
    q.done("b", True)
    q.add([(0.0, 0.0, 0.0)])
    # the turn goes on after c: a is busy, so b, although a would be nearer
    assert [(r, g.id) for r, g, _ in q.assign(q.free_robots({"a", "b", "c"}), costs)] == [("b", 3)]


def test_a_failed_goal_goes_back_to_the_front_for_the_others_and_is_dropped_when_all_failed():
    q = DispatchQueue(["a", "b"])
    q.add([(1.0, 0.0, 0.0), (5.0, 0.0, 0.0)])
    costs = line_costs({"a": 0.0, "b": 6.0})
    q.assign(["a", "b"], costs)                       # a: goal 0, b: goal 1
    assert q.done("a", False) is None                 # a failed goal 0
    assert [g.id for g in q.pending] == [0]
    assert q.assign(q.free_robots({"a", "b"}), costs) == []   # only a is free, and it failed it
    q.done("b", True)
    given = q.assign(q.free_robots({"a", "b"}), costs)
    assert [(r, g.id) for r, g, _ in given] == [("b", 0)]    # the other robot takes it
    assert "every robot failed it (a, b)" in q.done("b", False)
    assert not q.pending and q.dropped[0][0].id == 0


def test_a_goal_no_free_robot_reaches_waits_for_one_that_can():
    q = DispatchQueue(["a", "b"])
    q.add([(1.0, 0.0, 0.0)])
    q.assign(["a"], line_costs({"a": 0.0, "b": 0.0}))        # a busy
    q.add([(99.0, 0.0, 0.0), (2.0, 0.0, 0.0)])

    def costs(robots, goals):   # only a reaches x = 99
        return np.array([[np.inf if (g.x > 50 and r == "b") else abs(g.x) for g in goals] for r in robots])
    # b is free but cannot reach goal 1: it takes goal 2, goal 1 waits (a could reach it)
    assert [(r, g.id) for r, g, _ in q.assign(q.free_robots({"a", "b"}), costs)] == [("b", 2)]
    assert [g.id for g in q.pending] == [1] and not q.dropped
    q.done("a", True)
    assert [(r, g.id) for r, g, _ in q.assign(q.free_robots({"a", "b"}), costs)] == [("a", 1)]
    assert not q.pending


def test_best_pairs_with_more_goals_than_robots_and_unreachable_pairs():
    assert sorted(best_pairs(np.array([[1.0, 5.0, np.inf], [np.inf, np.inf, np.inf]]))) == [(0, 0)]
    assert best_pairs(np.full((2, 2), np.inf)) == []
    assert sorted(best_pairs(np.array([[3.0, 1.0, 2.0]]))) == [(0, 1)]


def test_an_unknown_policy_is_refused_by_name():
    with pytest.raises(DispatchError, match="unknown dispatch policy 'nearest'"):
        DispatchQueue(["a"], "nearest")


def test_a_goal_nobody_reaches_does_not_hold_up_the_others_and_is_dropped_when_all_are_free():
    q = DispatchQueue(["a", "b"])

    def costs(robots, goals):
        return np.array([[np.inf if g.x > 50 else abs(g.x) for g in goals] for r in robots])
    q.add([(1.0, 0.0, 0.0)])
    q.assign(["a"], costs)                                   # a busy
    q.add([(99.0, 0.0, 0.0), (2.0, 0.0, 0.0)])
    assert [(r, g.id) for r, g, _ in q.assign(["b"], costs)] == [("b", 2)]   # goal 1 skipped, kept
    assert [g.id for g in q.pending] == [1]
    q.done("a", True)
    q.done("b", True)
    assert q.assign(["a", "b"], costs) == [] and not q.pending
    assert [(g.id, why) for g, why in q.dropped] == [(1, "no robot can reach it")]
