"""Node ``follower_controller``: one per robot, in the robot's namespace (``/follower_1/...``).

Every control period (sim time) it

1. reads its private parameters again (every ``~param_refresh`` s) from rospy's parameter cache,
   which the master updates when one is set, so ``rosparam set`` of a gain or limit takes effect
   without a restart and without a call to the master (only ``~rate`` needs a restart: a
   warning says so);
2. looks up its pose in the leader's frame from tf2 (``<leader>/base_link -> <ns>/base_link``),
   polling up to ``~pose_wait`` of wall time (0.5 s under the simulator's lockstep, where the wait
   costs no sim time) for a transform at most ``~max_pose_age`` old; a failed or stale lookup
   skips the control law and holds the robot still: it never acts on old data. Lookups and
   failures are counted and published;
3. picks its target: its slot from ``/fleet/assignment`` (for a formation along the path, a
   column, the point of the leader's path its slot's distance behind the leader, from the
   leader's map positions recorded since the assignment: trail.path_slot); or, when something
   only the laser sees (a robot, an obstacle) stands on the straight way to a rigid slot, a way
   round it (mode ``detour``: the way to the slot turned by the smallest multiple of
   ``~detour_step`` that is clear, control_laws.detour); or, when the slot or the way to it is
   blocked otherwise (a wall, its inflation, a wall the laser sees near the way, no clear way
   round), a
   point on the leader's recent path (the trail) ``~trail_lookahead`` ahead of where the
   follower is on it, but no nearer the leader than the slot is: a path the leader drove is
   free, also around corners and through doors, and the follower rejoins its slot once the way
   is clear again. A path shorter than the slot's distance from the leader (it has just set
   off) has no such point: the follower keeps to its slot (its safety layer stops it short of
   what blocks it) rather than drive ahead of the robots that belong in front of it. A column's
   follower joins the leader's path in slot order (merge.py): while the robot of the slot ahead
   of its own is not ahead of it, it waits in a lane ``~merge_lane`` beside the path (mode
   ``merge``), then slides in behind it at ``~merge_gap`` from it, so two followers coming from a
   diamond's two sides do not meet on the path and hold each other;
4. runs the control law (``control_laws.py``: slot tracking or consensus), smooths and limits
   the command, and gives the safety layer the last word (``safety_filter``): anything closer
   than ``safety_distance`` within +-``safety_half_angle`` of the direction of travel, or in
   the lane the body sweeps next (``safety_near_distance`` long, +-``safety_lane_half_width``
   wide), stops the robot's travel;
5. publishes ``cmd_vel`` and ``~state`` (FollowerState). (Every robot's power and energy are the
   metrics collector's, from its measured velocity, whoever commands it.)

While its robot leads (the assignment names it), the node publishes no command: the robot's
move_base drives it. Before the first assignment, and while the fleet is IDLE, ABORTED or paused,
it holds the robot still (zero commands, so the simulator's lockstep keeps waiting for it).

Threads: rospy runs each subscription's callback and the timer in threads of their own. The
node's state (assignment, trails, the leader's pose, the scan) is guarded by one lock, which a
cycle holds from start to end, so an assignment never changes under a running cycle. A cycle that
fails is logged with its traceback, holds the robot still and counts as a failure; the next
cycle runs as usual (rospy's Timer would end for good on an exception).
"""
import math
import threading
import time
import traceback

import rospy

from mbot_common.geometry import Pose2D, Twist2D, compose, normalize_angle, relative, transform_point, yaw_of
from mbot_follower.control_laws import (CommandFilter, ControlInput, ControllerConfig, GiveWay, detour,
                                        make_control_law, safety_filter, scan_points, way_blocked)
from mbot_follower.fleet_io import (CachedParams, RobotTfListener, StalePose, assignment_from_msg, lookup_pose,
                                    quiet_at_shutdown, stale_scan)
from mbot_follower.free_space import FreeSpace
from mbot_follower.merge import merge_target, robot_ahead
from mbot_follower.trail import LeaderTrail, Trail, path_pose, path_slot

