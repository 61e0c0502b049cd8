"""Node ``metrics_collector``: the ROS side of the formation metrics (the numbers are metrics.py).

Inputs: ``/fleet/assignment`` (latched), ``/fleet/status``, ``/contacts``, ``/map`` (is a slot
in a wall?), ``/stage/markers`` (the simulator's static obstacles, spawned ones too: a slot beside
one is blocked as beside a wall; recorded as events), the ground truth of every robot from
``/stage/ground_truth`` (mbot_msgs/RobotStates, frame map: one message per step for the
whole fleet; ``~ground_truth: robots`` takes each ``/<ns>/base_pose_ground_truth`` instead),
and per robot ``/<ns>/follower_controller/state`` and ``/<ns>/move_base/global_plan``. The
robots are ``~robots`` if set, else every robot that appears in an assignment (subscribed when it first appears).

Outputs: ``/fleet/metrics`` (mbot_msgs/FleetMetrics, every ``~publish_period``, 1 s) and, when
``~output_dir`` is not empty, metrics.csv, events.csv, controller.csv and metrics.json in it,
every ``~write_period`` (5 s) and at shutdown, so that a killed run still leaves its files; and
``/lockstep/heartbeat`` (std_msgs/Header, stamp the newest sample's time), which the simulator
waits for in lockstep, so that its sim time does not run ahead of what was measured.

The control latency pairs each FollowerState with the simulator's report of when it applied that
command, ``/stage/applied_commands`` (mbot_msgs/AppliedCommands); without that report (a real
robot) it is the pose's age when the command was computed, logged once.

Parameters (all times sim time): ``~rate`` 10 Hz samples, ``~command_wait`` 1 s (a command not
applied this long after it was computed was not applied; no report this long: the fallback),
``~recovered_rms`` 0.15 m and
``~recovered_hold`` 1 s (recovery after a loss), ``~robot_radius`` 0.15 m (clearance),
``~stale_after`` 1 s, ``~moving_speed`` 0.05 m/s, ``~teleport_speed`` 5 m/s, ``~hold_back`` 5 s,
``~slot_clearance`` 0.25 m, ``~free_hold`` 3 s and ``~controller_silence`` 0.5 s (see MetricsConfig).
A message without a stamp (zero) counts at the time it arrives.
"""
import math
import threading
import time

import rospy
from mbot_msgs.msg import (AppliedCommands, Contact, FleetAssignment, FleetMetrics, FleetStatus, FollowerState,
                           RobotStates)
from nav_msgs.msg import OccupancyGrid, Odometry, Path
from std_msgs.msg import Header
from visualization_msgs.msg import MarkerArray

from mbot_common.geometry import yaw_of
from mbot_common.params import read_params
from mbot_follower.fleet_io import assignment_from_msg, quiet_at_shutdown
from mbot_follower.free_space import FreeSpace
from mbot_follower.metrics import MetricsCollector, MetricsConfig, RunWriter, summarize
from mbot_follower.metrics.collector import LATENCY_POSE_AGE
from mbot_follower.metrics.obstacles import from_markers

#: The live summary (/fleet/metrics, metrics.json while the run goes) goes over the whole record,
#: so its cost grows with the run: it is computed again only after 1 / SUMMARY_SHARE times its
#: last CPU time has passed, so that it never takes more than this share of a core. The final
#: summary (at shutdown) is always computed.
SUMMARY_SHARE = 0.05

#: Node parameters that are not MetricsConfig fields: name -> (kind, default).
NODE_PARAMS = {
    "robots": (list, []),          # robot names; empty: every robot of an assignment
    "output_dir": (str, ""),       # where the files go; empty: write nothing
    "publish_period": (float, 1.0),  # /fleet/metrics period [s]
    "write_period": (float, 5.0),    # files written this often [s]
    # fleet: the simulator's /stage/ground_truth (every robot in one message per step); robots:
    # each robot's /<robot>/base_pose_ground_truth (a simulator without the fleet topic)
    "ground_truth": (str, "fleet"),
}
GROUND_TRUTH = ("fleet", "robots")


