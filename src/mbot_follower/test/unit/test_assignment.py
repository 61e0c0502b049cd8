"""Slot assignment: the leader keeps slot 0, the followers travel least in total (= brute force
over the squared distances that assign_slots minimises)."""
import itertools
import math

import numpy as np
import pytest

from mbot_follower.assignment import assign_single_file, assign_slots, total_travel, travel_cost


def brute_force(positions, slots, leader):
    """The least total travel over every permutation of the follower slots, and its assignment."""
    followers = [i for i in range(len(positions)) if i != leader]
    best, best_slot_of = math.inf, None
    for perm in itertools.permutations(range(1, len(slots))):
        slot_of = [0] * len(positions)
        for robot, slot in zip(followers, perm):
            slot_of[robot] = slot
        cost = travel_cost(positions, slots, slot_of)
        if cost < best:
            best, best_slot_of = cost, slot_of
    return best, best_slot_of


@pytest.mark.parametrize("n", range(1, 8))
def test_equals_brute_force_on_random_cases(n):
    rng = np.random.RandomState(100 + n)
    for case in range(20 if n < 7 else 5):
        positions = rng.uniform(-5, 5, size=(n, 2))
        slots = rng.uniform(-5, 5, size=(n, 2))
        leader = int(rng.randint(n))
        slots[0] = positions[leader]            # slot 0 sits on the leader
        slot_of = assign_slots(positions, slots, leader_index=leader)
        assert sorted(slot_of) == list(range(n))
        assert slot_of[leader] == 0
        best, best_slot_of = brute_force(positions, slots, leader)
        assert travel_cost(positions, slots, slot_of) == pytest.approx(best, abs=1e-9)
        assert slot_of == best_slot_of          # random reals: the optimum is unique


def test_crossing_paths_are_untangled():
    # greedy (robot 1 first takes its nearest slot) would send robot 2 the long way round
    positions = [[0, 0], [-1, 0.2], [-1, -0.2]]
    slots = [[0, 0], [-1.0, 1.0], [-1.0, -0.1]]
    assert assign_slots(positions, slots) == [0, 1, 2]
    assert total_travel(positions, slots, [0, 1, 2]) == pytest.approx(0.8 + 0.1)


def test_side_by_side_robots_switching_to_a_column_keep_their_order():
    # a diamond (leader, left, right, rear) switching to a column 1.5 m apart: with plain
    # distances the rear slot ties between the two side robots; the squared cost gives it to the
    # robot at the back, so nobody has to overtake anybody (in a corridor nobody could)
    positions = [[0.0, 0.0], [-1.1, 1.1], [-1.1, -1.1], [-2.2, 0.0]]
    slots = [[0.0, 0.0], [-1.5, 0.0], [-3.0, 0.0], [-4.5, 0.0]]
    slot_of = assign_slots(positions, slots)
    assert slot_of[3] == 3                      # the rear robot takes the rear slot
    assert sorted(slot_of[1:3]) == [1, 2]


def test_the_leader_keeps_slot_0_even_when_a_follower_is_nearer():
    positions = [[5.0, 5.0], [0.1, 0.0], [-1.0, 0.0]]   # robot 1 sits on slot 0, robot 0 leads
    slots = [[0.0, 0.0], [-1.0, 0.0], [-2.0, 0.0]]
    assert assign_slots(positions, slots, leader_index=0) == [0, 1, 2]
    assert assign_slots(positions, slots, leader_index=2)[2] == 0


@pytest.mark.parametrize("positions,slots,leader,says", [
    ([[0, 0], [1, 1]], [[0, 0]], 0, "2 robots but 1 slots"),
    ([[0, 0, 0]], [[0, 0, 0]], 0, "positions: expected an (n, 2) array"),
    ([[0, 0], [1, float("nan")]], [[0, 0], [1, 1]], 0, "positions: every coordinate must be finite"),
    ([[0, 0], [1, 1]], [[0, 0], [1, 1]], 2, "leader_index must be a robot index in [0, 1], got 2"),
    ([[0, 0], [1, 1]], [[0, 0], [1, 1]], True, "leader_index must be a robot index"),
])
def test_bad_input_is_named(positions, slots, leader, says):
    with pytest.raises(ValueError) as e:
        assign_slots(positions, slots, leader_index=leader)
    assert says in str(e.value)


@pytest.mark.parametrize("nudge", [-0.01, 0.0, 0.01])
def test_a_diamond_becomes_a_column_in_order_along_the_leader_heading(nudge):
    """Leader at the origin facing +x, a diamond behind it: two sides mirrored at x = -1 (one
    nudged a centimetre either way), the tail at x = -2. Column slots at x = -1, -2, -3: the
    sides take the two nearer slots, in the order they stand behind the leader, the tail the
    last, so nobody passes anybody."""
    positions = [(0.0, 0.0), (-1.0 + nudge, 1.0), (-1.0, -1.0), (-2.0, 0.0)]
    slots = [(0.0, 0.0), (-1.0, 0.0), (-2.0, 0.0), (-3.0, 0.0)]
    slot_of = assign_single_file(positions, slots, heading=0.0)
    assert slot_of[0] == 0 and slot_of[3] == 3
    assert sorted(slot_of[1:3]) == [1, 2]
    if nudge > 0:     # robot 1 stands nearer behind the leader: it goes first
        assert slot_of[1] == 1
    elif nudge < 0:
        assert slot_of[2] == 1


def test_single_file_follows_the_leader_heading_and_refuses_a_mismatch():
    positions = [(0.0, 0.0), (0.0, -2.0), (0.0, -1.0)]        # leader facing +y, followers below
    slots = [(0.0, 0.0), (0.0, -1.0), (0.0, -2.0)]
    assert assign_single_file(positions, slots, heading=math.pi / 2) == [0, 2, 1]
    with pytest.raises(ValueError, match="assign_single_file"):
        assign_single_file(positions, slots[:2], heading=0.0)
