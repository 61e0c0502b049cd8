"""Node ``coordinator``: the ROS side of the fleet coordinator (the logic is coordinator.py).

Inputs: ``/fleet/target_pose`` and ``/simulation/target_pose`` (geometry_msgs/Pose2D), the action
``/fleet/goal`` (mbot_msgs/FleetGoal), ``/fleet/formation`` (std_msgs/String) and the service
``/fleet/set_formation`` (mbot_msgs/SetFormation); each robot's pose from tf2 (``map ->
<robot>/base_link``), each follower controller's ``~state`` (its heartbeat), the leader's scan
(the fleet pauses when something is closer than ``~pause_distance`` in front of it) and ``/map``
(targets in walls or off the map are refused).

Outputs: ``/fleet/status`` (FleetStatus, on every change and at 2 Hz), ``/fleet/assignment``
(latched), ``/fleet/markers`` (slots, links, labels, state, a red marker while paused), the tf
frame ``~view_frame`` (``fleet``: the middle of the members, not rotated, for an rviz view that
follows the fleet) and the leader's move_base goal. While the leader drives through a switch
(coordinator.py) its ``move_base/DWAPlannerROS`` ``max_vel_x`` is raised to
``~switch_leader_vel`` by dynamic_reconfigure, and set back afterwards. ``~debug_mode`` prints
every follower's slot error in cm and degrees.
"""
import math
import queue
import threading
import time

import rospy

from mbot_common.geometry import Pose2D
from mbot_follower.control_laws import safety_stop
from mbot_follower.coordinator import ABORTED, ARRIVED, CoordinatorConfig, FleetCoordinator
from mbot_follower.fleet_io import (CachedParams, StalePose, assignment_to_msg, lookup_pose, quiet_at_shutdown,
                                    stale_scan)
from mbot_follower.formations import FormationLibrary
from mbot_follower.free_space import FreeSpace
from mbot_follower import markers

NODE_PARAMS = {
    "rate": 10.0,              # coordinator cycle [Hz sim time]
    "max_pose_age": 0.5,       # a robot's pose older than this does not count as seen [s]
    "pause_distance": 1.2,     # obstacle this close in front of the leader pauses the fleet [m]
    "pause_half_angle": math.radians(30.0),  # half-width of "in front" [rad]
    "max_scan_age": 0.3,       # an older leader scan pauses the fleet: a stale view is not safe [s]
    "map_clearance": 0.2,      # a target closer than this to a wall is refused [m]
    "debug_mode": False,       # print every follower's slot error once per second
    "startup_timeout": 60.0,   # [s wall] wait this long for every robot before counting absent ones lost
    "view_frame": "fleet",     # tf frame at the middle of the fleet ("" = none)
    "lockstep": False,         # the simulator's lockstep holds sim time for this node's heartbeat
    "loss_wall_wait": 1.0,     # [s wall] under lockstep: how long an overdue robot is waited for
    "param_refresh": 1.0,      # how often the private parameters are read again [s sim time]
}
# read once at the start: a change (rosparam set) is a warning that it needs a restart. The
# rest (NODE_PARAMS and CoordinatorConfig) apply at the next ~param_refresh.
RESTART_PARAMS = ("rate", "map_clearance", "robots", "world", "leader", "formation", "spacing", "formation_file")


def _robots_from_params():
    """The fleet's robots: ~robots if given, else the robots of the world file ~world."""
    robots = rospy.get_param("~robots", [])
    if robots:
        return [str(r) for r in robots]
    world = rospy.get_param("~world", "")
    if not world:
        raise ValueError("set ~robots (a list of names) or ~world (a world name or file)")
    import rospkg
    from mbot_common.paths import find_maps_directory, resolve_world
    from mbot_common.world import load_world

    maps = find_maps_directory(rospkg.RosPack().get_path("mbot_follower"))
    return [r.name for r in load_world(resolve_world(world, maps)).robots]


