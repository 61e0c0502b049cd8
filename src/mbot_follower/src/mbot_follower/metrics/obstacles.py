"""The simulator's static obstacles (a world file's and those spawned at run time), for the
metrics' blocked-slot rule: a slot within `slot_clearance` of one cannot be held, as one beside a
wall of the map cannot. They come from /stage/markers (namespace "obstacles"); moving obstacles
(people) are not walls, the coordinator's pause handles them. Nothing here knows ROS."""
import math
from collections import namedtuple

#: A static obstacle: its centre x, y [m] and yaw theta [rad] in map; a box has length (along
#: its x axis) and width [m], a cylinder a radius [m] (the other shape's sizes are 0).
Obstacle = namedtuple("Obstacle", "name shape x y theta length width radius")

MARKER_NS = "obstacles"     # stage_node's namespace of static obstacles on /stage/markers
CUBE, CYLINDER = 1, 3       # visualization_msgs/Marker types
ADD = 0                     # visualization_msgs/Marker action


def distance(obstacle, x, y):
    """Distance [m] of the point (x, y) from the obstacle's outline; 0 inside it."""
    dx, dy = x - obstacle.x, y - obstacle.y
    if obstacle.shape == "cylinder":
        return max(math.hypot(dx, dy) - obstacle.radius, 0.0)
    c, s = math.cos(obstacle.theta), math.sin(obstacle.theta)
    along, across = c * dx + s * dy, -s * dx + c * dy   # in the box's frame
    return math.hypot(max(abs(along) - 0.5 * obstacle.length, 0.0), max(abs(across) - 0.5 * obstacle.width, 0.0))


def blocks(obstacles, x, y, clearance):
    """True if a robot centred at (x, y) would come within `clearance` [m] of one of the
    obstacles (the walls' rule, free_space.FreeSpace)."""
    return any(distance(o, x, y) <= clearance + 1e-9 for o in obstacles)


def describe(obstacle):
    """The obstacle's shape and size for events.csv, e.g. "box 0.4 x 0.4 m, yaw 0 rad"."""
    if obstacle.shape == "cylinder":
        return "cylinder radius %g m" % obstacle.radius
    return "box %g x %g m, yaw %g rad" % (obstacle.length, obstacle.width, round(obstacle.theta, 4))


def from_markers(markers):
    """The static obstacles among /stage/markers' markers (anything with ns, action, type, text,
    pose and scale): a CUBE is a box, a CYLINDER a cylinder; other namespaces are left out."""
    out = []
    for m in markers:
        if m.ns != MARKER_NS or m.action != ADD or m.type not in (CUBE, CYLINDER):
            continue
        q = m.pose.orientation
        theta = math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))
        if m.type == CUBE:
            out.append(Obstacle(m.text, "box", m.pose.position.x, m.pose.position.y, theta, m.scale.x, m.scale.y, 0.0))
        else:
            out.append(Obstacle(m.text, "cylinder", m.pose.position.x, m.pose.position.y, theta, 0.0, 0.0,
                                0.5 * m.scale.x))
    return out