def read_config():
    """(MetricsConfig, node parameters) from the private parameters; ConfigError / ValueError
    naming a parameter of the wrong type, an unknown one or a bad value."""
    spec = dict(NODE_PARAMS)
    spec.update({key: (float, value) for key, value in MetricsConfig().to_dict().items()})
    values = read_params(rospy.get_param("~", {}), spec, rospy.get_name())
    try:
        config = MetricsConfig(**{key: values[key] for key in MetricsConfig().to_dict()})
    except ValueError as error:
        raise ValueError("%s: %s" % (rospy.get_name(), error))
    for key in ("publish_period", "write_period"):
        if not (math.isfinite(values[key]) and values[key] > 0.0):
            raise ValueError("%s: %s: expected a number > 0 [s], got %r" % (rospy.get_name(), key, values[key]))
    if values["ground_truth"] not in GROUND_TRUTH:
        raise ValueError("%s: ground_truth: expected one of %s, got %r" % (
            rospy.get_name(), ", ".join(GROUND_TRUTH), values["ground_truth"]))
    for name in values["robots"]:
        if not isinstance(name, str) or not name or "/" in name:
            raise ValueError("%s: robots: expected robot names (no slashes), got %r" % (rospy.get_name(), name))
    return config, values


def twist_values(twist):
    """A Twist's six numbers, compared exactly: the simulator reports the cmd_vel as it arrived."""
    return (twist.linear.x, twist.linear.y, twist.linear.z, twist.angular.x, twist.angular.y, twist.angular.z)


def stamp_of(header):
    """The message's sim time [s]; the arrival time if it carries no stamp."""
    return header.stamp.to_sec() if not header.stamp.is_zero() else rospy.get_time()


