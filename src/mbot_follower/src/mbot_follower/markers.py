"""/fleet/markers for rviz: each slot (a disc where a follower belongs), a line from the leader
to each follower, a label with each robot's role and slot error, the fleet state above the
leader, and a red cylinder in front of the leader while the fleet is paused; and the centre of
the fleet, where the `fleet` frame is that rviz's view can follow."""
import math

from mbot_common.geometry import Pose2D, compose

SLOT_COLOR = (0.1, 0.6, 1.0, 0.5)
LINK_COLOR = (0.2, 0.8, 0.2, 0.9)
TEXT_COLOR = (1.0, 1.0, 1.0, 1.0)
PAUSE_COLOR = (1.0, 0.1, 0.1, 0.8)


def _marker(ns, mid, kind, stamp, color):
    from visualization_msgs.msg import Marker

    m = Marker()
    m.header.frame_id = "map"
    m.header.stamp = stamp
    m.ns, m.id, m.type, m.action = ns, mid, kind, Marker.ADD
    m.pose.orientation.w = 1.0
    m.color.r, m.color.g, m.color.b, m.color.a = color
    return m


def fleet_markers(core, poses, stamp):
    """A MarkerArray for the coordinator `core` (FleetCoordinator) and the robots' `poses`."""
    from geometry_msgs.msg import Point
    from visualization_msgs.msg import Marker, MarkerArray

    array = MarkerArray()
    clear = Marker()
    clear.action = Marker.DELETEALL
    array.markers.append(clear)
    a = core.assignment
    leader = poses.get(core.leader)
    if a is None or leader is None:
        return array
    errors = core.slot_errors(poses)
    slots = core.slot_poses(poses)   # on the leader's path for a column
    links = _marker("links", 0, Marker.LINE_LIST, stamp, LINK_COLOR)
    links.scale.x = 0.04
    for i, robot in enumerate(sorted(a.slots)):
        slot = slots[robot]
        if robot != a.leader:
            disc = _marker("slots", i, Marker.CYLINDER, stamp, SLOT_COLOR)
            disc.pose.position.x, disc.pose.position.y = slot.x, slot.y
            disc.scale.x = disc.scale.y = 0.3
            disc.scale.z = 0.02
            array.markers.append(disc)
        pose = poses.get(robot)
        if pose is None:
            continue
        if robot != a.leader:
            links.points += [Point(leader.x, leader.y, 0.05), Point(pose.x, pose.y, 0.05)]
        # below the robot: the simulator's markers write its name above it
        label = _marker("labels", i, Marker.TEXT_VIEW_FACING, stamp, TEXT_COLOR)
        label.pose.position.x, label.pose.position.y, label.pose.position.z = pose.x, pose.y - 0.35, 0.3
        label.scale.z = 0.18
        if robot == a.leader:
            label.text = "leader"
        else:
            dist, heading = errors.get(robot, (float("nan"), float("nan")))
            label.text = "%.0f cm %.0f deg" % (dist * 100.0, math.degrees(heading))
        array.markers.append(label)
    array.markers.append(links)
    state = _marker("state", 0, Marker.TEXT_VIEW_FACING, stamp, PAUSE_COLOR if core.paused else TEXT_COLOR)
    state.pose.position.x, state.pose.position.y, state.pose.position.z = leader.x, leader.y + 1.2, 0.5
    state.scale.z = 0.3
    state.text = "%s %s%s" % (core.state(), core.formation, " PAUSED" if core.paused else "")
    array.markers.append(state)
    if core.paused:
        ahead = compose(leader, Pose2D(0.8, 0.0, 0.0))
        warn = _marker("pause", 0, Marker.CYLINDER, stamp, PAUSE_COLOR)
        warn.pose.position.x, warn.pose.position.y = ahead.x, ahead.y
        warn.scale.x = warn.scale.y = 0.5
        warn.scale.z = 0.3
        array.markers.append(warn)
    return array


def fleet_center(members, poses):
    """(x, y) [m] of the middle of the box around the members' poses in map, or None when none
    has a pose: the origin of the `fleet` frame an rviz view follows."""
    known = [poses[r] for r in members if r in poses]
    if not known:
        return None
    xs, ys = [p.x for p in known], [p.y for p in known]
    return 0.5 * (min(xs) + max(xs)), 0.5 * (min(ys) + max(ys))
