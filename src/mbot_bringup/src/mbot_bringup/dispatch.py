"""Central dispatch: which robot drives to which goal, no formation.

Goals arrive in a queue (`DispatchQueue`), at any time, more of them than robots if need be.
Whenever robots are free (a new fleet, a goal reached or failed, new goals), the oldest pending
goals, as many as there are free robots, are given out by one of two policies:

- ``hungarian``: the least total path cost, the Hungarian method
  (`scipy.optimize.linear_sum_assignment`) on a table of costs robot x goal;
- ``round_robin``: the goals in order to the robots in turn, skipping a robot that cannot reach
  the goal (the simple baseline a fleet manager offers for a class of equal tasks).

The costs come from outside: the node asks each robot's own planner (move_base's ``make_plan``:
its costmap, its teammates); `path_length_table` measures through the map instead (8-connected
grid, no corner cutting: `mbot_navigation.grid_paths`), not the straight line: in a warehouse
the robot across a shelf is far away. Taking the oldest goals first means no goal waits for
ever behind nearer ones. A goal whose robot fails (move_base aborts) goes back to the front of the
queue for the other robots. Pure numpy/scipy, no ROS (dispatcher_node.py is the node).
"""
import math

import numpy as np
from scipy.optimize import linear_sum_assignment

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


POLICIES = ("hungarian", "round_robin")
LOOK_AHEAD = 10   # goals beyond one per free robot whose costs are asked for, for those no free robot reaches


def best_pairs(table):
    """[(robot index, goal index)] of the least total cost over a table robots x goals that may
    hold inf (unreachable) and have more goals than robots: as many pairs as can be made
    without an unreachable one."""
    table = np.asarray(table, dtype=float)
    if table.size == 0:
        return []
    finite = table[np.isfinite(table)]
    if not len(finite):
        return []
    big = (finite.sum() + 1.0) * 10.0
    rows, cols = linear_sum_assignment(np.where(np.isfinite(table), table, big))
    return [(int(i), int(j)) for i, j in zip(rows, cols) if np.isfinite(table[i, j])]


class Goal(object):
    """A goal in the queue: id (its order of arrival), pose [m, rad], the robots that failed it."""

    def __init__(self, goal_id, x, y, yaw):
        self.id, self.x, self.y, self.yaw = goal_id, x, y, yaw
        self.failed_by = set()

    def __repr__(self):
        return "goal %d (%.2f, %.2f)" % (self.id, self.x, self.y)


class DispatchQueue(object):
    """The goals waiting, the goal each robot drives to, and who gets what next (see the module).

    Not thread-safe: the node holds one lock around every call."""

    def __init__(self, robots, policy="hungarian"):
        if policy not in POLICIES:
            raise DispatchError("unknown dispatch policy %r: expected one of %s" % (policy, ", ".join(POLICIES)))
        self.robots = list(robots)
        self.policy = policy
        self.pending = []      # Goals in the order they came (a failed one back at the front)
        self.active = {}       # robot -> its Goal
        self.dropped = []      # (Goal, why): every robot failed it
        self._next_id = 0
        self._turn = 0         # round_robin: index of the robot whose turn is next

    def add(self, poses):
        """Queue goals [(x, y, yaw)]; returns their Goals."""
        goals = []
        for (x, y, yaw) in poses:
            goals.append(Goal(self._next_id, float(x), float(y), float(yaw)))
            self._next_id += 1
        self.pending.extend(goals)
        return goals

    def free_robots(self, available):
        """The robots of `available` (those with a known pose) that drive to no goal."""
        return [r for r in self.robots if r in available and r not in self.active]

    def assign(self, free, costs):
        """Give pending goals to the `free` robots; returns [(robot, Goal, cost)] (they are active
        from now on). costs(robots, goals) -> table robots x goals [m], inf where a robot cannot
        reach a goal. The oldest goals first, one per free robot: a goal that none of them can
        reach (or that they failed) waits for the others and does not hold up the goals behind
        it; when every robot is free and none can reach it, it is dropped (see `dropped`)."""
        free = [r for r in free if r not in self.active]
        if not free or not self.pending:
            return []
        # one table for the oldest goals (a planner's cost is per robot: one search serves all goals)
        candidates = self.pending[:len(free) + LOOK_AHEAD]
        full = np.asarray(costs(free, candidates), dtype=float).reshape(len(free), len(candidates))
        window, columns = [], []
        for j, goal in enumerate(candidates):
            if len(window) == len(free):
                break
            column = full[:, j].copy()
            column[[r in goal.failed_by for r in free]] = np.inf
            if np.isfinite(column).any():
                window.append(goal)
                columns.append(column)
            elif not self.active and set(free) | goal.failed_by >= set(self.robots):
                self.pending.remove(goal)
                self.dropped.append((goal, "no robot can reach it"))
        if not window:
            return []
        table = np.column_stack(columns)
        if self.policy == "hungarian":
            pairs = best_pairs(table)
        else:
            pairs, taken = [], set()
            for j in range(len(window)):
                for k in range(len(self.robots)):
                    robot = self.robots[(self._turn + k) % len(self.robots)]
                    if robot in free and robot not in taken and np.isfinite(table[free.index(robot), j]):
                        pairs.append((free.index(robot), j))
                        taken.add(robot)
                        self._turn = (self.robots.index(robot) + 1) % len(self.robots)
                        break
        given = []
        for i, j in sorted(pairs, key=lambda p: p[1]):
            robot, goal = free[i], window[j]
            self.active[robot] = goal
            self.pending.remove(goal)
            given.append((robot, goal, float(table[i, j])))
        return given

    def done(self, robot, succeeded):
        """The robot's goal ended. A failed goal goes back to the front of the queue for the other
        robots, or is dropped (returned with the reason) when every robot has failed it."""
        goal = self.active.pop(robot, None)
        if goal is None or succeeded:
            return None
        goal.failed_by.add(robot)
        if set(self.robots) <= goal.failed_by:
            why = "every robot failed it (%s)" % ", ".join(sorted(goal.failed_by))
            self.dropped.append((goal, why))
            return why
        self.pending.insert(0, goal)
        return None
