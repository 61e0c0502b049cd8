"""Planar geometry: poses, velocities, angles and quaternions (the C++ twin is geometry.h).

A Pose2D (x [m], y [m], theta [rad]) is read as a transform "child in parent": the pose of a
robot in the map is the transform map -> robot. With that reading

    compose(a, b)   a (+) b: b is given in a's frame; the result is b in a's parent frame
    inverse(a)      the parent frame seen from a
    relative(a, b)  b seen from a = inverse(a) (+) b (both given in the same frame)

exactly like tf: T_map_follower = T_map_leader * T_leader_follower.

Angles are wrapped to (-pi, pi]. Plain floats and tuples only: no ROS types, but yaw_of() reads
any object with .x .y .z .w (a geometry_msgs/Quaternion).
"""
import math
from collections import namedtuple

#: A planar pose: x [m], y [m], theta [rad] (counter-clockwise from the x axis).
Pose2D = namedtuple("Pose2D", "x y theta")

#: A planar velocity in the body frame: vx forward [m/s], vy to the left [m/s] (0 for a
#: diff-drive robot), wz counter-clockwise [rad/s] (geometry_msgs/Twist linear.x, linear.y,
#: angular.z).
Twist2D = namedtuple("Twist2D", "vx vy wz")


def normalize_angle(a):
    """The angle a [rad] wrapped to (-pi, pi]. ValueError for inf or NaN (no direction)."""
    if not math.isfinite(a):
        raise ValueError("normalize_angle: expected a finite angle [rad], got %r" % (a,))
    a = math.remainder(a, 2.0 * math.pi)  # in [-pi, pi]
    return a + 2.0 * math.pi if a <= -math.pi else a


def angle_diff(a, b):
    """The smallest signed difference a - b [rad], in (-pi, pi]."""
    return normalize_angle(a - b)


def _quaternion_xyzw(q):
    if all(hasattr(q, name) for name in ("x", "y", "z", "w")):
        return q.x, q.y, q.z, q.w
    try:
        values = tuple(q)
    except TypeError:
        raise ValueError("yaw_of: expected a quaternion (.x .y .z .w or a sequence (x, y, z, w)), got %r" % (q,))
    if len(values) != 4:
        raise ValueError("yaw_of: expected 4 values (x, y, z, w), got %d: %r" % (len(values), q))
    return values


def yaw_of(q):
    """The yaw [rad] (rotation about z, in (-pi, pi]) of a quaternion.

    q: anything with .x .y .z .w (geometry_msgs/Quaternion) or a sequence (x, y, z, w). The
    quaternion need not be unit length (the formula is scale-free); a zero quaternion has no
    orientation and is a ValueError.
    """
    x, y, z, w = _quaternion_xyzw(q)
    if x == 0.0 and y == 0.0 and z == 0.0 and w == 0.0:
        raise ValueError("yaw_of: a zero quaternion (0, 0, 0, 0) has no orientation")
    # Yaw of the ZYX Euler angles; w^2 + x^2 - y^2 - z^2 = 1 - 2 (y^2 + z^2) for a unit quaternion.
    yaw = math.atan2(2.0 * (w * z + x * y), w * w + x * x - y * y - z * z)
    return normalize_angle(yaw)


def quaternion_from_yaw(yaw):
    """The unit quaternion (x, y, z, w) of a rotation by yaw [rad] about z."""
    return (0.0, 0.0, math.sin(0.5 * yaw), math.cos(0.5 * yaw))


def compose(a, b):
    """a (+) b: pose b, given in a's frame, expressed in a's parent frame (Pose2D)."""
    ax, ay, at = a
    bx, by, bt = b
    c, s = math.cos(at), math.sin(at)
    return Pose2D(ax + c * bx - s * by, ay + s * bx + c * by, normalize_angle(at + bt))


def inverse(p):
    """The inverse transform of p: p's parent frame expressed in p's frame (Pose2D)."""
    x, y, t = p
    c, s = math.cos(t), math.sin(t)
    return Pose2D(-c * x - s * y, s * x - c * y, normalize_angle(-t))


def relative(a, b):
    """The pose of b expressed in a's frame (both given in one frame): inverse(a) (+) b."""
    return compose(inverse(a), b)


def transform_point(pose, x, y):
    """The point (x, y) [m], given in pose's frame, expressed in pose's parent frame: (x', y')."""
    px, py, t = pose
    c, s = math.cos(t), math.sin(t)
    return (px + c * x - s * y, py + s * x + c * y)
