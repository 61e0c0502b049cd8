"""The leader's recent path: to follow it when a slot falls into a wall, and to place the slots
of a formation that drives along the path (a column).

In a corridor the slots beside the leader are inside the walls; a follower then drives along
the leader's own track instead, which is free because the leader just drove there: it pursues a
point a little ahead of where it is on the track (`pursuit_point`), at most as far as `distance`
metres of path behind the leader.

Path slots (`path_slot`): a slot (x, y) of the leader frame with x < 0 is not a rigid point of the
leader's frame but the point -x metres of path behind the leader, y to the left of the path
there, facing the path's direction of travel. A column's followers then drive where the leader
drove, also around corners. Behind the trail's oldest point the path goes on straight, along the
tail heading (the leader's heading when the trail was started): right after `start()` every path
slot is exactly the rigid slot.

The leader's path of an assignment (`LeaderTrail`, one definition for the coordinator, the metrics
collector, the fleet probe and the report): it starts at the leader's pose at the assignment's
time (the newest pose not later than it; without one, the first pose after it), then takes every
later pose of the leader, points at least LEADER_TRAIL_STEP apart, the newest LEADER_TRAIL_LENGTH
metres of it.

Points are in the world (map) frame [m]. Pure Python.
"""
import collections
import math

from mbot_common.geometry import Pose2D, compose

#: The path's direction at a point is that of the chord from HEADING_HALF_WINDOW [m] of path
#: behind it to as much ahead of it: single trail steps (min_step apart) of a noisy pose would
#: turn the direction by degrees.
HEADING_HALF_WINDOW = 0.15
#: [m] the leader's path keeps points this far apart ...
LEADER_TRAIL_STEP = 0.05
#: [m] ... and this much of the newest path (a column of 40 robots at 1.2 m is 47 m long)
LEADER_TRAIL_LENGTH = 50.0


