"""Wander: drive forward and turn away from obstacles seen by the laser.

The simplest reactive behaviour, used by the simulator demo to keep robots moving without
navigation. Pure functions on plain lists, so it is testable without ROS.
"""
import math

from mbot_common.geometry import normalize_angle


class WanderConfig(object):
    """Parameters of the wander behaviour."""

    def __init__(self, speed=0.3, turn_rate=1.0, safe_distance=0.6, cone=math.radians(40)):
        self.speed = speed                  # forward speed when the way is clear [m/s]
        self.turn_rate = turn_rate          # turn rate when blocked [rad/s]
        self.safe_distance = safe_distance  # closer than this ahead means blocked [m]
        self.cone = cone                    # half-width of the cone that counts as ahead [rad]


def _finite(r):
    return not (math.isnan(r) or math.isinf(r))


def side_clearance(ranges, angle_min, angle_increment, lo, hi, far=1e9):
    """Smallest finite range among beams whose angle is in [lo, hi] [rad]; +Inf beams count as far."""
    best = far
    for i, r in enumerate(ranges):
        a = normalize_angle(angle_min + i * angle_increment)
        if lo <= a <= hi:
            if r == float("-inf"):   # REP-117: too close to measure
                return 0.0
            if _finite(r):
                best = min(best, r)
    return best


def wander_command(ranges, angle_min, angle_increment, config=None):
    """Return (linear [m/s], angular [rad/s]) for one laser scan.

    Clear ahead: drive straight at `speed`. Blocked ahead: stop and turn towards the side with
    more room, so that a robot never pushes into a wall.
    """
    config = config or WanderConfig()
    ahead = side_clearance(ranges, angle_min, angle_increment, -config.cone, config.cone)
    if ahead > config.safe_distance:
        # Steer gently away from the nearer side while driving.
        left = side_clearance(ranges, angle_min, angle_increment, config.cone, math.pi / 2)
        right = side_clearance(ranges, angle_min, angle_increment, -math.pi / 2, -config.cone)
        bias = 0.0
        if min(left, right) < 2 * config.safe_distance:
            bias = 0.5 * config.turn_rate * (1.0 if left > right else -1.0)
        return config.speed, bias
    left = side_clearance(ranges, angle_min, angle_increment, 0.0, math.pi)
    right = side_clearance(ranges, angle_min, angle_increment, -math.pi, 0.0)
    return 0.0, config.turn_rate if left >= right else -config.turn_rate