class CoordinatorNode(object):
    def __init__(self):
        import actionlib
        import tf2_ros
        from geometry_msgs.msg import Pose2D as Pose2DMsg
        from mbot_msgs.msg import FleetAssignment, FleetGoalAction, FleetStatus, FollowerState
        from mbot_msgs.srv import SetFormation
        from nav_msgs.msg import OccupancyGrid
        from std_msgs.msg import Header, String
        from visualization_msgs.msg import MarkerArray

        self._FleetStatus = FleetStatus
        self.params = dict(NODE_PARAMS)
        self.robots = _robots_from_params()
        leader = rospy.get_param("~leader", "") or self.robots[0]
        config = CoordinatorConfig()
        # rospy's parameter cache (as the follower): a rosparam set reaches the node without polling
        self._param_cache = CachedParams(dict(NODE_PARAMS, **vars(config)))
        self._init_params(config)
        self._read_params(self._param_cache.values(), config, startup=True)
        library = FormationLibrary()
        formation_file = rospy.get_param("~formation_file", "")
        if formation_file:
            library.load_file(formation_file)
        self.core = FleetCoordinator(self.robots, leader, rospy.get_param("~formation", "triangle"),
                                     rospy.get_param("~spacing", 2.5), config, library)
        self.lock = threading.RLock()
        self.last_heard_pose = {}
        self.last_heard_controller = {}
        self.controller_mode = {}
        self.poses = {}
        self.leader_scan = None
        self._scan_sub = None
        self._scan_robot = None
        self._scan_since = None      # [s sim] when the leader's scan was subscribed
        self._nav_robot = None       # whose move_base has our goal
        self._published_state = None
        self._last_status = None
        self._last_debug = None
        self._startup_done = False
        self._waited_for = set()     # overdue robots given their wall-time wait (lockstep)
        self._scan_waited = False    # the stale leader scan was given its wait (lockstep)
        self._last_nav = None
        self._wall_clock, self._sleep = time.monotonic, time.sleep   # unit tests inject their own
        self._wall_start = self._wall_clock()

        self.tf_buffer = tf2_ros.Buffer(cache_time=rospy.Duration(5.0))
        self._tf_listener = tf2_ros.TransformListener(self.tf_buffer)
        self.status_pub = rospy.Publisher("/fleet/status", FleetStatus, queue_size=10)
        self.assignment_pub = rospy.Publisher("/fleet/assignment", FleetAssignment, queue_size=1, latch=True)
        self.marker_pub = rospy.Publisher("/fleet/markers", MarkerArray, queue_size=1)
        self.tf_broadcaster = tf2_ros.TransformBroadcaster()
        self._view_stamp = None
        # In lockstep the simulator holds sim time until this heartbeat is current: a loss is
        # judged in sim seconds, which must not run away while a busy machine starves this node.
        self.heartbeat_pub = rospy.Publisher("/lockstep/heartbeat", Header, queue_size=10)
        self._heartbeat = Header(frame_id=rospy.get_name())
        for topic in ("/fleet/target_pose", "/simulation/target_pose"):
            rospy.Subscriber(topic, Pose2DMsg, self._on_target_pose, queue_size=1)
        rospy.Subscriber("/fleet/formation", String, self._on_formation, queue_size=1)
        rospy.Subscriber("/map", OccupancyGrid, self._on_map, queue_size=1)
        for robot in self.robots:
            rospy.Subscriber("/%s/follower_controller/state" % robot, FollowerState, self._on_controller,
                             callback_args=robot, queue_size=1)
        self.formation_srv = rospy.Service("/fleet/set_formation", SetFormation, self._on_set_formation)
        self.action = actionlib.SimpleActionServer("/fleet/goal", FleetGoalAction, execute_cb=self._execute,
                                                   auto_start=False)
        self.action.start()
        from move_base_msgs.msg import MoveBaseAction

        self._nav_clients = {r: actionlib.SimpleActionClient("/%s/move_base" % r, MoveBaseAction) for r in self.robots}
        self._nav_connected = set()
        self._connect_nav_thread = threading.Thread(target=self._connect_nav, daemon=True)
        self._connect_nav_thread.start()
        self._leader_speed = NavSpeedLimit()
        self.timer = rospy.Timer(rospy.Duration(1.0 / self.params["rate"]), quiet_at_shutdown(self._cycle))
        rospy.loginfo("coordinator: robots %s, leader %s, formation %s (spacing %.2f m)", ", ".join(self.robots),
                      leader, self.core.formation, self.core.spacing)

    # --- parameters ---------------------------------------------------------------------------

    def _init_params(self, config):
        """The parameter state before the first read (no ROS calls: unit tests build the node so)."""
        self._config_keys = set(vars(config))
        self._started_with = {}       # restart-only key -> its value at the start
        self._warned_keys = set()
        self._last_param_read = None

    def _read_params(self, values, config, startup=False):
        """Apply the private parameters `values` to self.params and `config` (the core's).
        At the start a bad value is an error (ValueError naming it); later it is refused with an
        error and the previous value stays. A changed restart-only key is a warning, once."""
        for key, value in sorted(values.items()):
            if key in RESTART_PARAMS and key not in NODE_PARAMS:
                if startup:
                    self._started_with[key] = value
                elif value != self._started_with.get(key, value):
                    self._warn_restart(key, value, self._started_with[key])
                continue
            if key in NODE_PARAMS:
                current = self.params[key]
            elif key in self._config_keys:
                current = getattr(config, key)
            else:
                if key not in self._warned_keys:
                    self._warned_keys.add(key)
                    rospy.logwarn("coordinator: unknown parameter ~%s (ignored)", key)
                continue
            try:
                # bool("false") is True: a bool wants a bool; a float takes an int
                if isinstance(current, bool) and not isinstance(value, bool):
                    raise ValueError
                value = type(current)(value)
            except (TypeError, ValueError):
                message = "parameter ~%s: expected a %s, got %r" % (key, type(current).__name__, value)
                if startup:
                    raise ValueError(message)
                rospy.logerr_throttle(5.0, "coordinator: %s: refused, keeping %r" % (message, current))
                continue
            if value == current:
                continue
            if key in RESTART_PARAMS and not startup:
                self._warn_restart(key, value, current)
            elif key in NODE_PARAMS:
                self.params[key] = value
            else:
                setattr(config, key, value)
            if not startup and key not in RESTART_PARAMS:
                rospy.loginfo("coordinator: ~%s = %r (was %r)", key, value, current)

    def _warn_restart(self, key, value, running):
        if (key, value) not in self._warned_keys:
            self._warned_keys.add((key, value))
            rospy.logwarn("coordinator: ~%s changed to %r: it takes effect when the node restarts (running "
                          "with %r)", key, value, running)

    def _refresh_params(self, now):
        if self._last_param_read is None or now - self._last_param_read >= self.params["param_refresh"]:
            self._last_param_read = now
            self._read_params(self._param_cache.values(), self.core.config)

    # --- commands -----------------------------------------------------------------------------

    def _on_target_pose(self, msg):
        ok, text = self._set_goal(Pose2D(msg.x, msg.y, msg.theta))
        (rospy.loginfo if ok else rospy.logerr)("coordinator: target (%.2f, %.2f, %.2f): %s", msg.x, msg.y,
                                                msg.theta, text)

    def _set_goal(self, target, formation="", spacing=0.0):
        with self.lock:
            now = rospy.Time.now()
            ok, text, actions = self.core.set_goal(target, now.to_sec(), dict(self.poses), formation, spacing)
            self._run(actions, now)
            self._publish_status(force=True, stamp=now)
        return ok, text

    def _on_formation(self, msg):
        ok, text = self._switch(msg.data, 0.0)
        (rospy.loginfo if ok else rospy.logerr)("coordinator: formation %r: %s", msg.data, text)

    def _on_set_formation(self, req):
        from mbot_msgs.srv import SetFormationResponse

        ok, text = self._switch(req.formation, req.spacing)
        return SetFormationResponse(ok, text)

    def _switch(self, name, spacing):
        if not (spacing == 0.0 or (math.isfinite(spacing) and spacing > 0.0)):
            return False, "spacing %r: expected a number > 0 [m] (0 keeps the current one)" % spacing
        with self.lock:
            now = rospy.Time.now()
            ok, text, actions = self.core.set_formation(name.strip(), now.to_sec(), dict(self.poses), spacing)
            self._run(actions, now)
            self._publish_status(force=True, stamp=now)
        return ok, text

    def _execute(self, goal):
        """/fleet/goal: accept from the action server's own thread (as move_base does), then
        report until the fleet arrives, aborts or the goal is preempted."""
        from mbot_msgs.msg import FleetGoalFeedback, FleetGoalResult

        start = rospy.Time.now()
        t = goal.target
        ok, text = self._set_goal(Pose2D(t.x, t.y, t.theta), goal.formation, goal.spacing)
        result = FleetGoalResult()
        if not ok:
            result.success, result.message = False, text
            self.action.set_aborted(result, text)
            return
        rate = rospy.Rate(5.0)
        while not rospy.is_shutdown():
            if self.action.is_preempt_requested():
                with self.lock:
                    self._run(self.core.cancel_goal(rospy.Time.now().to_sec(), "goal preempted"))
                result.success, result.message = False, "preempted"
                result.duration = (rospy.Time.now() - start).to_sec()
                self.action.set_preempted(result, "preempted")
                return
            with self.lock:
                state, reason, errors = self.core.state(), self.core.reason, self.core.errors
                leader_pose = self.poses.get(self.core.leader)
            feedback = FleetGoalFeedback(state=state)
            if errors is not None:
                feedback.rms_error, feedback.max_error = errors.rms, errors.max
            if leader_pose is not None:
                feedback.distance_to_goal = math.hypot(leader_pose.x - t.x, leader_pose.y - t.y)
            self.action.publish_feedback(feedback)
            if state in (ARRIVED, ABORTED):
                result.success, result.message = state == ARRIVED, reason
                result.duration = (rospy.Time.now() - start).to_sec()
                (self.action.set_succeeded if state == ARRIVED else self.action.set_aborted)(result, reason)
                return
            try:
                rate.sleep()
            except rospy.ROSInterruptException:
                return

    # --- inputs -------------------------------------------------------------------------------

    def _on_map(self, msg):
        free_space = FreeSpace.from_grid_msg(msg, self.params["map_clearance"])
        with self.lock:
            self.core.free_space = free_space

    def _on_controller(self, msg, robot):
        self.last_heard_controller[robot] = msg.header.stamp.to_sec()
        self.controller_mode[robot] = msg.mode

    def _on_scan(self, msg):
        self.leader_scan = msg

    def _follow_leader_scan(self, leader, now):
        from sensor_msgs.msg import LaserScan

        if self._scan_robot == leader:
            return
        if self._scan_sub is not None:
            self._scan_sub.unregister()
        self.leader_scan = None
        self._scan_robot = leader
        self._scan_since = now
        self._scan_sub = rospy.Subscriber("/%s/scan" % leader, LaserScan, self._on_scan, queue_size=1,
                                          tcp_nodelay=True)  # no Nagle wait between hosts

    def _obstacle_ahead(self, leader, now):
        """Why the fleet must pause for what is in front of the leader (a str), or False. The
        leader's scan older than ~max_scan_age is a reason: a stale view is not a safe one (the
        follower's safety layer has the same rule, fleet_io.stale_scan)."""
        scan = self.leader_scan
        why = stale_scan(scan.header.stamp.to_sec() if scan is not None else None, now,
                         self.params["max_scan_age"], self._scan_since)
        if why is not None:
            rospy.logwarn_throttle(2.0, "coordinator: the leader %s's scan (/%s/scan): %s: the fleet pauses" % (
                leader, leader, why))
            return "the leader %s's scan: %s" % (leader, why)
        if scan is not None and safety_stop(scan.ranges, scan.angle_min, scan.angle_increment,
                                            self.params["pause_distance"], self.params["pause_half_angle"]):
            return "obstacle in front of the leader %s" % leader
        return False

    # --- the cycle ----------------------------------------------------------------------------

    def _cycle(self, event):
        started = rospy.Time.now()
        # rospy's timer thread dies with the first exception: a bug must cost one cycle, not the fleet
        try:
            self._step(event)
        except Exception:  # noqa: B902 (logged with its traceback; the next cycle runs)
            import traceback

            rospy.logerr_throttle(5.0, "coordinator: cycle failed:\n%s" % traceback.format_exc())
        self._heartbeat.stamp = started
        self.heartbeat_pub.publish(self._heartbeat)

    def _look_up_poses(self, now_ros):
        """{robot: Pose2D} of the robots with a current pose; notes when each was last heard of."""
        poses = {}
        for robot in self.robots:
            try:
                # any age: the stamp says when the robot was last heard of (loss is 1 s without tf)
                pose, stamp = lookup_pose(self.tf_buffer, "map", "%s/base_link" % robot, now_ros, float("inf"))
            except StalePose:
                continue
            self.last_heard_pose[robot] = stamp.to_sec()
            if now_ros.to_sec() - stamp.to_sec() <= self.params["max_pose_age"]:
                poses[robot] = pose
        return poses

    def _last_heard(self, now, leader):
        """({robot: sim time it was last complete}, lag of all poses, lag of all controller states)."""
        pose_lag = _lag(self.last_heard_pose, now)
        # the leader's own controller is idle and always quick: judge followers by followers
        controller_lag = _lag({r: t for r, t in self.last_heard_controller.items() if r != leader}, now)
        last_heard = {}
        for robot in self.robots:
            heard = self.last_heard_pose.get(robot, -1e9) + pose_lag
            if robot != leader:  # a follower also needs its controller
                heard = min(heard, self.last_heard_controller.get(robot, -1e9) + controller_lag)
            last_heard[robot] = heard
        return last_heard, pose_lag, controller_lag

    def _overdue(self, now, leader):
        """The members unheard for longer than the loss timeout."""
        last_heard = self._last_heard(now, leader)[0]
        with self.lock:
            return {r for r in self.core.members if now - last_heard[r] > self.core.config.loss_timeout}

    def _wait_for_overdue(self, now_ros, leader, poses):
        """Under lockstep, give members whose messages are overdue ~loss_wall_wait of wall time
        before they count as lost; returns the poses looked up again. On a loaded machine one
        connection's messages can stall for a second of sim time while the robot's controller
        runs every cycle (a 3-robot benchmark run lost a follower for 0.15 s so). Meanwhile this
        node's heartbeat stands, and with it sim time (but for the simulator's pacer lag), so the
        wait costs little sim time. A robot that stays silent is waited for once."""
        if not (self._startup_done and self.params["lockstep"]):
            return poses
        now = now_ros.to_sec()
        overdue = self._overdue(now, leader)
        self._waited_for &= overdue   # heard again: its next silence is waited for again
        if not overdue - self._waited_for:
            return poses
        found = {}

        def heard():
            found["poses"] = self._look_up_poses(now_ros)
            return not overdue & self._overdue(now, leader)

        waited = self._wall_wait(heard)
        if waited is not None:
            rospy.logwarn("coordinator: the messages of %s came %.2f s of wall time late (a loaded machine)",
                          ", ".join(sorted(overdue)), waited)
        else:
            self._waited_for |= self._overdue(now, leader)
        return found.get("poses", poses)

    def _wall_wait(self, done):
        """Sleep until done() (checked every 10 ms), at most ~loss_wall_wait of wall time; returns
        the wall time it took, None if it never came."""
        started = self._wall_clock()
        while self._wall_clock() - started < self.params["loss_wall_wait"] and not rospy.is_shutdown():
            self._sleep(0.01)
            if done():
                return self._wall_clock() - started
        return None

    def _wait_for_scan(self, leader, now):
        """Under lockstep, give a stale leader scan ~loss_wall_wait of wall time to come before the
        fleet pauses for it, once per stale spell (as _wait_for_overdue does for robots): on a
        loaded machine this node's scan thread fell 0.35 s of sim time behind and paused a fleet
        that had a clear view (trio_switch under stress)."""
        if not (self._startup_done and self.params["lockstep"]) or self._scan_robot != leader:
            return

        def fresh():
            scan = self.leader_scan
            return stale_scan(scan.header.stamp.to_sec() if scan is not None else None, now,
                              self.params["max_scan_age"], self._scan_since) is None

        if fresh():
            self._scan_waited = False
            return
        if self._scan_waited:
            return
        self._scan_waited = True
        waited = self._wall_wait(fresh)
        if waited is not None:
            rospy.logwarn("coordinator: the leader %s's scan came %.2f s of wall time late (a loaded machine)",
                          leader, waited)

    def _step(self, _event):
        now_ros = rospy.Time.now()
        now = now_ros.to_sec()
        with self.lock:
            self._refresh_params(now)
        leader = self.core.leader
        poses = self._wait_for_overdue(now_ros, leader, self._look_up_poses(now_ros))
        self._wait_for_scan(leader, now)
        with self.lock:
            self.poses = poses
            leader = self.core.leader
            last_heard, pose_lag, controller_lag = self._last_heard(now, leader)
            if not self._started(last_heard, now):
                return
            self._follow_leader_scan(leader, now)
            obstacle = self._obstacle_ahead(leader, now)
            # followers off their slot for a reason the leader's waiting would not cure
            excused = [r for r, mode in self.controller_mode.items() if mode in ("trail", "safety_stop")]
            nav = self._leader_nav()
            if nav != self._last_nav:
                rospy.loginfo("coordinator: %s's navigation: %s", leader, nav or "no goal")
                self._last_nav = nav
            lost_before = set(self.core.lost)
            actions = self.core.update(now, poses, last_heard, nav, obstacle, excused)
            for robot in sorted(set(self.core.lost) - lost_before):
                rospy.logwarn("coordinator: %s unheard: newest pose %.2f s old, controller state %.2f s old "
                              "(all poses %.2f s behind, all controller states %.2f s behind)", robot,
                              _age(self.last_heard_pose.get(robot), now),
                              _age(self.last_heard_controller.get(robot), now), pose_lag, controller_lag)
            # the assignment and the status of one decision carry its time: a metrics sample
            # between two stamps would see the new slots under the old state
            self._run(actions, now_ros)
            self._publish_status(stamp=now_ros)
            self.marker_pub.publish(markers.fleet_markers(self.core, poses, now_ros))
            self._publish_view_frame(poses, now_ros)
            if self.params["debug_mode"] and (self._last_debug is None or now - self._last_debug >= 1.0):
                self._last_debug = now
                for robot, (dist, heading) in sorted(self.core.slot_errors(poses).items()):
                    rospy.loginfo("coordinator: %s slot error %.1f cm, %.1f deg", robot, dist * 100.0,
                                  math.degrees(heading))

    def _publish_view_frame(self, poses, stamp):
        from geometry_msgs.msg import TransformStamped

        center = markers.fleet_center(self.core.members, poses)
        # tf2 warns (TF_REPEATED_DATA) in every listener about a second transform with one stamp
        if not self.params["view_frame"] or center is None or stamp == self._view_stamp:
            return
        self._view_stamp = stamp
        t = TransformStamped()
        t.header.stamp = stamp
        t.header.frame_id = "map"
        t.child_frame_id = self.params["view_frame"]
        t.transform.translation.x, t.transform.translation.y = center
        t.transform.rotation.w = 1.0
        self.tf_broadcaster.sendTransform(t)

    def _started(self, last_heard, now):
        """Startup is a wall-time affair (at real_time_factor 0 sim time races ahead while nodes
        come up): the coordinator starts once every robot was heard, or after ~startup_timeout
        seconds of wall time, when the absent ones count as lost."""

        if self._startup_done:
            return True
        missing = [r for r in self.robots if now - last_heard[r] > self.core.config.loss_timeout]
        if missing and self._wall_clock() - self._wall_start < self.params["startup_timeout"]:
            rospy.loginfo_throttle(5.0, "coordinator: waiting for %s" % ", ".join(missing))
            return False
        if missing:
            rospy.logerr("coordinator: %s did not come up in %.0f s: starting without them", ", ".join(missing),
                         self.params["startup_timeout"])
        self._startup_done = True
        return True

    def _leader_nav(self):
        """The state of the goal we gave the leader's move_base, in the words update() takes."""
        from actionlib_msgs.msg import GoalStatus

        client = self._nav_clients.get(self._nav_robot)
        if client is None or self._nav_robot != self.core.leader:
            return None
        state = client.get_state()
        if state == GoalStatus.SUCCEEDED:
            return "SUCCEEDED"
        if state in (GoalStatus.ABORTED, GoalStatus.REJECTED):
            return "ABORTED: %s" % client.get_goal_status_text()
        if state in (GoalStatus.ACTIVE, GoalStatus.PENDING):
            return "ACTIVE"
        return None

    def _connect_nav(self):
        """Connect a move_base client for every robot (any may lead), waiting in wall time: at
        real_time_factor 0 a wait in sim time would give up before the nav nodes are up."""

        pending = list(self.robots)
        while pending and not rospy.is_shutdown():
            for robot in list(pending):
                if self._nav_clients[robot].wait_for_server(rospy.Duration(0.01)):
                    self._nav_connected.add(robot)
                    pending.remove(robot)
            time.sleep(0.1)

    def _run(self, actions, stamp=None):
        from mbot_navigation.move_base_client import make_goal

        for action in actions:
            if action[0] == "assignment":
                self.assignment_pub.publish(assignment_to_msg(self.core.assignment, stamp or rospy.Time.now()))
            elif action[0] == "goal":
                _, robot, target = action
                if self._nav_robot is not None and self._nav_robot != robot:
                    self._cancel(self._nav_robot)
                client = self._nav_clients[robot]
                if robot not in self._nav_connected:
                    rospy.logerr("coordinator: /%s/move_base is not connected (yet); sending the goal anyway", robot)
                client.send_goal(make_goal(target.x, target.y, target.theta))
                self._nav_robot = robot
                rospy.loginfo("coordinator: %s navigates to (%.2f, %.2f)", robot, target.x, target.y)
            elif action[0] == "cancel":
                self._cancel(action[1])
            elif action[0] == "leader_speed":
                self._leader_speed.set(action[1], action[2])

    def _cancel(self, robot):
        client = self._nav_clients.get(robot)
        if client is not None and self._nav_robot == robot:
            client.cancel_all_goals()
            self._nav_robot = None

    def _publish_status(self, force=False, stamp=None):
        c = self.core
        key = (c.state(), c.reason, c.leader, c.formation, tuple(c.members), tuple(c.lost), c.paused, c.switching)
        now = stamp or rospy.Time.now()
        if not force and key == self._published_state and self._last_status is not None \
                and (now - self._last_status).to_sec() < 0.5:
            return
        if key != self._published_state:
            rospy.loginfo("coordinator: %s (%s)", c.state(), c.reason)
        self._published_state = key
        self._last_status = now
        msg = self._FleetStatus()
        msg.header.stamp = now
        msg.header.frame_id = "map"
        msg.state, msg.reason, msg.formation, msg.spacing = c.state(), c.reason, c.formation, c.spacing
        msg.leader, msg.lost, msg.paused, msg.switching = c.leader, list(c.lost), c.paused, c.switching
        msg.members = sorted(c.members, key=lambda r: r != c.leader)   # the leader first, as the message says
        if c.target is not None:
            msg.has_target = True
            msg.target.x, msg.target.y, msg.target.theta = c.target
        e = c.errors
        if e is not None:
            msg.rms_error, msg.max_error, msg.fit_rms_error = e.rms, e.max, e.fit_rms
            msg.edge_error, msg.heading_error = e.edge_max, e.heading_max
        self.status_pub.publish(msg)


