"""The leader's recent path, to follow it when a slot falls into a wall.

In a corridor the slots beside the leader are inside the walls; a follower then drives along
the leader's own track instead, which is free because the leader just drove there: it pursues a
point a little ahead of where it is on the track (`pursuit_point`), at most as far as `distance`
metres of path behind the leader. Points are in the world (map) frame [m]. Pure Python.
"""
import collections
import math


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

    def __len__(self):
        return len(self._points)

    def clear(self):
        self._points.clear()
        self._steps.clear()
        self._length = 0.0

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
        through doors, where the point `distance` behind the newest may lie behind a wall."""
        if not self._points:
            raise ValueError("Trail.pursuit_point: the trail is empty (add() the leader's positions first)")
        for name, value in (("lookahead", lookahead), ("distance", distance)):
            if isinstance(value, bool) or not math.isfinite(value) or value < 0:
                raise ValueError("Trail.pursuit_point: %s must be a finite number >= 0 [m], got %r" % (name, value))
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
