"""Helpers shared by the navigation rostests (test/nav_*.py): goals, the robot's ground-truth
track, the simulator's contacts and the map. Everything waits in sim time; rostest's time-limit
(wall time) catches a simulator that stopped."""
import logging
import math
import threading

import rospy
from actionlib_msgs.msg import GoalStatus
from mbot_common.geometry import angle_diff as signed_angle_diff, yaw_of
from mbot_common.waits import wait_for_sim as wait_until  # noqa: F401 (the tests import it from here)
from mbot_msgs.msg import Contact
from nav_msgs.msg import OccupancyGrid, Odometry

from mbot_navigation.grid_paths import grid_from_msg
from mbot_navigation.move_base_client import connect_move_base, make_goal  # noqa: F401 (tests import it from here)

STATE_NAMES = {v: k for k, v in GoalStatus.__dict__.items() if k.isupper() and isinstance(v, int)}


def state_name(state):
    return STATE_NAMES.get(state, str(state))


def action_client(robot, timeout=60.0):
    """A connected SimpleActionClient for /<robot>/move_base (the server starts once the nav node
    has the map and the robot's pose); waits `timeout` wall seconds (see connect_move_base)."""
    try:
        return connect_move_base(robot, wall_timeout=timeout)
    except RuntimeError as e:
        raise AssertionError(str(e))


def run_goal(client, goal, timeout):
    """Send `goal`, wait up to `timeout` sim seconds; (state, status text, sim seconds taken)."""
    start = rospy.Time.now()
    client.send_goal(goal)
    if not client.wait_for_result(rospy.Duration(timeout)):
        client.cancel_goal()
        client.wait_for_result(rospy.Duration(5.0))
        return None, "no result within %.0f sim s" % timeout, (rospy.Time.now() - start).to_sec()
    return client.get_state(), client.get_goal_status_text(), (rospy.Time.now() - start).to_sec()


class ErrorLog(logging.Handler):
    """The ERROR (and worse) records that rospy logs in this process; attach it to the "rosout"
    logger."""

    def __init__(self):
        logging.Handler.__init__(self, logging.ERROR)
        self.records = []

    def emit(self, record):
        self.records.append(record.getMessage())


class Track(object):
    """A robot's ground-truth pose (/<robot>/base_pose_ground_truth) and the distance it drove.
    With history=True it also keeps every sample by its stamp, to compare what a node estimated
    for that stamp with: history[stamp in ns] = (x, y, yaw, distance driven since the start)."""

    def __init__(self, robot, history=False):
        self._lock = threading.Lock()
        self.pose = None       # (x, y, yaw)
        self.stamp = None      # [s sim] of pose
        self.length = 0.0      # [m] since reset()
        self.total = 0.0       # [m] since the first sample
        self.history = {} if history else None
        # a history needs every sample: a long queue rides out a busy moment of this process
        self._sub = rospy.Subscriber("/%s/base_pose_ground_truth" % robot, Odometry, self._on_odom,
                                     queue_size=2000 if history else 50)

    def _on_odom(self, msg):
        p, q = msg.pose.pose.position, msg.pose.pose.orientation
        yaw = yaw_of(q)
        with self._lock:
            if self.pose is not None:
                step = math.hypot(p.x - self.pose[0], p.y - self.pose[1])
                self.length += step
                self.total += step
            self.pose = (p.x, p.y, yaw)
            self.stamp = msg.header.stamp.to_sec()
            if self.history is not None:
                self.history[msg.header.stamp.to_nsec()] = (p.x, p.y, yaw, self.total)

    def reset(self):
        with self._lock:
            self.length = 0.0

    def wait(self, timeout=60.0):
        wait_until(lambda: self.pose is not None, timeout, "the robot's ground truth")
        return self.pose

    def pose_since(self, t, timeout=10.0):
        """The first pose stamped at sim time t or later: a busy test process receives the
        ground truth late, and the newest pose it has may show the robot still turning."""
        wait_until(lambda: self.stamp is not None and self.stamp >= t, timeout, "the ground truth of t = %.2f s" % t)
        return self.pose


class Contacts(object):
    """Contacts that the simulator reports (/contacts) that involve one of `robots`."""

    def __init__(self, robots):
        self.robots = set(robots)
        self.events = []
        self._sub = rospy.Subscriber("/contacts", Contact, self._on_contact, queue_size=100)

    def _on_contact(self, msg):
        if msg.body_a in self.robots or msg.body_b in self.robots:
            self.events.append("%s-%s at (%.2f, %.2f), t = %.2f" % (msg.body_a, msg.body_b, msg.position.x,
                                                                    msg.position.y, msg.header.stamp.to_sec()))


def wait_for_map(timeout=60.0):
    """The map (/map, latched) as a grid_paths.Grid."""
    msg = rospy.wait_for_message("/map", OccupancyGrid, timeout=timeout)
    return grid_from_msg(msg)


def angle_diff(a, b):
    """|a - b| the short way round [rad], in [0, pi]."""
    return abs(signed_angle_diff(a, b))
