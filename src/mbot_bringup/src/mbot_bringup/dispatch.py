"""Central dispatch: which robot drives to which goal, no formation.

Given the robots' positions and a list of goals (at most one per robot), every goal gets one
robot so that the total path length is smallest: the Hungarian method
(`scipy.optimize.linear_sum_assignment`) on a table of path lengths. A path length is the
shortest way through the map for a robot of `robot_radius` (8-connected grid, no corner
cutting: `mbot_navigation.grid_paths`), not the straight line: in a warehouse the robot across
a shelf is far away. Robots without a goal stay where they are. Pure numpy/scipy, no ROS
(dispatcher_node.py is the node).
"""
import math

import numpy as np
from scipy.optimize import linear_sum_assignment

from mbot_follower.free_space import FreeSpace
from mbot_navigation.grid_paths import path_lengths_from


class DispatchConfig(object):
    """How path lengths are measured."""

    def __init__(self, robot_radius=0.15, margin=0.05):
        self.robot_radius = robot_radius  # [m] the robot's centre keeps this far from walls
        self.margin = margin              # [m] more clearance, as the costmap's padding does


class DispatchError(ValueError):
    """Goals that cannot be dispatched; the message says which and why."""


def path_length_table(free, resolution, origin_xy, robots, goals):
    """lengths[i, j] [m]: shortest path of robot i to goal j through the `free` cells (a boolean
    grid [row, column], row 0 at origin_xy's y); inf where there is none.

    robots, goals: lists of (x, y) [m]. A robot or goal off the free cells is snapped to the
    nearest free cell (a robot touching a wall's margin can still drive away)."""
    free = np.asarray(free, dtype=bool)
    if not free.any():
        raise DispatchError("the map has no free cell")
    free_cells = np.argwhere(free)

    def cell_of(x, y):
        rc = (int(math.floor((y - origin_xy[1]) / resolution)), int(math.floor((x - origin_xy[0]) / resolution)))
        if 0 <= rc[0] < free.shape[0] and 0 <= rc[1] < free.shape[1] and free[rc]:
            return rc
        nearest = free_cells[np.argmin(np.sum((free_cells - np.array(rc)) ** 2, axis=1))]
        return int(nearest[0]), int(nearest[1])

    goal_cells = [cell_of(x, y) for (x, y) in goals]
    table = np.full((len(robots), len(goals)), np.inf)
    for i, (x, y) in enumerate(robots):
        lengths = path_lengths_from(free, resolution, cell_of(x, y))
        table[i] = [lengths[c] for c in goal_cells]
    return table


def assign_goals(table):
    """{goal index: robot index} with the least total path length over the table
    (path_length_table: robots x goals). DispatchError when there are more goals than robots or
    a goal no robot can reach."""
    table = np.asarray(table, dtype=float)
    robots, goals = table.shape
    if goals > robots:
        raise DispatchError("%d goals for %d robots: at most one goal per robot" % (goals, robots))
    for j in range(goals):
        if not np.isfinite(table[:, j]).any():
            raise DispatchError("goal %d: no robot can reach it (in a wall, or cut off)" % j)
    # an unreachable pair must never be chosen while a reachable one exists: make it dearer than all
    finite = table[np.isfinite(table)]
    big = (finite.sum() + 1.0) * 10.0 if len(finite) else 1.0
    cost = np.where(np.isfinite(table), table, big)
    rows, cols = linear_sum_assignment(cost)
    assignment = {int(j): int(i) for i, j in zip(rows, cols)}
    for j, i in assignment.items():
        if not np.isfinite(table[i, j]):
            raise DispatchError("goal %d: no robot left that can reach it" % j)
    return assignment


def dispatch(world_map, occupancy, robots, goals, config=None):
    """{goal index: robot index} for robots [(x, y)] and goals [(x, y)] [m] on a map
    (mbot_common.maps.MapData for its resolution and origin; `occupancy` its grid, possibly with
    obstacles added), and the path length table."""
    config = config or DispatchConfig()
    space = FreeSpace(occupancy, world_map.resolution, world_map.origin[:2], config.robot_radius + config.margin)
    table = path_length_table(space.free, world_map.resolution, world_map.origin[:2], robots, goals)
    return assign_goals(table), table
