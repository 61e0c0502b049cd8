"""What the follower controllers, the coordinator and the metrics collector share on the ROS side:
the slot assignment as plain data and its message, and tf pose lookups that never wait.

Why lookups never wait in sim time: under the simulator's lockstep, sim time stands still until
every driven robot has sent its command. A lookup that waited in sim time (tf2's timeout) would
hold the clock it waits for. So a lookup takes the newest transform and refuses it when it is
older than a bound, after polling for a newer one for a moment of wall time.
"""
import functools
from collections import namedtuple

from mbot_common.geometry import Pose2D, yaw_of

#: The fleet's slot assignment as plain data.
#: leader: robot name; formation: name; spacing [m]; slots: {robot: (x, y)} in the leader's frame
#: (the leader's own slot is (0, 0)); follows: {robot: the robot whose pose it tracks};
#: along_path: the slots behind the leader lie on its path (trail.path_slot), not rigid.
Assignment = namedtuple("Assignment", "leader formation spacing slots follows along_path", defaults=(False,))


class StalePose(Exception):
    """A tf lookup that failed or whose newest transform is too old; the message says which."""


def quiet_at_shutdown(callback):
    """A timer callback that ends quietly when the node shuts down under it: rospy closes the
    publishers before it stops the timers, and a cycle running then would print a traceback
    ("publish() to a closed topic")."""
    import rospy

    @functools.wraps(callback)
    def wrapped(*args):
        try:
            return callback(*args)
        except rospy.ROSException:
            if rospy.is_shutdown():
                return None
            raise
    return wrapped


def assignment_from_msg(msg):
    """mbot_msgs/FleetAssignment -> Assignment."""
    slots = {s.robot: (s.offset.x, s.offset.y) for s in msg.slots}
    follows = {s.robot: s.follows for s in msg.slots}
    return Assignment(msg.leader, msg.formation, msg.spacing, slots, follows, msg.along_path)


def assignment_to_msg(assignment, stamp):
    """Assignment -> mbot_msgs/FleetAssignment (the leader's slot first)."""
    from mbot_msgs.msg import FleetAssignment, SlotAssignment

    msg = FleetAssignment()
    msg.header.stamp = stamp
    msg.header.frame_id = "%s/base_link" % assignment.leader
    msg.leader = assignment.leader
    msg.formation = assignment.formation
    msg.spacing = assignment.spacing
    msg.along_path = bool(assignment.along_path)
    order = [assignment.leader] + sorted(r for r in assignment.slots if r != assignment.leader)
    for robot in order:
        slot = SlotAssignment()
        slot.robot = robot
        slot.offset.x, slot.offset.y = assignment.slots[robot]
        slot.follows = assignment.follows.get(robot, "")
        msg.slots.append(slot)
    return msg


def lookup_pose(buffer, target_frame, source_frame, now, max_age, wall_wait=0.0):
    """Pose of `source_frame` in `target_frame` from the newest transform in a tf2 Buffer.

    :param now: rospy.Time (sim time) the age is measured against
    :param max_age: [s] oldest acceptable transform
    :param wall_wait: [s wall] how long to poll for a current transform when the newest is too
        old. A loaded machine delivers /tf later than /clock; under lockstep sim time waits for
        this node, so the transform is on its way. The wait is in wall time, never in sim time.
    :returns: (Pose2D, stamp)
    :raises StalePose: no transform, or the newest one is older than max_age
    """
    import time

    import rospy
    import tf2_ros

    deadline = time.time() + wall_wait
    while True:
        try:
            t = buffer.lookup_transform(target_frame, source_frame, rospy.Time(0))
            age = (now - t.header.stamp).to_sec()
            problem = None if age <= max_age else "newest transform is %.2f s old (limit %.2f s)" % (age, max_age)
        except (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException) as error:
            problem = str(error).splitlines()[0]
        if problem is None:
            tr = t.transform.translation
            return Pose2D(tr.x, tr.y, yaw_of(t.transform.rotation)), t.header.stamp
        if time.time() >= deadline:
            raise StalePose("%s -> %s: %s" % (target_frame, source_frame, problem))
        time.sleep(0.002)
