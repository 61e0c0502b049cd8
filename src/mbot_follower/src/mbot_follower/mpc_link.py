"""The follower controller's ROS side of the predictive law (``controller: mpc``), made only when
that law runs, so the other laws cost nothing of it:

- publishes this follower's predicted path on ``/<ns>/predicted_path`` (nav_msgs/Path in
  ``map``; each pose stamped with the sim time it is predicted for) every cycle;
- subscribes to the teammates' predicted paths (the other robots of the assignment) and gives
  the law their positions at its own step times, in its frame (a path older than STALE is not
  used: the laser still sees that robot); the robot a rigid slot is relative to (the leader,
  whose move_base publishes no such path) is predicted with its twist held;
- gives the law the laser points (from the scan the node already has: a follower has no local
  costmap of its own) in its frame, the control period and the last command;
- publishes ``~mpc_stats`` (std_msgs/String, JSON: solves, fallbacks and their reasons, relaxed
  distances, solve time p50/p99/max [ms]) every STATS_PERIOD of sim time, and logs new
  fallbacks (throttled).
"""
import json
import math

import numpy as np
import rospy

from mbot_common.geometry import Pose2D, Twist2D, compose
from mbot_follower.control_laws import integrate, scan_points

STALE = 0.5          # [s sim] a teammate's predicted path older than this is not used
STATS_PERIOD = 1.0   # [s sim] ~mpc_stats this often


def to_frame(frame, xy):
    """Map points (m, 2) into the frame whose map pose is `frame` (Pose2D)."""
    c, s = math.cos(frame.theta), math.sin(frame.theta)
    d = np.asarray(xy, dtype=float).reshape(-1, 2) - (frame.x, frame.y)
    return np.column_stack([c * d[:, 0] + s * d[:, 1], -s * d[:, 0] + c * d[:, 1]])


def from_pose(pose, xy):
    """Points (m, 2) of the frame of `pose` into the frame `pose` is given in."""
    c, s = math.cos(pose.theta), math.sin(pose.theta)
    p = np.asarray(xy, dtype=float).reshape(-1, 2)
    return np.column_stack([pose.x + c * p[:, 0] - s * p[:, 1], pose.y + s * p[:, 0] + c * p[:, 1]])


def positions_at(times, xy, when):
    """A path's positions (xy (m, 2) at `times`) at the times `when`, held beyond its ends."""
    return np.column_stack([np.interp(when, times, xy[:, 0]), np.interp(when, times, xy[:, 1])])


class MpcLink(object):
    def __init__(self, robot):
        from geometry_msgs.msg import PoseStamped
        from nav_msgs.msg import Path
        from std_msgs.msg import String

        self.robot = robot
        self._Path, self._String, self._PoseStamped = Path, String, PoseStamped
        self.path_pub = rospy.Publisher("predicted_path", Path, queue_size=1)
        self.stats_pub = rospy.Publisher("~mpc_stats", String, queue_size=1, latch=True)
        self.paths = {}      # robot -> (times (k,), xy (k, 2) in map)
        self._subs = {}
        self._last_stats = None
        self._fallbacks_logged = 0

    def follow(self, robots):
        """Listen to the predicted paths of `robots` (the others of the assignment), only them."""
        wanted = set(robots) - {self.robot}
        for robot in set(self._subs) - wanted:
            self._subs.pop(robot).unregister()
            self.paths.pop(robot, None)
        for robot in wanted - set(self._subs):
            self._subs[robot] = rospy.Subscriber("/%s/predicted_path" % robot, self._Path, self._on_path, robot,
                                                 queue_size=1)

    def _on_path(self, msg, robot):
        if not msg.poses:
            self.paths.pop(robot, None)
            return
        times = np.array([p.header.stamp.to_sec() for p in msg.poses])
        xy = np.array([(p.pose.position.x, p.pose.position.y) for p in msg.poses])
        self.paths[robot] = (times, xy)   # one assignment of a tuple: no lock needed

    def inputs(self, node, frame, pose, twist, now, rigid, reference):
        """The law's extra inputs (ControlInput fields) for this cycle: dt, previous, obstacles,
        teammates, all in the law's frame (`frame`: its map pose; `pose`: the robot in it)."""
        config = node.config
        period = 1.0 / node.params["rate"]
        step = period * config.mpc_step
        when = now + step * np.arange(config.mpc_horizon + 1)
        teammates = []
        for robot, (times, xy) in list(self.paths.items()):
            if (robot == reference and rigid) or times[-1] < now - STALE:
                continue
            teammates.append(to_frame(frame, positions_at(times, xy, when)))
        if rigid:   # the robot the slot is relative to: the frame's origin, its twist held
            origin, track = Pose2D(0.0, 0.0, 0.0), []
            for k in range(config.mpc_horizon + 1):
                track.append((origin.x, origin.y))
                origin = integrate(origin, twist, step)
            teammates.append(np.array(track))
        obstacles = ()
        scan = node.scan
        if scan is not None:
            points = scan_points(scan.ranges, scan.angle_min, scan.angle_increment, scan.range_min,
                                 config.mpc_obstacle_range + 0.5)
            if points:
                obstacles = from_pose(pose, points)
        return {"dt": period, "previous": Twist2D(*node.filter.previous), "obstacles": obstacles,
                "teammates": teammates}

    def publish(self, law, frame, now, stamp):
        """The law's prediction on predicted_path (map), and the statistics now and then."""
        if law.prediction is not None:
            msg = self._Path()
            msg.header.stamp = stamp
            msg.header.frame_id = "map"
            for k, (x, y, theta) in enumerate(law.prediction):
                p = compose(frame, Pose2D(x, y, theta))
                ps = self._PoseStamped()
                ps.header.frame_id = "map"
                ps.header.stamp = rospy.Time.from_sec(now + k * law.step_dt)
                ps.pose.position.x, ps.pose.position.y = p.x, p.y
                ps.pose.orientation.z, ps.pose.orientation.w = math.sin(p.theta / 2), math.cos(p.theta / 2)
                msg.poses.append(ps)
            self.path_pub.publish(msg)
        if law.fallbacks > self._fallbacks_logged:
            rospy.logwarn_throttle(10.0, "%s: mpc fell back to slot tracking %d times of %d (%s)" % (
                rospy.get_name(), law.fallbacks, law.solves, law.reasons))
            self._fallbacks_logged = law.fallbacks
        if self._last_stats is None or now - self._last_stats >= STATS_PERIOD:
            self._last_stats = now
            self.stats_pub.publish(self._String(json.dumps(law.stats(), sort_keys=True)))