class Trail(object):
    """Path points of the leader, newest last, at most `max_length` [m] of path long."""

    def __init__(self, min_step=0.05, max_length=50.0):
        for name, value in (("min_step", min_step), ("max_length", max_length)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) \
                    or not math.isfinite(value) or value <= 0:
                raise ValueError("Trail: %s must be a finite number > 0 [m], got %r" % (name, value))
        self.min_step = float(min_step)      # closer points are not stored [m]
        self.max_length = float(max_length)  # older path beyond this is dropped [m]
        self._points = collections.deque()   # (x, y), oldest first
        self._steps = collections.deque()    # _steps[k] = distance from point k to point k+1 [m]
        self._length = 0.0                   # sum of _steps [m]
        self.tail_heading = None             # direction of the path behind the oldest point [rad]

    def __len__(self):
        return len(self._points)

    def clear(self):
        self._points.clear()
        self._steps.clear()
        self._length = 0.0
        self.tail_heading = None

    def start(self, x, y, heading):
        """Begin a new trail at the leader's pose (x, y, heading): the path so far is a straight
        line through (x, y) along `heading` (path_slot() then gives the rigid slots)."""
        if not all(isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)
                   for v in (x, y, heading)):
            raise ValueError("Trail.start: x, y and heading must be finite numbers, got (%r, %r, %r)"
                             % (x, y, heading))
        self.clear()
        self.add(x, y)
        self.tail_heading = float(heading)

    def length(self):
        """Arc length from the oldest to the newest point [m]."""
        return self._length

    def add(self, x, y):
        """Record a leader position; ignored if it is closer than min_step to the newest point."""
        if not (math.isfinite(x) and math.isfinite(y)):
            raise ValueError("Trail.add: position must be finite, got (%r, %r)" % (x, y))
        if self._points:
            lx, ly = self._points[-1]
            step = math.hypot(x - lx, y - ly)
            if step < self.min_step:
                return
            self._steps.append(step)
            self._length += step
        self._points.append((float(x), float(y)))
        # Drop the oldest points while the rest is still at least max_length long (1e-9: sums
        # of steps like 0.1 are not exact in floating point).
        while self._steps and self._length - self._steps[0] >= self.max_length - 1e-9:
            self._length -= self._steps.popleft()
            self._points.popleft()
            # the straight path behind the oldest point goes on where the kept path starts
            self.tail_heading = self._oldest_step_heading()

    def _oldest_step_heading(self):
        """Direction of the step from the oldest point to the next [rad]; None below 2 points."""
        if len(self._points) < 2:
            return None
        (x0, y0), (x1, y1) = self._points[0], self._points[1]
        return math.atan2(y1 - y0, x1 - x0)

    def point_behind(self, distance):
        """(x, y) at arc length `distance` [m] behind the newest point, walking back along the
        path; the oldest point if the trail is shorter than that."""
        if not self._points:
            raise ValueError("Trail.point_behind: the trail is empty (add() the leader's positions first)")
        if isinstance(distance, bool) or not math.isfinite(distance) or distance < 0:
            raise ValueError("Trail.point_behind: distance must be a finite number >= 0 [m], got %r"
                             % (distance,))
        left = float(distance)
        k = len(self._points) - 1
        while k > 0:
            step = self._steps[k - 1]
            if left <= step:
                (x0, y0), (x1, y1) = self._points[k - 1], self._points[k]
                f = left / step          # fraction of the way back from point k to point k-1
                return (x1 + f * (x0 - x1), y1 + f * (y0 - y1))
            left -= step
            k -= 1
        return self._points[0]

    def pursuit_point(self, x, y, lookahead, distance):
        """(x, y) to drive to for a robot at (x, y) that follows the path: `lookahead` [m] of path
        beyond the path point nearest to the robot, but no nearer to the newest point than
        `distance` [m] of path. Driving straight to it stays near the path, around corners and
        through doors, where the point `distance` behind the newest may lie behind a wall.
        None when the path is shorter than `distance` (the leader has just set off): every point
        of it lies nearer to the leader than the robot's slot, and driving there would put the
        robot ahead of the ones that belong in front of it (a column that cannot sort itself
        out again)."""
        if not self._points:
            raise ValueError("Trail.pursuit_point: the trail is empty (add() the leader's positions first)")
        for name, value in (("lookahead", lookahead), ("distance", distance)):
            if isinstance(value, bool) or not math.isfinite(value) or value < 0:
                raise ValueError("Trail.pursuit_point: %s must be a finite number >= 0 [m], got %r" % (name, value))
        if self._length < distance:
            return None
        nearest, at = float("inf"), 0.0     # distance to the path, arc length from the oldest point
        arc = 0.0
        for k, step in enumerate(self._steps):
            (x0, y0), (x1, y1) = self._points[k], self._points[k + 1]
            u = min(1.0, max(0.0, ((x - x0) * (x1 - x0) + (y - y0) * (y1 - y0)) / (step * step)))
            d = math.hypot(x0 + u * (x1 - x0) - x, y0 + u * (y1 - y0) - y)
            if d < nearest:
                nearest, at = d, arc + u * step
            arc += step
        target = max(0.0, min(at + lookahead, self._length - distance))
        return self.point_behind(self._length - target)


class LeaderTrail(Trail):
    """The leader's path since an assignment (module docstring): restart() at each assignment,
    then follow() with each later pose of the leader, in time order. Empty until it has a pose:
    path slots are then the rigid ones (slot_pose)."""

    def __init__(self):
        Trail.__init__(self, LEADER_TRAIL_STEP, LEADER_TRAIL_LENGTH)
        self.since = None   # the assignment's time [s]

    def restart(self, since, pose=None):
        """A new assignment made at `since` [s]; `pose` (x, y, theta): the leader's newest pose not
        later than `since`, None if there is none (the path then starts at the next follow())."""
        self.clear()
        self.since = since
        if pose is not None:
            self.start(*pose[:3])

    def follow(self, x, y, theta):
        """The leader's next pose after the assignment."""
        if len(self):
            self.add(x, y)
        else:
            self.start(x, y, theta)


def trail_start(poses, since):
    """Where the leader's path of an assignment made at `since` [s] starts: of `poses`, (t, x, y,
    theta, ...) in time order, the newest not later than `since`, else the first; None if empty."""
    start = None
    for p in poses:
        if p[0] > since + 1e-9:
            return start if start is not None else p
        start = p
    return start


