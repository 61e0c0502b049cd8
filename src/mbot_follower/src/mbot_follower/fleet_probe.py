"""A client's view of a running formation fleet, for tests and benchmarks: it records every
robot's ground truth from the simulator, the coordinator's status and assignment, contacts and
the controllers' modes, sends targets and switches on the public topics, and waits for
conditions in sim time (with a wall-clock bound, since at real_time_factor 0 sim time may race or
stall). What it measures comes from the simulator, not from what the coordinator says of itself.
The slots of a formation along the path (a column) are placed on the leader's ground-truth path
since the assignment (trail.LeaderTrail, trail.path_slot), like the coordinator and the metrics
place them. Whether a switch is done is the metrics' rule (metrics.settle.SwitchSettle) on the
probe's samples: `switch_done`.
"""
import collections
import math
import threading
import time

import rospy
from geometry_msgs.msg import Pose2D as Pose2DMsg
from mbot_msgs.msg import Contact, FleetAssignment, FleetStatus, FollowerState, RobotStates
from std_msgs.msg import Header, String

from mbot_common.geometry import Pose2D, yaw_of
from mbot_follower.metrics.settle import SwitchSettle
from mbot_follower.metrics_node import stamp_of
from mbot_follower.trail import LeaderTrail, slot_pose, trail_start

STATES_WITH_SLOTS = ("FORMING", "NAVIGATING", "ARRIVED", "DEGRADED")
WALL_LIMIT = 600.0  # [s wall] no wait lasts longer than this, whatever sim time does
HISTORY = 50        # ground truth messages kept per robot (1 s at 50 Hz) to align the samples
SILENT_AFTER = 0.5  # [s sim] a robot whose ground truth is this far behind the newest is gone
RESUBSCRIBE_AFTER = 20.0  # [s wall] wait_for_fleet subscribes again to a topic still silent after this


def aligned(histories):
    """{robot: (t, pose, speed)} at one instant from each robot's ground truth history (oldest
    first): the newest entry no later than the oldest of the robots' newest stamps. The
    simulator stamps every robot's ground truth with the same step times, but the callbacks of
    a loaded test process run late and in any order: pairing each robot's newest message mixed
    poses of different times, an error of speed x age (0.35 m/s x 0.5 s) that the fleet never
    had. A robot silent for SILENT_AFTER (removed) keeps its newest entry."""
    newest = {r: h[-1] for r, h in histories.items() if h}
    if not newest:
        return {}
    latest = max(e[0] for e in newest.values())
    live = [r for r, e in newest.items() if e[0] >= latest - SILENT_AFTER]
    common = min(newest[r][0] for r in live)
    result = dict(newest)
    for r in live:
        result[r] = next((e for e in reversed(histories[r]) if e[0] <= common + 1e-6), histories[r][0])
    return result


class SampledAssignment(object):
    """An assignment message as it was at one sample, with its slots placed in the map then
    (`slot_poses`: {robot: Pose2D}); reads like the message (leader, formation, slots, ...)."""

    def __init__(self, msg, slot_poses):
        self.msg = msg
        self.slot_poses = slot_poses

    def __getattr__(self, name):
        return getattr(self.msg, name)


