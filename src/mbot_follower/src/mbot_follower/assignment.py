"""Which robot takes which slot: the least total travel, the leader always in slot 0.

When a formation is formed or switched, every follower may take any follower slot. Giving each
robot the slot nearest to it one by one can send two robots across each other; the optimal
assignment (the Hungarian method, `scipy.optimize.linear_sum_assignment`) minimises the total
travel instead. Travel is counted as the sum of SQUARED straight-line distances: with plain
distances, robots side by side that switch to a column tie (either may take the rear slot), and
the wrong choice makes a robot overtake another, which in a corridor it cannot. Squared
distances break the tie the right way, and their optimum never has two straight paths crossing
(the CAPT result of Turpin, Michael and Kumar). The leader does not move to a slot: slot 0 is
wherever it is. A single file (a column) is assigned in order along the leader's heading
instead (assign_single_file): robots mirrored about the leader's axis, as a diamond's two sides,
tie even in squared distances, and the wrong choice sends one behind the other it must pass.
Pure numpy/scipy, no ROS.
"""
import math

import numpy as np
from scipy.optimize import linear_sum_assignment


def _as_points(name, value):
    points = np.asarray(value, dtype=float)
    if points.ndim != 2 or points.shape[1] != 2:
        raise ValueError("%s: expected an (n, 2) array of [x, y], got shape %s"
                         % (name, points.shape))
    if not np.all(np.isfinite(points)):
        raise ValueError("%s: every coordinate must be finite, got %s" % (name, points.tolist()))
    return points


def assign_slots(positions, slot_positions, leader_index=0):
    """Return `slot_of`, a list where slot_of[i] is the slot index of robot i.

    positions: (n, 2) world positions of the robots [m]; slot_positions: (n, 2) world positions
    of the slots [m], slot 0 = the leader's slot. Robot `leader_index` gets slot 0; the other
    robots get slots 1..n-1 so that the sum of squared distances robot -> slot is smallest
    (travel_cost()).
    """
    robots = _as_points("positions", positions)
    slots = _as_points("slot_positions", slot_positions)
    n = len(robots)
    if len(slots) != n:
        raise ValueError("assign_slots: %d robots but %d slots (one slot per robot)"
                         % (n, len(slots)))
    if n == 0:
        raise ValueError("assign_slots: no robots")
    if isinstance(leader_index, bool) or not isinstance(leader_index, (int, np.integer)) \
            or not 0 <= leader_index < n:
        raise ValueError("assign_slots: leader_index must be a robot index in [0, %d], got %r"
                         % (n - 1, leader_index))

    slot_of = [0] * n
    followers = [i for i in range(n) if i != leader_index]
    if followers:
        # cost[a, b]: squared distance of follower a to follower slot b + 1
        diff = robots[followers][:, None, :] - slots[1:][None, :, :]
        cost = diff[:, :, 0] ** 2 + diff[:, :, 1] ** 2
        rows, cols = linear_sum_assignment(cost)
        for a, b in zip(rows, cols):
            slot_of[followers[a]] = int(b) + 1
    return slot_of


def assign_single_file(positions, slot_positions, heading, leader_index=0):
    """slot_of (as assign_slots) for a single file (a column): the follower nearest behind the
    leader gets the slot nearest behind it, and so on, measured along the leader's heading
    [rad]. Nobody has to pass anybody, which in a corridor nobody could; least squared travel
    may ask for it when two robots are nearly as far from both slots (a diamond's two sides)."""
    robots = _as_points("positions", positions)
    slots = _as_points("slot_positions", slot_positions)
    if len(slots) != len(robots) or not 0 <= leader_index < len(robots):
        raise ValueError("assign_single_file: %d robots, %d slots, leader_index %r"
                         % (len(robots), len(slots), leader_index))
    back = np.array([-math.cos(heading), -math.sin(heading)])
    origin = robots[leader_index]
    followers = sorted((i for i in range(len(robots)) if i != leader_index),
                       key=lambda i: float(np.dot(robots[i] - origin, back)))
    file_slots = sorted(range(1, len(slots)), key=lambda k: float(np.dot(slots[k] - slots[0], back)))
    slot_of = [0] * len(robots)
    for i, k in zip(followers, file_slots):
        slot_of[i] = k
    return slot_of


def total_travel(positions, slot_positions, slot_of):
    """Sum of the distances [m] from each robot to its slot (the leader's term is its distance to
    slot 0, which is 0 when slot 0 is placed on the leader)."""
    robots = _as_points("positions", positions)
    slots = _as_points("slot_positions", slot_positions)
    return float(sum(np.hypot(*(slots[s] - robots[i])) for i, s in enumerate(slot_of)))


def travel_cost(positions, slot_positions, slot_of):
    """What assign_slots() minimises: the sum of squared distances [m^2] robot -> slot."""
    robots = _as_points("positions", positions)
    slots = _as_points("slot_positions", slot_positions)
    return float(sum(np.sum((slots[s] - robots[i]) ** 2) for i, s in enumerate(slot_of)))