#: Private parameters of the node itself (the control law's are ControllerConfig's fields).
NODE_PARAMS = {
    "rate": 20.0,             # control frequency [Hz sim time]
    "max_pose_age": 0.1,      # oldest tf pose the controller acts on [s]
    "pose_wait": 0.1,         # how long to poll for a current pose before holding still [s wall]
    "max_scan_age": 0.3,      # an older laser scan stops the robot: the safety layer is blind [s]
    "tf_source": "relay",     # relay: only the robots it needs (fleet_tf_relay); tf: all of /tf
    "controller": "slot_tracking",  # control law: slot_tracking, consensus or mpc
    "param_refresh": 0.5,     # how often the private parameters are read again [s sim time]
    "map_clearance": 0.25,    # a slot closer than this to a wall of /map is blocked [m]
    "scan_clearance": 0.35,   # a laser point closer than this to the way to the slot blocks it [m]
    "scan_horizon": 2.0,      # how far along the way to the slot the laser check looks [m]
    "detour_step": math.radians(15),      # a way round an obstacle turns in steps of this [rad]
    "detour_max_turn": math.radians(90),  # ... at most this far from the way to the slot [rad]
    "trail_lookahead": 0.6,   # on the trail, drive to the point this far ahead on it [m]
    "path_turn_window": 0.2,  # a path slot turns as the path does over this much path ahead of it [m]
    "merge_lane": 0.7,        # a column follower waits this far beside the path for its turn [m]
    "merge_gap": 0.6,         # ... then slides in behind the robot of the slot ahead, this far from it [m]
}
#: Parameters that take effect only at start (the control timer's period).
RESTART_PARAMS = ("rate", "tf_source")
HOLD_STATES = ("IDLE", "ABORTED")
TF_CACHE = 5.0      # [s] of poses the node's tf buffer keeps (its cache_time)
POSE_PERIOD = 0.02  # [s] between a robot's poses (the simulator's odometry at 50 Hz)


def reference_of(a, robot):
    """The robot whose pose `robot` tracks in assignment `a`: the one it follows in a chain (the
    leader in a star), or the leader when that one is no longer in the formation."""
    reference = a.follows.get(robot) or a.leader
    return reference if reference in a.slots else a.leader