class FleetProbe(object):
    """Records the fleet: ground truth of every robot, status, assignment, contacts."""

    def __init__(self, robots, pace=False):
        """pace: send a lockstep heartbeat with every sample, so that the simulator's time waits
        for this process (a benchmark timing the steps it drives) instead of racing ahead of it."""
        self.lock = threading.RLock()   # slot_errors() takes it, also inside describe()
        self.robots = robots
        self.truth = {}        # robot -> (t, Pose2D, speed), the newest
        self._history = {r: collections.deque(maxlen=HISTORY) for r in robots}
        self.samples = []      # (t, state, {robot: Pose2D}, {robot: speed}, assignment)
        self.status = None
        self.states = []       # (t, state, reason): t the status message's stamp [s sim]
        self.assignment = None
        self.trail = LeaderTrail()   # the leader's ground truth since the assignment (path slots)
        self.contacts = []
        self._truth_sub = self._subscribe_truth()
        rospy.Subscriber("/fleet/status", FleetStatus, self._on_status, queue_size=50)
        rospy.Subscriber("/fleet/assignment", FleetAssignment, self._on_assignment, queue_size=5)
        rospy.Subscriber("/contacts", Contact, self._on_contact, queue_size=100)
        self.target_pub = rospy.Publisher("/simulation/target_pose", Pose2DMsg, queue_size=1, latch=True)
        self.formation_pub = rospy.Publisher("/fleet/formation", String, queue_size=1, latch=True)
        self.modes = {}        # robot -> its follower controller's last mode
        self.heartbeats = {}   # robot -> stamp of its controller's last state [s sim]
        self._state_subs = {r: self._subscribe_state(r) for r in robots}
        self._heartbeat_pub = rospy.Publisher("/lockstep/heartbeat", Header, queue_size=10) if pace else None
        self.timer = rospy.Timer(rospy.Duration(0.1), self._sample)

    def _subscribe_truth(self):
        # the whole fleet's ground truth in one message per step (stage_node's /stage/ground_truth),
        # not one subscription per robot: rospy's cost is per message
        return rospy.Subscriber("/stage/ground_truth", RobotStates, self._on_fleet_truth, queue_size=5,
                                tcp_nodelay=True)

    def _subscribe_state(self, robot):
        return rospy.Subscriber("/%s/follower_controller/state" % robot, FollowerState, self._on_follower, queue_size=5)

    def _on_follower(self, msg):
        self.modes[msg.robot] = msg.mode
        self.heartbeats[msg.robot] = msg.header.stamp.to_sec()

    def _on_fleet_truth(self, msg):
        for s in msg.robots:
            if s.name in self._history:
                self._truth(s.name, s.stamp.to_sec(), Pose2D(s.pose.x, s.pose.y, s.pose.theta),
                            math.hypot(s.twist.linear.x, s.twist.linear.y))

    def _on_truth(self, msg, robot):
        """One robot's nav_msgs/Odometry ground truth (its base_pose_ground_truth)."""
        p = msg.pose.pose
        v = msg.twist.twist.linear
        self._truth(robot, msg.header.stamp.to_sec(), Pose2D(p.position.x, p.position.y, yaw_of(p.orientation)),
                    math.hypot(v.x, v.y))

    def _truth(self, robot, t, pose, speed):
        with self.lock:
            self.truth[robot] = (t, pose, speed)
            self._history[robot].append(self.truth[robot])
            if self.assignment is not None and robot == self.assignment.leader \
                    and self.truth[robot][0] > self.trail.since + 1e-9:
                self.trail.follow(pose.x, pose.y, pose.theta)

    def _on_status(self, msg):
        with self.lock:
            if self.status is None or msg.state != self.status.state:
                # the coordinator's stamp: a loaded process runs this callback late
                self.states.append((stamp_of(msg.header), msg.state, msg.reason))
            self.status = msg

    def _on_assignment(self, msg):
        with self.lock:
            self.assignment = msg
            # the leader's path starts at its pose at the assignment's stamp; this callback may
            # run late, after the leader's next poses: those are on the path already
            since = stamp_of(msg.header)
            history = self._history.get(msg.leader, ())
            start = trail_start(history, since)
            self.trail.restart(since, start[1][:3] if start is not None and start[0] <= since + 1e-9 else None)
            for t, pose, _ in history:
                if t > since + 1e-9:
                    self.trail.follow(pose.x, pose.y, pose.theta)

    def _on_contact(self, msg):
        with self.lock:
            self.contacts.append(msg)

    def _sample(self, event):
        if self._heartbeat_pub is not None:
            self._heartbeat_pub.publish(Header(stamp=event.current_real, frame_id=rospy.get_name()))
        with self.lock:
            if self.status is None:
                return
            truth = aligned(self._history)
            poses = {r: v[1] for r, v in truth.items()}
            speeds = {r: v[2] for r, v in truth.items()}
            a = self.assignment
            if a is not None:
                a = SampledAssignment(a, self._slot_poses(poses, a))
            self.samples.append((rospy.get_time(), self.status.state, poses, speeds, a))

    # --- measures -----------------------------------------------------------------------------

    def _slot_poses(self, poses, assignment):
        """{robot: Pose2D} of the assignment's slots for the leader's pose in `poses` ({}: none);
        a path slot on the leader's path as recorded now."""
        if assignment is None or assignment.leader not in poses:
            return {}
        trail = self.trail if assignment.along_path else None
        return {s.robot: slot_pose(poses[assignment.leader], (s.offset.x, s.offset.y), trail)
                for s in assignment.slots}

    def slot_poses(self, poses, assignment):
        """{robot: Pose2D} of an assignment's slots placed for the leader's pose in `poses`."""
        with self.lock:
            return self._slot_poses(poses, assignment)

    def slot_errors(self, poses, assignment):
        """{follower: distance to its slot} from ground truth poses and an assignment: a sample's
        (its slots as placed then) or the message (its slots placed now)."""
        if assignment is None or assignment.leader not in poses:
            return {}
        slots = getattr(assignment, "slot_poses", None)
        if slots is None:
            with self.lock:
                slots = self._slot_poses(poses, assignment)
        errors = {}
        for s in assignment.slots:
            if s.robot == assignment.leader or s.robot not in poses or s.robot not in slots:
                continue
            errors[s.robot] = math.hypot(poses[s.robot].x - slots[s.robot].x, poses[s.robot].y - slots[s.robot].y)
        return errors

    def _settle(self, settle, samples, formation, since):
        """Feed the samples (of self.samples) from `since` [s sim] to `settle` (SwitchSettle):
        each one's slot errors if its assignment is `formation`; True once it is done."""
        for (t, state, poses, _, a) in samples:
            if t < since or state not in STATES_WITH_SLOTS:
                continue
            if a is None or a.formation != formation or a.leader not in poses:
                settle.since = None
            elif settle.update(t, self.slot_errors(poses, a)):
                return True
        return settle.done

    def switch_done(self, formation, since):
        """The metrics' rule (SwitchSettle: every follower within 0.3 m of its slot for 0.5 s) on
        this probe's samples from `since` [s sim] with `formation` assigned: (reached_at, done_at)
        [s sim], None while not done. The probe does not know which slots the coordinator counts
        as blocked: every follower counts."""
        settle = SwitchSettle()
        with self.lock:
            samples = list(self.samples)
        return (settle.reached_at, settle.done_at) if self._settle(settle, samples, formation, since) else None

    def wait_switch_done(self, formation, since, sim_timeout):
        """Wait until the switch to `formation` made at `since` [s sim] is done (switch_done);
        returns (reached_at, done_at) [s sim]."""
        settle = SwitchSettle()
        seen = [0]

        def done():
            with self.lock:
                samples = self.samples[seen[0]:]
                seen[0] = len(self.samples)
            return self._settle(settle, samples, formation, since)

        self.wait(done, sim_timeout, "the %s to stand (every follower within %.2f m of its slot for %.1f s)"
                  % (formation, settle.tolerance, settle.hold))
        return settle.reached_at, settle.done_at

    def last_heard(self, robot, sim_timeout=30.0):
        """The stamp of the last state that `robot`'s dead controller sent [s sim], once all of
        them are in: when its connection to this probe has closed. On a loaded machine a dead
        controller's last states can reach this process seconds of sim time after it died (a
        stressed trio_loss read a heartbeat 3.5 s older than the controller's last command)."""
        sub = self._state_subs[robot]
        self.wait(lambda: sub.get_num_connections() == 0, sim_timeout, "%s's controller to disconnect" % robot)
        return self.heartbeats[robot]

    def state(self):
        with self.lock:
            return self.status.state if self.status else None

    def wait(self, condition, sim_timeout, what):
        """Wait until condition() (sim time, wall-bounded); fail naming `what` and the fleet's state."""
        start = rospy.get_time()
        wall_end = time.time() + WALL_LIMIT
        while not rospy.is_shutdown() and time.time() < wall_end:
            if condition():
                return rospy.get_time()
            if rospy.get_time() - start > sim_timeout:
                break
            time.sleep(0.01)
        with self.lock:
            s = self.status
        raise AssertionError("timed out after %.0f s sim waiting for %s (fleet: %s, %s)\n%s" % (
            rospy.get_time() - start, what, s.state if s else "no status", s.reason if s else "", self.describe()))

    def describe(self):
        """Where every robot is, its slot error and its controller's mode (for failure messages)."""
        with self.lock:
            poses = {r: v[1] for r, v in self.truth.items()}
            errors = self.slot_errors(poses, self.assignment)
            lines = ["formation %s, leader %s" % (self.assignment.formation, self.assignment.leader)
                     if self.assignment else "no assignment"]
            for r in sorted(poses):
                lines.append("  %s at (%.2f, %.2f, %.0f deg), slot error %s, mode %s" % (
                    r, poses[r].x, poses[r].y, math.degrees(poses[r].theta),
                    "%.2f m" % errors[r] if r in errors else "-", self.modes.get(r, "?")))
        return "\n".join(lines)

    def wait_for_fleet(self, wall_timeout=120.0):
        """Wait in wall time (at real_time_factor 0 sim time races ahead while the nodes start)
        for the coordinator, every robot's ground truth, controller and move_base."""
        from mbot_navigation.move_base_client import connect_move_base

        heard = set()

        def listen(r):
            return rospy.Subscriber("/%s/follower_controller/state" % r, FollowerState,
                                    lambda msg: heard.add(r), queue_size=1)

        subs = {r: listen(r) for r in self.robots}
        end = time.time() + wall_timeout
        again = time.time() + RESUBSCRIBE_AFTER
        while time.time() < end and not rospy.is_shutdown():
            with self.lock:
                everyone = len(self.truth) == len(self.robots) and len(heard) == len(self.robots)
                ready = self.status is not None and everyone
            if ready:
                break
            if time.time() > again:
                # At load 50 one of five ground-truth subscriptions once never connected (rospy
                # got the publisher twice at once): subscribe again to what is still silent.
                if not self.truth:
                    self._truth_sub.unregister()
                    self._truth_sub = self._subscribe_truth()
                for r in self.robots:
                    if r not in heard:  # (one connection per topic and process: renew both)
                        subs[r].unregister()
                        self._state_subs[r].unregister()
                        self._state_subs[r] = self._subscribe_state(r)
                        subs[r] = listen(r)
                again = time.time() + RESUBSCRIBE_AFTER
            time.sleep(0.1)
        for sub in subs.values():
            sub.unregister()
        if not ready:
            raise AssertionError("fleet not up after %.0f s wall: status %s, ground truth of %s, controllers of %s" % (
                wall_timeout, self.status is not None, sorted(self.truth), sorted(heard)))
        for r in self.robots:
            connect_move_base(r, max(1.0, end - time.time()))

    def send_target(self, x, y, theta=0.0):
        self.target_pub.publish(Pose2DMsg(x, y, theta))

    def samples_in(self, states, since=0.0):
        with self.lock:
            return [s for s in self.samples if s[1] in states and s[0] >= since]