# ------------------------------------------------------------------ path slots

def _pose_arg(function, name, value):
    try:
        values = [float(v) for v in value]
    except (TypeError, ValueError):
        values = []
    if len(values) != 3 or not all(math.isfinite(v) for v in values) \
            or any(isinstance(v, bool) for v in value):
        raise ValueError("%s: %s must be a pose (x, y, theta) of finite numbers, got %r" % (function, name, value))
    return Pose2D(*values)


def _tail_heading(head, trail):
    if trail.tail_heading is not None:
        return trail.tail_heading
    heading = trail._oldest_step_heading()   # never started: the path goes on as its oldest step goes
    return head.theta if heading is None else heading


def _point_behind(head, trail, distance):
    """(x, y) at arc length `distance` >= 0 behind the head: from the head's position to the
    trail's newest point, back along the trail (Trail.point_behind), then straight on along the
    tail heading."""
    if len(trail):
        nx, ny = trail.point_behind(0.0)
        to_newest = math.hypot(nx - head.x, ny - head.y)
        if distance <= to_newest and to_newest > 0.0:
            f = distance / to_newest
            return head.x + f * (nx - head.x), head.y + f * (ny - head.y)
        left = distance - to_newest
        if left <= trail.length():
            return trail.point_behind(left)
        (ox, oy), left = trail.point_behind(trail.length()), left - trail.length()
    else:
        (ox, oy), left = (head.x, head.y), distance
    tail = _tail_heading(head, trail)
    return ox - left * math.cos(tail), oy - left * math.sin(tail)


def path_pose(head, trail, distance):
    """Pose2D of the leader's path at arc length `distance` [m] behind the leader at `head`
    (x, y, theta, its pose now): the point on the path, its heading the path's direction of
    travel there (the chord over +-HEADING_HALF_WINDOW of path)."""
    head = _pose_arg("path_pose", "head", head)
    if not isinstance(trail, Trail):
        raise ValueError("path_pose: trail must be a Trail, got %r" % (trail,))
    if isinstance(distance, bool) or not isinstance(distance, (int, float)) \
            or not math.isfinite(distance) or distance < 0:
        raise ValueError("path_pose: distance must be a finite number >= 0 [m], got %r" % (distance,))
    x, y = _point_behind(head, trail, float(distance))
    ax, ay = _point_behind(head, trail, max(0.0, distance - HEADING_HALF_WINDOW))
    bx, by = _point_behind(head, trail, distance + HEADING_HALF_WINDOW)
    if math.hypot(ax - bx, ay - by) < 1e-9:   # a path that folds back onto itself
        return Pose2D(x, y, _tail_heading(head, trail))
    return Pose2D(x, y, math.atan2(ay - by, ax - bx))


def path_slot(head, trail, offset):
    """Pose2D (map) of the slot `offset` (x, y) [m of the leader frame] of a formation that drives
    along the leader's path: for x < 0 the path's pose -x metres behind the leader at `head`
    (x, y, theta), moved y to the left of the path; for x >= 0 the rigid slot, head (+) offset,
    facing the leader's way."""
    head = _pose_arg("path_slot", "head", head)
    try:
        ox, oy = (float(v) for v in offset)
    except (TypeError, ValueError):
        ox = oy = float("nan")
    if not (math.isfinite(ox) and math.isfinite(oy)):
        raise ValueError("path_slot: offset must be (x, y), two finite numbers [m], got %r" % (offset,))
    if ox >= 0.0:
        return compose(head, Pose2D(ox, oy, 0.0))
    return compose(path_pose(head, trail, -ox), Pose2D(0.0, oy, 0.0))


def slot_pose(head, offset, trail=None):
    """Pose2D (map) of the slot `offset` (x, y) [m] of a leader at `head` (x, y, theta): on the
    leader's path (path_slot) when its `trail` is given, i.e. for a formation along the path;
    without a trail the rigid slot, head (+) offset, facing the leader's way."""
    if trail is not None:
        return path_slot(head, trail, offset)
    head = _pose_arg("slot_pose", "head", head)
    return compose(head, Pose2D(float(offset[0]), float(offset[1]), 0.0))
