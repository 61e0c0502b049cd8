"""What the follower controllers, the coordinator and the metrics collector share on the ROS side:
the slot assignment as plain data and its message, and tf pose lookups that never wait.

Why lookups never wait in sim time: under the simulator's lockstep, sim time stands still until
every driven robot has sent its command. A lookup that waited in sim time (tf2's timeout) would
hold the clock it waits for. So a lookup takes the newest transform and refuses it when it is
older than a bound, after polling for a newer one for a moment of wall time.
"""
import functools
import math
import threading
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
    ("publish() to a closed topic", or ValueError "I/O operation on closed file" when the
    publisher's buffer closed in the middle of publish())."""
    import rospy

    @functools.wraps(callback)
    def wrapped(*args):
        try:
            return callback(*args)
        except (rospy.ROSException, ValueError):
            if rospy.is_shutdown():
                return None
            raise
    return wrapped


def stale_scan(stamp, now, max_age, since=None):
    """Why a laser view is too old to trust, or None when it is current: the rule of the
    follower's safety layer and of the coordinator's leader pause (an old view of free space is
    none). `stamp` [s] is the newest scan's header stamp (None: no scan yet); `since` [s] is when
    the node began to listen: no scan yet is stale only once max_age has passed since then."""
    if stamp is None:
        if since is not None and now - since <= max_age:
            return None
        return "no scan yet"
    age = now - stamp
    if age > max_age:
        return "newest scan is %.2f s old (limit ~max_scan_age %.2f s)" % (age, max_age)
    return None


class CachedParams(object):
    """A node's private parameters (``~``) from rospy's parameter cache.

    The node subscribes to its namespace on the master once; the master then calls the node back
    when a parameter changes (``rosparam set``), so reading the parameters every cycle costs no
    call to the master. rospy's cache takes updates only of keys it already holds: the known keys
    that are not set get their defaults on the master first (as dynamic_reconfigure does), so
    that setting one later reaches the node too.
    """

    def __init__(self, defaults):
        import rospy

        values = rospy.get_param("~", {})
        missing = {key: value for key, value in defaults.items() if key not in values}
        if missing:
            merged = dict(values)
            merged.update(missing)
            rospy.set_param("~", merged)   # one call for all of them
        self._key = rospy.resolve_name("~")
        rospy.get_param_cached(self._key)

    def values(self):
        """{key: value} as the master has them now (a copy)."""
        import rospy

        return dict(rospy.get_param_cached(self._key, {}))


def twist_between(first, second):
    """(vx, vy, wz) in the robot's frame that takes the odometry pose `first` to `second`, each
    (x, y, theta, t [s]); None when they are not in time order. The simulator's odometry pose is its
    twist integrated, so two poses 0.02 s apart give the twist of /odom without receiving it."""
    dt = second[3] - first[3]
    if not dt > 0.0:
        return None
    turn = math.atan2(math.sin(second[2] - first[2]), math.cos(second[2] - first[2]))
    heading = first[2] + 0.5 * turn   # the chord of an arc lies along the mean heading
    dx, dy = second[0] - first[0], second[1] - first[1]
    c, s = math.cos(heading), math.sin(heading)
    return ((c * dx + s * dy) / dt, (-s * dx + c * dy) / dt, turn / dt)


class RobotTfListener(object):
    """A tf2 Buffer filled with the poses of chosen robots only: ``/<robot>/tf_pose`` of the fleet
    tf relay (mbot_localization's fleet_tf_relay: each robot's map -> odom -> base_footprint) and
    ``/tf_static`` (the fixed joints). tf2_ros.TransformListener would deserialize the whole
    fleet's /tf in Python, every follower every robot: a cost that grows with the square of the
    fleet. Lookups in the buffer are the same as with the listener.

    source "tf" makes it a plain tf2_ros.TransformListener (every robot; no relay needed).

    With the relay it also keeps each followed robot's twist from its last two odometry poses
    (``twist(robot)``): a follower then needs no subscription to the leader's /odom (50 Hz of
    messages with two 6 x 6 covariances, for three numbers)."""

    def __init__(self, buffer, source="relay", topic="tf_pose"):
        import rospy
        import tf2_ros
        from tf2_msgs.msg import TFMessage

        if source not in ("relay", "tf"):
            raise ValueError("tf source: expected relay or tf, got %r" % (source,))
        self.buffer = buffer
        self.source = source
        self.topic = topic
        self._msg = TFMessage
        self._subs = {}
        self._since = {}          # robot -> the clock at its first message
        self._lock = threading.Lock()
        self._last_update = 0.0   # [s] the clock at the newest message
        self._odom = {}           # robot -> its newest odometry pose (x, y, theta, t)
        self._twist = {}          # robot -> (vx, vy, wz) between its last two odometry poses
        if source == "tf":
            self._listener = tf2_ros.TransformListener(buffer)
        else:
            self._static = rospy.Subscriber("/tf_static", TFMessage, self._on_static, queue_size=100)

    def follow(self, robots):
        """Receive the poses of `robots` (a set of names) and of no other robot."""
        import rospy

        if self.source == "tf":
            return
        with self._lock:
            for robot in set(self._subs) - set(robots):
                self._subs.pop(robot).unregister()
                self._since.pop(robot, None)
                self._odom.pop(robot, None)
                self._twist.pop(robot, None)
            for robot in set(robots) - set(self._subs):
                self._subs[robot] = rospy.Subscriber("/%s/%s" % (robot, self.topic), self._msg, self._on_tf,
                                                     robot, queue_size=100, tcp_nodelay=True)

    def warm(self, robots, now, history):
        """True once the poses of every robot of `robots` have come in for `history` [s] up to
        `now`. A robot followed only now has none: a post-dated map -> odom begins after its
        odometry, and lookups fail until sim time has passed the first one (a full /tf listener,
        subscribed from the start, never saw that)."""
        if self.source == "tf":
            return True
        with self._lock:
            return all(r in self._since and now - self._since[r] >= history for r in robots)

    def robots(self):
        with self._lock:
            return set(self._subs)

    def twist(self, robot):
        """(vx, vy, wz) of `robot` from its last two odometry poses, or None (none yet, or not
        followed through the relay)."""
        with self._lock:
            return self._twist.get(robot)

    def _on_tf(self, msg, robot=None):
        import rospy

        now = rospy.get_time()
        with self._lock:
            if robot is not None and robot in self._subs:
                self._since.setdefault(robot, now)
        if now + 1.0 < self._last_update:   # sim time jumped back (a reset): as tf2_ros does
            self.buffer.clear()
        self._last_update = now
        for t in msg.transforms:
            self.buffer.set_transform(t, "fleet_tf_relay")
            if robot is not None and t.child_frame_id == robot + "/base_footprint":
                pose = (t.transform.translation.x, t.transform.translation.y, yaw_of(t.transform.rotation),
                        t.header.stamp.to_sec())
                with self._lock:
                    last = self._odom.get(robot)
                    if last is not None and pose[3] < last[3]:   # a reset: start again
                        self._twist.pop(robot, None)
                    elif last is not None:
                        twist = twist_between(last, pose)
                        if twist is not None:
                            self._twist[robot] = twist
                    if last is None or pose[3] != last[3]:
                        self._odom[robot] = pose

    def _on_static(self, msg):
        for t in msg.transforms:
            self.buffer.set_transform_static(t, "tf_static")


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


def lookup_pose(buffer, target_frame, source_frame, now, max_age, wall_wait=0.0, clock=None, sleep=None):
    """Pose of `source_frame` in `target_frame` from the newest transform in a tf2 Buffer.

    :param now: rospy.Time (sim time) the age is measured against
    :param max_age: [s] oldest acceptable transform
    :param wall_wait: [s wall] how long to poll for a current transform when the newest is too
        old. A loaded machine delivers /tf later than /clock; under lockstep sim time waits for
        this node, so the transform is on its way. The wait is in wall time, never in sim time.
    :param clock, sleep: the wall clock and its sleep (time.monotonic, time.sleep; tests inject theirs)
    :returns: (Pose2D, stamp)
    :raises StalePose: no transform, or the newest one is older than max_age
    """
    import time

    import rospy
    import tf2_ros

    clock = clock or time.monotonic
    sleep = sleep or time.sleep
    deadline = clock() + wall_wait
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
        if clock() >= deadline:
            raise StalePose("%s -> %s: %s" % (target_frame, source_frame, problem))
        sleep(0.002)