class NavSpeedLimit(object):
    """Sets a robot's navigation speed limit (``/<robot>/move_base/DWAPlannerROS`` ``max_vel_x``,
    by dynamic_reconfigure) and sets the usual one back, in a thread of its own: the
    coordinator's cycle never waits for a service."""

    TIMEOUT = 2.0  # [s wall] for the reconfigure services

    def __init__(self):
        self._requests = queue.Queue()
        self._clients = {}
        self._usual = {}  # robot -> its max_vel_x before it was raised
        threading.Thread(target=self._work, daemon=True).start()

    def set(self, robot, speed):
        """Drive `robot` at up to `speed` [m/s] (never slower than usual); None: as usual again."""
        self._requests.put((robot, speed))

    def _work(self):
        while not rospy.is_shutdown():
            robot, speed = self._requests.get()
            try:
                self._apply(robot, speed)
            except Exception as error:  # a dead or missing nav node: the fleet goes on at its speed
                rospy.logwarn("coordinator: could not set the speed limit of %s's navigation: %s", robot, error)

    def _apply(self, robot, speed):
        import dynamic_reconfigure.client

        if robot not in self._clients:
            self._clients[robot] = dynamic_reconfigure.client.Client(
                "/%s/move_base/DWAPlannerROS" % robot, timeout=self.TIMEOUT)
        client = self._clients[robot]
        if speed is None:
            if robot in self._usual:
                usual = self._usual.pop(robot)
                client.update_configuration({"max_vel_x": usual})
                rospy.loginfo("coordinator: %s navigates at up to %.2f m/s again", robot, usual)
            return
        if robot not in self._usual:
            config = client.get_configuration(timeout=self.TIMEOUT)
            if config is None:
                raise RuntimeError("no configuration from /%s/move_base/DWAPlannerROS" % robot)
            self._usual[robot] = config["max_vel_x"]
        if speed > self._usual[robot]:
            client.update_configuration({"max_vel_x": speed})
            rospy.loginfo("coordinator: %s navigates at up to %.2f m/s through the switch", robot, speed)


def _age(stamp, now):
    """Seconds since `stamp` for a log line: a transform stamped after this cycle's clock reading
    (sim time moved on meanwhile) is 0 s old, not -0.25 s; never heard is infinitely old."""
    return float("inf") if stamp is None else max(0.0, now - stamp)


def _lag(stamps, now):
    """How far a stream of stamped messages runs behind our clock: now minus its newest stamp.
    A robot is lost when it falls silent while the others go on; a loaded machine that delivers
    everybody's tf or heartbeats late must not make the coordinator count every robot lost."""
    return max(0.0, now - max(stamps.values())) if stamps else 0.0


def main():
    rospy.init_node("coordinator")
    try:
        CoordinatorNode()
    except ValueError as error:
        rospy.logfatal("coordinator: %s" % error)
        raise SystemExit(1)
    rospy.spin()
