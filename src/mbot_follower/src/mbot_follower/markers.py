"""/fleet/markers for rviz: each slot (a disc where a follower belongs, and a thin line to it from
a follower that is not there yet), a line from the leader to each follower, a label with each
robot's role and slot error, a red "lost" under a lost robot, the fleet state above the fleet
(with the lost robots), and a red cylinder in front of the leader while the fleet is paused; and
the centre of the fleet, where the `fleet` frame is that rviz's view can follow."""
import math

from mbot_common.geometry import Pose2D, compose

SLOT_COLOR = (0.1, 0.6, 1.0, 0.5)
LINK_COLOR = (0.2, 0.8, 0.2, 0.9)
TEXT_COLOR = (1.0, 1.0, 1.0, 1.0)
PAUSE_COLOR = (1.0, 0.1, 0.1, 0.8)
LOST_COLOR = (1.0, 0.25, 0.25, 1.0)
TO_SLOT_MIN = 0.1   # a follower farther than this from its slot gets a line to it [m]


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
    to_slots = _marker("to_slots", 0, Marker.LINE_LIST, stamp, SLOT_COLOR)
    to_slots.scale.x = 0.02
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
            if math.hypot(slot.x - pose.x, slot.y - pose.y) > TO_SLOT_MIN:
                to_slots.points += [Point(pose.x, pose.y, 0.03), Point(slot.x, slot.y, 0.03)]
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
    if to_slots.points:
        array.markers.append(to_slots)
    for i, robot in enumerate(sorted(core.lost)):
        pose = poses.get(robot)
        if pose is None:   # removed from the simulator: nothing to mark
            continue
        lost = _marker("lost", i, Marker.TEXT_VIEW_FACING, stamp, LOST_COLOR)
        lost.pose.position.x, lost.pose.position.y, lost.pose.position.z = pose.x, pose.y - 0.35, 0.3
        lost.scale.z = 0.25
        lost.text = "lost"
        array.markers.append(lost)
    state = _marker("state", 0, Marker.TEXT_VIEW_FACING, stamp, PAUSE_COLOR if core.paused else TEXT_COLOR)
    # above the fleet's top robot and its name: a long text beside the leader covered a follower
    state.pose.position.x = fleet_center(list(poses), poses)[0]
    state.pose.position.y = max(p.y for p in poses.values()) + 0.9
    state.pose.position.z = 0.5
    state.scale.z = 0.3
    state.text = "%s %s%s%s" % (core.state(), core.formation, " PAUSED" if core.paused else "",
                                " (lost: %s)" % ", ".join(sorted(core.lost)) if core.lost else "")
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