class FollowerController(object):
    """The ROS side of one follower: subscriptions, tf, parameters and publishing."""

    def __init__(self):
        import tf2_ros
        from geometry_msgs.msg import Twist
        from mbot_msgs.msg import FleetAssignment, FleetStatus, FollowerState
        from nav_msgs.msg import OccupancyGrid, Odometry
        from sensor_msgs.msg import LaserScan

        self._msg = {"Twist": Twist, "FollowerState": FollowerState, "Odometry": Odometry}
        self.robot = rospy.get_namespace().strip("/")
        if not self.robot:
            raise ValueError("follower_controller must run in a robot's namespace (ns=\"follower_1\")")
        self._init_state()
        self._param_cache = CachedParams(dict(NODE_PARAMS, **vars(ControllerConfig())))
        self._read_params(self._param_cache.values(), startup=True)
        self.law = make_control_law(self.params["controller"])

        self.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(5.0))
        self._tf = RobotTfListener(self.tf_buffer, self.params["tf_source"])
        self._tf.follow({self.robot})
        self.cmd_pub = rospy.Publisher("cmd_vel", Twist, queue_size=1)
        self.state_pub = rospy.Publisher("~state", FollowerState, queue_size=10)
        rospy.Subscriber("/fleet/assignment", FleetAssignment, self._on_assignment, queue_size=1)
        rospy.Subscriber("/fleet/status", FleetStatus, self._on_status, queue_size=1)
        # tcp_nodelay: between hosts Nagle would hold a scan (several TCP segments) for the delayed ACK
        rospy.Subscriber("scan", LaserScan, self._on_scan, queue_size=1, tcp_nodelay=True)
        rospy.Subscriber("/map", OccupancyGrid, self._on_map, queue_size=1)
        self.timer = rospy.Timer(rospy.Duration(1.0 / self.params["rate"]), quiet_at_shutdown(self._cycle))
        rospy.loginfo("%s: follower controller (%s) ready", rospy.get_name(), self.params["controller"])

    def _init_state(self):
        """The node's state before any message (no ROS calls: unit tests build the node so)."""
        self.lock = threading.Lock()
        self._tf = None                    # RobotTfListener (None in unit tests: the buffer is filled there)
        self.params = dict(NODE_PARAMS)
        self.law = make_control_law(self.params["controller"])
        self.config = ControllerConfig()
        self._config_keys = set(vars(ControllerConfig()))
        self._warned_keys = set()
        self.filter = CommandFilter(self.config)
        self.give_way = GiveWay()
        self._held = False
        self._detour_side = 1              # the side of the last way round an obstacle (+1 left)
        self.assignment = None
        self.fleet_state = "IDLE"
        self.paused = False
        self.scan = None
        self.free_space = None
        self._map_msg = None               # kept to apply a new ~map_clearance
        self.trail = Trail()               # the leader's path, for a blocked slot (trail mode)
        self.path = LeaderTrail()          # the leader's path since the assignment (path slots)
        self._path_pending = False         # start self.path from the tf buffer at the next cycle
        self._path_since = None            # the assignment's stamp (rospy.Time)
        self._leader_map = None            # the leader's newest map pose
        self._reference = None
        self.leader_twist = Twist2D(0.0, 0.0, 0.0)
        self._leader_odom_sub = None
        self._leader_sub_name = None
        self._was_driving = False
        self._last_param_read = None
        self.lookups = 0
        self.lookup_failures = 0
        self.cycle_failures = 0
        self.overruns = 0        # cycles whose computation took longer than the period [wall]
        self.late_starts = 0     # cycles that began a period or more after their time [sim]
        self._mpc = None         # mpc_link.MpcLink, made when the mpc law first runs

    # --- parameters ---------------------------------------------------------------------------

    def _read_params(self, values, startup=False):
        """Apply the private parameters `values`: node settings and the control law's gains and
        limits. A bad value is refused with an error naming it; the previous value stays. A
        changed ~rate is a warning: it takes effect at the next start."""
        for key, value in values.items():
            if key in NODE_PARAMS:
                self._apply_node_param(key, value, startup)
            elif key in self._config_keys:
                try:
                    self.config.update({key: value})
                except ValueError as error:
                    if startup:
                        raise
                    rospy.logerr_throttle(5.0, "%s: parameter ~%s refused: %s" % (rospy.get_name(), key, error))
            elif key not in self._warned_keys:
                self._warned_keys.add(key)
                message = "%s: unknown parameter ~%s (known: %s)" % (
                    rospy.get_name(), key, ", ".join(sorted(set(NODE_PARAMS) | self._config_keys)))
                if startup:
                    raise ValueError(message)
                rospy.logerr(message)

    def _apply_node_param(self, key, value, startup):
        kind = type(NODE_PARAMS[key])
        try:
            value = kind(value)
        except (TypeError, ValueError):
            if startup:
                raise ValueError("%s: parameter ~%s: expected a %s, got %r" % (
                    rospy.get_name(), key, kind.__name__, value))
            rospy.logerr_throttle(5.0, "%s: parameter ~%s refused: expected a %s, got %r" % (
                rospy.get_name(), key, kind.__name__, value))
            return
        if value == self.params[key] or startup:
            self.params[key] = value
            return
        if key in RESTART_PARAMS:
            if key not in self._warned_keys:
                self._warned_keys.add(key)
                rospy.logwarn("%s: ~%s changed to %r: it takes effect when the node restarts (running at %r)" % (
                    rospy.get_name(), key, value, self.params[key]))
            return
        if key == "controller":
            try:
                self.law = make_control_law(value)
            except ValueError as error:
                rospy.logerr_throttle(5.0, "%s: parameter ~controller refused: %s" % (rospy.get_name(), error))
                return
        self.params[key] = value
        if key == "map_clearance" and self._map_msg is not None:
            self.free_space = FreeSpace.from_grid_msg(self._map_msg, value)
        rospy.loginfo("%s: ~%s is now %r" % (rospy.get_name(), key, value))

    # --- inputs -------------------------------------------------------------------------------

    def _on_assignment(self, msg):
        self._on_assignment_data(assignment_from_msg(msg), msg.header.stamp)

    def _on_assignment_data(self, assignment, stamp=None):
        """`stamp`: the assignment's time (its header); None or 0 (no stamp): when it arrived."""
        if stamp is None or stamp.is_zero():
            stamp = rospy.Time.now()
        with self.lock:
            self._take_assignment(assignment, stamp)

    def _take_assignment(self, assignment, stamp):
        self.assignment = assignment
        self._path_since = stamp
        reference = self.assignment.follows.get(self.robot) or self.assignment.leader
        if self._reference != reference:
            self._reference = reference
            self.trail.clear()
        self._path_pending = True
        self._leader_map = None
        # The twist that moves the slot: the reference robot's for a rigid slot, the leader's
        # for a path slot (it moves along the path as fast as the leader drives).
        source = self.assignment.leader if self.assignment.along_path else reference
        if self._leader_sub_name != source:
            if self._leader_odom_sub is not None:
                self._leader_odom_sub.unregister()
                self._leader_odom_sub = None
            self._leader_sub_name = source
            self.leader_twist = Twist2D(0.0, 0.0, 0.0)
            if self._tf is not None and self._tf.source == "relay":
                return   # its twist comes with its poses (RobotTfListener.twist), read each cycle
            self._leader_odom_sub = rospy.Subscriber(
                "/%s/odom" % source, self._msg["Odometry"], self._on_leader_odom, source, queue_size=1,
                tcp_nodelay=True)

    def _on_status(self, msg):
        with self.lock:
            self.fleet_state = msg.state
            self.paused = msg.paused

    def _on_scan(self, msg):
        with self.lock:
            self.scan = msg

    def _on_map(self, msg):
        free_space = FreeSpace.from_grid_msg(msg, self.params["map_clearance"])  # slow: outside the lock
        with self.lock:
            self._map_msg = msg
            self.free_space = free_space

    def _on_leader_odom(self, msg, source):
        t = msg.twist.twist
        with self.lock:
            if source == self._leader_sub_name:   # not a message of a robot it no longer tracks
                self.leader_twist = Twist2D(t.linear.x, t.linear.y, t.angular.z)

    # --- the control cycle --------------------------------------------------------------------

    def _cycle(self, event):
        """One control period: the step under the node's lock; a failure is logged, holds the
        robot still and the next period runs as usual."""
        with self.lock:
            period = 1.0 / self.params["rate"]
            if event is not None and event.current_expected is not None and event.current_real is not None \
                    and (event.current_real - event.current_expected).to_sec() >= period:
                self.late_starts += 1   # this cycle began a period or more after its time (sim)
            try:
                self._step(rospy.Time.now())
            except rospy.ROSException:
                raise   # shutting down (quiet_at_shutdown)
            except Exception:
                self.cycle_failures += 1
                rospy.logerr_throttle(5.0, "%s: control cycle failed (%d so far), holding still:\n%s" % (
                    rospy.get_name(), self.cycle_failures, traceback.format_exc()))
                self._hold()

    def _step(self, now):
        started = time.time()
        if self._last_param_read is None or (now - self._last_param_read).to_sec() >= self.params["param_refresh"]:
            self._read_params(self._param_cache.values())
            self._last_param_read = now
        a = self.assignment
        tf_warm = True
        if self._tf is not None:
            needed = self._robots_needed(a)
            self._tf.follow(needed)
            tf_warm = self._tf.warm(needed, now.to_sec(), 2.0 * self.params["max_pose_age"])
            if self._tf.source == "relay" and self._leader_sub_name is not None:
                twist = self._tf.twist(self._leader_sub_name)
                self.leader_twist = Twist2D(*twist) if twist is not None else Twist2D(0.0, 0.0, 0.0)
        if a is None or self.robot not in a.slots:
            # Not (yet) in the formation: stand still. The command also tells the simulator's
            # lockstep to wait for this node, so sim time cannot run away from the fleet.
            self._hold()
            self._publish_state(now, "idle", started)
            return
        if a.leader == self.robot:
            if self._was_driving:  # handing the robot over to its move_base: stop once
                self._send(Twist2D(0.0, 0.0, 0.0))
                self.filter.reset()
                self._was_driving = False
            self._publish_state(now, "leading", started)
            return
        if self.fleet_state in HOLD_STATES or self.paused:
            self._hold()
            self._publish_state(now, "paused" if self.paused else "hold", started)
            return

        if not tf_warm:
            # a robot it began to follow just now: no lookup until its poses have come in
            self._hold()
            self._publish_state(now, "no_pose", started)
            return

        # star: every follower tracks the leader; chain: the robot ahead of it (a.follows)
        reference = reference_of(a, self.robot)
        age = self.params["max_pose_age"]
        lookup_started = time.time()
        try:
            self.lookups += 1
            pose, stamp = lookup_pose(self.tf_buffer, "%s/base_link" % reference, "%s/base_link" % self.robot,
                                      now, age, self.params["pose_wait"])
            ref_map, _ = lookup_pose(self.tf_buffer, "map", "%s/base_link" % reference, now, age)
        except StalePose as error:
            self.lookup_failures += 1
            rospy.logwarn_throttle(2.0, "%s: no current pose, holding still: %s" % (rospy.get_name(), error))
            self._hold()
            self._publish_state(now, "no_pose", started)
            return

        started += time.time() - lookup_started  # waiting for tf is not computing: not in cycle_time
        self._record_trail(a, reference, ref_map, now)
        frame, pose, slot, frame_twist = self._slot_frame(a, reference, pose, ref_map)
        goal, merging = self._merge_goal(a, now, frame, pose, slot) if frame is not ref_map else (slot, False)
        target, mode = self._target(goal, pose, frame, math.hypot(*a.slots[self.robot]), scan_check=not merging,
                                    rigid=frame is ref_map)
        if merging and mode == "slot":
            mode = "merge"
        neighbours = []
        if self.params["controller"] == "consensus":
            neighbours = self._neighbours(a, now, reference) if frame is ref_map else \
                self._path_neighbours(a, now, frame)
        twist = frame_twist if mode in ("slot", "merge", "detour") else Twist2D(frame_twist.vx, 0.0, 0.0)
        extra = self._mpc_inputs(a, frame, pose, twist, now, frame is ref_map, reference)
        cmd = self.law.compute(ControlInput(pose, target, twist, neighbours, **extra), self.config)
        if extra:
            self._mpc.publish(self.law, frame, now.to_sec(), now)
        cmd = self.filter.apply(cmd, 1.0 / self.params["rate"], getattr(self.law, "smooth", True))
        why = stale_scan(self.scan.header.stamp.to_sec() if self.scan is not None else None, now.to_sec(),
                         self.params["max_scan_age"])
        if why is not None:
            # The safety layer sees only through the laser: an old view of free space is none.
            rospy.logwarn_throttle(2.0, "%s: %s on %s: holding still" % (
                rospy.get_name(), why, rospy.resolve_name("scan")))
            self._hold()
            self._publish_state(now, "no_scan", started, stamp, (slot[0] - pose.x, slot[1] - pose.y), -pose.theta)
            return
        scan = (self.scan.ranges, self.scan.angle_min, self.scan.angle_increment)
        away = self.give_way.step(now.to_sec(), self._held, *scan, rank=self._rank(a, slot), config=self.config)
        if away is not None:
            cmd, mode = away, "give_way"
        # The safety layer has the last word: smoothing must not carry the robot on into something.
        cmd, self._held = safety_filter(cmd, *scan, config=self.config)
        if self._held:
            self.filter.sent(cmd)
            mode = "safety_stop"
        self._send(cmd)
        self._was_driving = True
        err = (slot[0] - pose.x, slot[1] - pose.y)
        self._publish_state(now, mode, started, stamp, err, -pose.theta, cmd)

    def _mpc_inputs(self, a, frame, pose, twist, now, rigid, reference):
        """The predictive law's extra inputs (none for the other laws: they cost nothing)."""
        if self.params["controller"] != "mpc":
            return {}
        if self._mpc is None:
            from mbot_follower.mpc_link import MpcLink
            self._mpc = MpcLink(self.robot)
        self._mpc.follow(a.slots)
        return self._mpc.inputs(self, frame, pose, twist, now.to_sec(), rigid, reference)

    def _record_trail(self, a, reference, ref_map, now):
        """Add the leader's map position to its trails. In a chain the leader is not the robot
        this follower tracks: a stale leader pose only skips this point of the trails (it must
        not hold the robot still). The path of a new assignment starts at the leader's pose."""
        leader_map = ref_map
        if reference != a.leader:
            try:
                leader_map = lookup_pose(self.tf_buffer, "map", "%s/base_link" % a.leader, now,
                                         self.params["max_pose_age"])[0]
            except StalePose:
                return
        self.trail.add(leader_map.x, leader_map.y)
        if self._path_pending:
            self._path_pending = not self._start_path(a.leader)
        if not self._path_pending:
            self.path.follow(leader_map.x, leader_map.y, leader_map.theta)
        self._leader_map = leader_map

    def _start_path(self, leader):
        """Start the leader's path of the assignment as the coordinator and the metrics collector
        do (trail.LeaderTrail): at the leader's pose at the assignment's stamp, then its poses
        since, from the tf buffer (an assignment that arrives late misses none of the path, also
        round a corner). Without a pose at the stamp (the leader's poses came in only later) it
        starts at the first one the buffer has after it. False while the buffer has no pose of
        the leader at or after the stamp yet: it waits for one."""
        import tf2_ros

        frame = "%s/base_link" % leader
        errors = (tf2_ros.LookupException, tf2_ros.ConnectivityException, tf2_ros.ExtrapolationException)

        def pose_at(t):
            try:
                tf = self.tf_buffer.lookup_transform("map", frame, t)
            except errors:
                return None
            return tf.transform.translation.x, tf.transform.translation.y, yaw_of(tf.transform.rotation)

        since = self._path_since
        try:
            newest = self.tf_buffer.lookup_transform("map", frame, rospy.Time(0)).header.stamp
        except errors:
            return False
        if newest < since:
            return False
        self.path.restart(since.to_sec(), pose_at(since))
        # the poses since, at the rate they come in (the collector takes each one); no further
        # back than the buffer keeps (an assignment of long ago starts at its oldest pose)
        step = rospy.Duration(POSE_PERIOD)
        t = rospy.Time.from_sec(max(since.to_sec(), newest.to_sec() - TF_CACHE)) + step
        while t < newest:
            pose = pose_at(t)
            if pose is not None:
                self.path.follow(*pose)
            t += step
        return True

    def _slot_frame(self, a, reference, pose, ref_map):
        """(frame in the map, the robot's pose in it, its slot (x, y) in it, the frame's twist)
        for the control law, which wants a slot that stands still in a moving frame.

        A rigid slot stands still in the reference robot's frame, which moves with that robot's
        twist. A path slot (along_path, behind the leader) stands still in its own frame, the
        slot's pose on the leader's path: that frame moves forward as fast as the leader drives
        and turns as the path turns ahead of it (not as the leader turns)."""
        offset = a.slots[self.robot]
        if not a.along_path or offset[0] >= 0.0 or self._leader_map is None or self._path_pending:
            return ref_map, pose, self._slot_relative_to(a, reference), self.leader_twist
        leader, distance = self._leader_map, -offset[0]
        slot = path_slot(leader, self.path, offset)
        speed = math.hypot(self.leader_twist.vx, self.leader_twist.vy)
        window = min(self.params["path_turn_window"], distance)
        turn = normalize_angle(path_pose(leader, self.path, distance - window).theta
                               - path_pose(leader, self.path, distance).theta)
        twist = Twist2D(speed, 0.0, speed * turn / window if window > 0.0 else 0.0)
        return slot, relative(slot, compose(ref_map, pose)), (0.0, 0.0), twist

    def _merge_goal(self, a, now, frame, pose, slot):
        """(goal in the path slot's frame, waiting beside the path): a column follower joins the
        path behind the robot of the slot ahead of its own (merge.py). A lane point in a wall of
        the map, or an unknown pose of the robot ahead, is no reason to wait."""
        ahead_robot = robot_ahead(a.slots, self.robot)
        if ahead_robot is None:
            return slot, False
        try:
            ahead_map, _ = lookup_pose(self.tf_buffer, "map", "%s/base_link" % ahead_robot, now,
                                       self.params["max_pose_age"])
        except StalePose:
            return slot, False
        ahead = relative(frame, ahead_map)
        goal, merging = merge_target((pose.x, pose.y), (ahead.x, ahead.y), self.params["merge_lane"],
                                     self.params["merge_gap"])
        if merging and self.free_space is not None:
            if not self.free_space.is_free(*transform_point(frame, *goal)):
                return slot, False
        return goal, merging

    def _robots_needed(self, a):
        """The robots whose poses this cycle may look up: itself, the robot it follows, the
        leader (its trail), the robot ahead on a column's path (merging) and, for consensus,
        every member."""
        if a is None or self.robot not in a.slots or a.leader == self.robot:
            return {self.robot}
        needed = {self.robot, a.leader, a.follows.get(self.robot) or a.leader}
        ahead = robot_ahead(a.slots, self.robot)
        if a.along_path and ahead is not None:
            needed.add(ahead)
        if self.params["controller"] == "consensus":
            needed.update(a.slots)
        return needed & (set(a.slots) | {self.robot})

    def _rank(self, a, slot):
        """How many follower slots lie farther from the leader than this robot's (GiveWay)."""
        mine = math.hypot(*a.slots[self.robot])
        return sum(1 for r, s in a.slots.items() if r not in (self.robot, a.leader) and math.hypot(*s) > mine + 1e-6)

    def _slot_relative_to(self, a, reference, robot=None):
        """The slot of `robot` (default: this one) seen from the robot it tracks (slots are given
        in the leader's frame; the formation is taken to face the way its reference faces)."""
        sx, sy = a.slots[robot or self.robot]
        rx, ry = a.slots[reference]
        return sx - rx, sy - ry

    def _target(self, slot, pose, ref_map, behind_leader, scan_check=True, rigid=True):
        """(target in the reference robot's frame, mode): the slot; or, when something only the
        laser sees stands on the straight way to a rigid slot (a robot, an obstacle), a way round
        it (mode detour); or, when the slot or the way to it is blocked otherwise (a wall of the
        map, a wall the laser sees near the way, or no way round), the trail point. The trail is
        the leader's: in a chain the point is `behind_leader` (the slot's distance from the
        leader) back on it, not the distance from the robot ahead. A follower waiting beside a
        column's path (merging) does not check its way with the laser: the robots it sees in its
        lane it waits for, and the trail would take it onto the path out of turn. A column's
        follower (not rigid) keeps to the trail, its slot's own path, rather than steer off it
        round the robot ahead."""
        slot_map = compose(ref_map, Pose2D(slot[0], slot[1], 0.0))
        me_map = compose(ref_map, pose)
        blocked = not self._map_way_free(me_map, slot_map)
        if not blocked and scan_check and self.scan is not None:
            goal = relative(pose, Pose2D(slot[0], slot[1], 0.0))   # the slot in the robot's own frame
            points = self._scan_points()
            horizon, clearance = self.params["scan_horizon"], self.params["scan_clearance"]
            blocked = way_blocked(points, goal.x, goal.y, horizon, clearance)
            # a wall (a door jamb) in the way: the leader's trail leads through, a turned way may not
            if blocked and rigid and not way_blocked(self._wall_points(points, me_map), goal.x, goal.y,
                                                     horizon, clearance):
                way = self._detour(points, goal, me_map)
                if way is not None:
                    t = compose(pose, Pose2D(way[0], way[1], 0.0))
                    return (t.x, t.y), "detour"
        point = None
        if blocked and len(self.trail):
            point = self.trail.pursuit_point(me_map.x, me_map.y, self.params["trail_lookahead"], behind_leader)
        if point is None:  # not blocked, or the leader's path does not reach back to the slot yet
            return slot, "slot"
        t = relative(ref_map, Pose2D(point[0], point[1], 0.0))
        return (t.x, t.y), "trail"

    def _map_way_free(self, me_map, end):
        """The map point `end` and the straight way to it from `me_map` are clear of the walls of
        /map and their margin (True without a map)."""
        if self.free_space is None:
            return True
        return self.free_space.is_free(end.x, end.y) and self.free_space.segment_free(me_map.x, me_map.y, end.x, end.y)

    def _scan_points(self):
        """The laser's points (robot frame) as far as the way checks look."""
        scan = self.scan
        reach = self.params["scan_horizon"] + self.params["scan_clearance"]
        return scan_points(scan.ranges, scan.angle_min, scan.angle_increment, scan.range_min, reach)

    def _wall_points(self, points, me_map):
        """The laser points (robot frame) that lie on a wall of /map or its margin."""
        if self.free_space is None:
            return []
        return [p for p in points if not self.free_space.is_free(*transform_point(me_map, *p))]

    def _detour(self, points, goal, me_map):
        """A clear way round what stands between the robot and its slot (`goal`, robot frame),
        also clear on the map; None next to a slot that something stands in (circling it would
        not bring the robot in), or when no way is clear."""
        distance = math.hypot(goal.x, goal.y)
        clearance = self.params["scan_clearance"]
        if distance < self.config.safety_distance and any(
                math.hypot(px - goal.x, py - goal.y) < clearance for px, py in points):
            return None

        def is_free(x, y):
            return self._map_way_free(me_map, compose(me_map, Pose2D(x, y, 0.0)))

        found = detour(points, goal.x, goal.y, self.params["scan_horizon"], clearance,
                       self.params["detour_step"], self.params["detour_max_turn"], self._detour_side, is_free)
        if found is None:
            return None
        way, self._detour_side = found
        return way

    def _path_neighbours(self, a, now, frame):
        """The other followers' poses and path slots in `frame` (consensus along the path)."""
        result = []
        for robot, offset in a.slots.items():
            if robot in (self.robot, a.leader):
                continue
            try:
                pose, _ = lookup_pose(self.tf_buffer, "map", "%s/base_link" % robot, now, self.params["max_pose_age"])
            except StalePose:
                continue
            slot = relative(frame, path_slot(self._leader_map, self.path, offset))
            result.append((relative(frame, pose), (slot.x, slot.y)))
        return result

    def _neighbours(self, a, now, reference):
        """The other followers' poses and slots for consensus, in the frame of the robot this one
        tracks (`reference`: the leader in a star, the robot ahead in a chain), the frame of its
        own pose and slot: the law compares (pose_j - pose_i) with (slot_j - slot_i), which mixes
        nothing only when all four are in one frame.

        In a chain each neighbour holds its slot in the frame of the robot it tracks, which may be
        turned against this one's (a follower that tracks this robot sits where this robot faces,
        not where the leader does): the neighbour's pose given here is its slot plus its own slot
        error, turned from that frame into this one. A neighbour on its chain slot is on its slot
        here; in a star this is simply its pose.

        The robots that track this one (directly or down the chain) are left out: their slots
        swing with this robot's heading, so their errors would steer it by its own heading
        (a rigid echelon chain did not form in 60 s with them)."""
        result = []
        for robot in a.slots:
            if robot in (self.robot, a.leader) or self._tracks_me(a, robot):
                continue
            its_reference = reference_of(a, robot)
            max_age = self.params["max_pose_age"]
            try:
                pose, _ = lookup_pose(self.tf_buffer, "%s/base_link" % its_reference, "%s/base_link" % robot, now,
                                      max_age)
                turn = 0.0
                if its_reference != reference:
                    turn = lookup_pose(self.tf_buffer, "%s/base_link" % reference, "%s/base_link" % its_reference,
                                       now, max_age)[0].theta
            except StalePose:
                continue
            own_x, own_y = self._slot_relative_to(a, its_reference, robot)
            error = transform_point(Pose2D(0.0, 0.0, turn), pose.x - own_x, pose.y - own_y)
            slot = self._slot_relative_to(a, reference, robot)
            result.append((Pose2D(slot[0] + error[0], slot[1] + error[1], normalize_angle(pose.theta + turn)), slot))
        return result

    def _tracks_me(self, a, robot):
        """Whether `robot` tracks this one, directly or through robots down the chain."""
        seen = set()
        while robot in a.follows and robot not in seen:
            seen.add(robot)
            robot = a.follows[robot]
            if robot == self.robot:
                return True
        return False

    # --- outputs ------------------------------------------------------------------------------

    def _hold(self):
        self.filter.reset()
        self._send(Twist2D(0.0, 0.0, 0.0))

    def _send(self, cmd):
        msg = self._msg["Twist"]()
        msg.linear.x, msg.linear.y, msg.angular.z = cmd.vx, cmd.vy, cmd.wz
        self.cmd_pub.publish(msg)

    def _publish_state(self, now, mode, started, pose_stamp=None, err=(0.0, 0.0), heading_error=0.0, cmd=None):
        msg = self._msg["FollowerState"]()
        msg.header.stamp = now
        msg.robot = self.robot
        msg.active = mode in ("slot", "merge", "detour", "trail", "safety_stop", "give_way")
        msg.mode = mode
        msg.controller = self.params["controller"]
        if pose_stamp is not None:
            msg.pose_stamp = pose_stamp
        msg.slot_error.x, msg.slot_error.y = err
        msg.heading_error = heading_error
        if cmd is not None:
            msg.cmd.linear.x, msg.cmd.linear.y, msg.cmd.angular.z = cmd.vx, cmd.vy, cmd.wz
        msg.lookups = self.lookups
        msg.lookup_failures = self.lookup_failures
        msg.cycle_time = time.time() - started
        if msg.cycle_time > 1.0 / self.params["rate"]:
            self.overruns += 1   # took longer than its period (wall): the next one starts late
        msg.overruns, msg.late_starts = self.overruns, self.late_starts
        self.state_pub.publish(msg)


def main():
    rospy.init_node("follower_controller")
    try:
        FollowerController()
    except ValueError as error:
        rospy.logfatal("%s: %s" % (rospy.get_name(), error))
        raise SystemExit(1)
    rospy.spin()
