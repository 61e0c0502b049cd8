"""Merging into a column in slot order.

When a formation switches to a column, followers that stood side by side (a diamond's two sides,
its two rear corners) all head for the leader's path at once. Two of them meet on it, each in the
other's way: their safety layers hold both, and neither can back away (the other is at its
shoulder). So a follower joins the path only behind the robot whose slot is next ahead of its own
(the leader for the first follower). While that robot is level with it or behind it, the
follower keeps to a lane beside the path, `lane` metres to the side it is on, and drives along
that lane to its slot's place on the path. Once the robot ahead is ahead of it, the follower
slides in behind it, keeping `gap` metres from it (a circle round it, taken to be on the path):
the nearer it comes to `gap` behind it, the closer to the path it drives, and from `gap` behind
on it drives to its slot. (Waiting in the lane until the robot ahead was `gap` ahead, and only
then crossing to the path, left the last follower a sideways step at its slot: 0.5 s of a
5-robot switch.) Followers already near the path (less than lane / 2 off it) are left alone: a
column that stands is never pulled apart.

Everything is in the frame of the follower's path slot: x along the path (the way the column
drives), y to its left, the slot at (0, 0). Pure Python, no ROS.
"""
import math


def robot_ahead(slots, robot):
    """The robot whose slot is next ahead of `robot`'s in a column: of the slots {robot: (x, y)}
    of the leader frame, the one with the smallest x greater than `robot`'s (the leader's slot
    (0, 0) included). None for the leader, or when nobody's slot is ahead."""
    mine = slots[robot][0]
    ahead = [(x, r) for r, (x, _) in slots.items() if r != robot and x > mine + 1e-6]
    return min(ahead)[1] if ahead else None


def merge_target(me, ahead, lane, gap):
    """(target (x, y) in the slot's frame, True while keeping out of the path).

    :param me: (x, y) of the follower in its slot's frame
    :param ahead: (x, y) of the robot next ahead (robot_ahead) in that frame, None if unknown
    :param lane: how far beside the path a follower waits [m]
    :param gap: how far from the robot ahead it keeps while it slides in behind it [m]
    """
    x, y = me
    behind = ahead[0] - x if ahead is not None else None   # how far that robot is ahead of this one
    if behind is None or abs(y) < lane / 2.0 or behind >= gap:
        return (0.0, 0.0), False
    side = 1.0 if y > 0 else -1.0
    if behind <= 0.0:   # level with it, or it is still behind: wait in the lane (or further out)
        return (0.0, side * max(abs(y), lane)), True
    return (0.0, side * min(lane, math.sqrt(gap * gap - behind * behind))), True