class MetricsNode(object):
    def __init__(self, config, robots, output_dir, ground_truth="fleet"):
        self.collector = MetricsCollector(config)
        self.writer = RunWriter(output_dir) if output_dir else None
        self.fixed_robots = bool(robots)
        # The subscribers' threads and the timers share the collector. The summary of a long run
        # takes a tenth of a CPU second, seconds of wall time on a loaded machine: it is computed
        # on a snapshot outside this lock. Held that long, the lock stalled the heartbeat, the
        # simulator's lockstep went on without this node, and its samples lacked poses.
        self.lock = threading.Lock()
        self.write_lock = threading.Lock()   # one writer at a time, the newest record last
        self.closed = False
        self.summary_due = 0.0   # [s monotonic wall] when the live summary may be computed again
        self.subs = {}
        self.pub = rospy.Publisher("/fleet/metrics", FleetMetrics, queue_size=1)
        # In lockstep the simulator holds sim time until this heartbeat (the newest sample's time)
        # is current: on a busy machine the ground-truth streams would otherwise run seconds of
        # sim time ahead of what this node has measured.
        self.heartbeat_pub = rospy.Publisher("/lockstep/heartbeat", Header, queue_size=10)
        self.heartbeat = Header(frame_id=rospy.get_name())
        self.shared_subs = [
            rospy.Subscriber("/fleet/assignment", FleetAssignment, self.on_assignment, queue_size=10),
            rospy.Subscriber("/fleet/status", FleetStatus, self.on_status, queue_size=10),
            rospy.Subscriber("/contacts", Contact, self.on_contact, queue_size=100),
            rospy.Subscriber("/map", OccupancyGrid, self.on_map, queue_size=1),
            rospy.Subscriber("/stage/markers", MarkerArray, self.on_markers, queue_size=5),
            rospy.Subscriber("/stage/applied_commands", AppliedCommands, self.on_applied, queue_size=50),
        ]
        self.latency_method = None   # logged when it changes
        self.fleet_truth = ground_truth == "fleet"
        if self.fleet_truth:
            self.shared_subs.append(rospy.Subscriber("/stage/ground_truth", RobotStates, self.on_fleet_truth,
                                                     queue_size=200, tcp_nodelay=True))
        for robot in robots:
            self.attach(robot)

    def attach(self, robot):
        if robot in self.subs:
            return
        rospy.loginfo("%s: measuring %s", rospy.get_name(), robot)
        self.subs[robot] = [
            rospy.Subscriber("/%s/follower_controller/state" % robot, FollowerState, self.on_state, robot,
                             queue_size=100),
            rospy.Subscriber("/%s/move_base/global_plan" % robot, Path, self.on_plan, robot, queue_size=5),
        ]
        if not self.fleet_truth:
            self.subs[robot].append(rospy.Subscriber("/%s/base_pose_ground_truth" % robot, Odometry, self.on_truth,
                                                     robot, queue_size=200, tcp_nodelay=True))

    # --- callbacks: convert the message, hand it to the collector ------------------------------

    def on_assignment(self, msg):
        assignment = assignment_from_msg(msg)
        with self.lock:
            if self.closed:
                return
            self.collector.on_assignment(stamp_of(msg.header), assignment)
        if not self.fixed_robots:
            for robot in [assignment.leader] + sorted(assignment.slots):
                self.attach(robot)

    def on_map(self, msg):
        free_space = FreeSpace.from_grid_msg(msg, self.collector.config.slot_clearance)
        with self.lock:
            self.collector.free_space = free_space

    def on_markers(self, msg):
        """The simulator's static obstacles, at the stamp of their markers (stage_node stamps a
        spawn's or removal's markers with its sim time)."""
        stamps = [m.header.stamp for m in msg.markers if not m.header.stamp.is_zero()]
        t = stamps[0].to_sec() if stamps else rospy.get_time()
        obstacles = from_markers(msg.markers)
        with self.lock:
            if not self.closed:
                self.collector.on_obstacles(t, obstacles)

    def on_status(self, msg):
        with self.lock:
            if not self.closed:
                self.collector.on_status(stamp_of(msg.header), msg.state, msg.reason, msg.lost, msg.paused,
                                         msg.switching)

    def on_contact(self, msg):
        with self.lock:
            if not self.closed:
                self.collector.on_contact(stamp_of(msg.header), msg.body_a, msg.body_b,
                                          msg.position.x, msg.position.y)

    def on_truth(self, msg, robot):
        if msg.header.frame_id.lstrip("/") != "map":
            rospy.logerr_throttle(10.0, "%s: /%s/base_pose_ground_truth: expected frame map, got %r; ignored"
                                  % (rospy.get_name(), robot, msg.header.frame_id))
            return
        p = msg.pose.pose
        try:
            theta = yaw_of(p.orientation)
        except ValueError as error:
            rospy.logerr_throttle(10.0, "%s: /%s/base_pose_ground_truth: %s; ignored"
                                  % (rospy.get_name(), robot, error))
            return
        v = msg.twist.twist
        self._poses([(robot, stamp_of(msg.header), p.position.x, p.position.y, theta,
                      (v.linear.x, v.linear.y, v.angular.z))])

    def on_fleet_truth(self, msg):
        """/stage/ground_truth: the robots measured (attached) among them."""
        if msg.header.frame_id.lstrip("/") != "map":
            rospy.logerr_throttle(10.0, "%s: /stage/ground_truth: expected frame map, got %r; ignored"
                                  % (rospy.get_name(), msg.header.frame_id))
            return
        self._poses([(s.name, s.stamp.to_sec(), s.pose.x, s.pose.y, s.pose.theta,
                      (s.twist.linear.x, s.twist.linear.y, s.twist.angular.z))
                     for s in msg.robots if s.name in self.subs])

    def _poses(self, poses):
        """Ground-truth poses [(robot, t, x, y, theta, twist)] to the collector; the heartbeat
        when they completed a sample."""
        with self.lock:
            if self.closed:
                return
            samples = len(self.collector.run.samples)
            for pose in poses:
                self.collector.on_pose(*pose)
            if len(self.collector.run.samples) == samples:
                return
            self.heartbeat.stamp = rospy.Time.from_sec(self.collector.run.samples[-1].t)
            self.heartbeat_pub.publish(self.heartbeat)

    def on_state(self, msg, robot):
        with self.lock:
            if not self.closed:
                self.collector.on_follower_state(robot, stamp_of(msg.header), msg.pose_stamp.to_sec(), msg.active,
                                                 msg.lookups, msg.lookup_failures, msg.cycle_time, msg.mode,
                                                 msg.overruns, msg.late_starts, twist_values(msg.cmd))
                self._log_latency_method()

    def on_applied(self, msg):
        commands = [(c.robot, c.received.to_sec(), c.applied.to_sec(), twist_values(c.cmd)) for c in msg.commands]
        with self.lock:
            if not self.closed:
                self.collector.on_applied_commands(msg.since.to_sec(), msg.header.stamp.to_sec(), commands)
                self._log_latency_method()

    def _log_latency_method(self):
        method = self.collector.latency_method
        if method == self.latency_method:
            return
        self.latency_method = method
        if method == LATENCY_POSE_AGE:
            rospy.logwarn("%s: no /stage/applied_commands (not a simulator?): control latency = the pose's age "
                          "when the command was computed, without transport and actuation" % rospy.get_name())
        else:
            rospy.loginfo("%s: control latency measured end to end, from /stage/applied_commands"
                          % rospy.get_name())

    def on_plan(self, msg, robot):
        if msg.poses and msg.header.frame_id.lstrip("/") != "map":
            rospy.logerr_throttle(10.0, "%s: /%s/move_base/global_plan: expected frame map, got %r; ignored"
                                  % (rospy.get_name(), robot, msg.header.frame_id))
            return
        points = [(p.pose.position.x, p.pose.position.y) for p in msg.poses]
        with self.lock:
            if not self.closed:
                self.collector.on_plan(robot, stamp_of(msg.header), points)

    # --- outputs --------------------------------------------------------------------------------

    def live_summary(self, run):
        """summarize(run), or None while the last one's cost is not yet paid off (SUMMARY_SHARE)."""
        now = time.monotonic()
        if now < self.summary_due:
            return None
        started = time.thread_time()
        summary = summarize(run)
        self.summary_due = now + (time.thread_time() - started) / SUMMARY_SHARE
        return summary

    def publish(self, _event=None):
        with self.lock:
            run = self.collector.run.snapshot()
            state = self.collector.state
        summary = self.live_summary(run)
        if summary is None:
            return
        fleet = summary["fleet"]

        def number(key):
            return float("nan") if fleet[key] is None else fleet[key]

        msg = FleetMetrics()
        msg.header.stamp = rospy.Time.now()
        msg.state = state
        msg.slot_rms = number("slot_rms_m")
        msg.slot_max = number("slot_max_m")
        msg.fit_rms = number("fit_rms_m")
        msg.leader_lateral_error = number("leader_lateral_rms_m")
        msg.latency_p95 = number("latency_p95_s")
        msg.tf_success_rate = number("tf_success_rate")
        msg.contacts = fleet["contacts"]
        msg.min_clearance = number("min_clearance_m")
        msg.energy = fleet["energy_j"]
        with self.lock:
            power = {r: p for r, (_, p) in self.collector.power.items()}
        msg.robots = sorted(summary["robots"])
        msg.robot_energy = [summary["robots"][r]["energy_j"] for r in msg.robots]
        msg.robot_power = [power.get(r, 0.0) for r in msg.robots]
        msg.distance = fleet["distance_m"]
        self.pub.publish(msg)

    def save(self, _event=None):
        if self.writer is None:
            return
        with self.lock:
            run = self.collector.run.snapshot()
        with self.write_lock:
            if not self.closed:   # else finish() writes (or wrote) a newer record
                self._write(run, self.live_summary(run))

    def finish(self):
        """At shutdown: the last write, then no more messages."""
        with self.lock:
            if self.closed:
                return
            self.closed = True
            self.collector.finish()   # the cycles still waiting for the simulator's report
            run = self.collector.run.snapshot()
        with self.write_lock:
            if self.writer is not None and self._write(run, summarize(run)):
                rospy.loginfo("%s: %d samples written to %s", rospy.get_name(), len(run.samples),
                              self.writer.output_dir)

    def _write(self, run, summary):
        """Write the record (metrics.json only with a summary); a folder that is gone (a test
        removed it as the run ended) or full is an error naming it, not a crash of the collector.
        Returns whether it was written."""
        try:
            self.writer.write(run, summary)
            return True
        except OSError as error:
            rospy.logerr_throttle(10.0, "%s: cannot write the record to %s: %s" % (
                rospy.get_name(), self.writer.output_dir, error))
            return False


def main():
    rospy.init_node("metrics_collector")
    try:
        config, params = read_config()
        node = MetricsNode(config, params["robots"], params["output_dir"], params["ground_truth"])
    except (ValueError, OSError) as error:   # ConfigError is a ValueError
        rospy.logfatal(str(error))
        return 1
    rospy.on_shutdown(node.finish)
    rospy.Timer(rospy.Duration(params["publish_period"]), quiet_at_shutdown(node.publish))
    rospy.Timer(rospy.Duration(params["write_period"]), node.save)
    rospy.spin()
    return 0
