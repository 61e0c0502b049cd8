"""Node ``dispatcher``: gives every robot of a fleet its own move_base goals, chosen centrally
(dispatch.py: a queue of goals; the least total path cost by the Hungarian method, or round
robin). No formation: fleet.launch mode:=dispatch.

Input: ``/dispatch/goals`` (geometry_msgs/PoseArray in the map frame): goals added to the queue,
at any time, any number; the robots' poses from tf2 (``map -> <robot>/base_link``).
Output: one goal at a time per robot on its ``/<robot>/move_base`` action, the next as soon as
it is free; ``/dispatch/assignment`` (std_msgs/String, latched: a line per robot driving, e.g.
"robot_2 -> goal 3 (3.00, 4.50) 7.35 m", then the goals waiting).

Parameters: ``~world`` (the run's world file: robots and map), ``~policy`` (hungarian,
round_robin), ``~cost`` (grid, default: the shortest way through the world's map; plan: the length of the
plan of the robot's own move_base ``make_plan`` service from where it stands, with its teammates
where they stand now),
``~stuck_timeout`` (30 s sim: a robot that has not moved 0.1 m for so long, unless it is within
0.5 m of its goal, or whose pose is lost, has its goal cancelled and given to another robot).
"""
import functools
import math
import threading

import numpy as np
import rospy

from mbot_common.geometry import yaw_of
from mbot_common.world import load_world
from mbot_follower.fleet_io import StalePose, lookup_pose
from mbot_follower.free_space import FreeSpace
from mbot_bringup.dispatch import DispatchConfig, DispatchError, DispatchQueue, path_length_table

MAX_POSE_AGE = 1.0   # [s sim] an older robot pose does not count: that robot gets no goal
COSTS = ("plan", "grid")
PROGRESS = 0.1       # [m] a robot that moved less than this is not progressing
NEAR_GOAL = 0.5      # [m] ... unless it is this close to its goal: it is finishing (turning, settling)
SUCCEEDED = 3        # actionlib GoalStatus


def plan_length(poses):
    """Length [m] of a nav_msgs/Path's poses; inf for an empty plan (no way)."""
    if not poses:
        return math.inf
    xy = np.array([(p.pose.position.x, p.pose.position.y) for p in poses])
    return float(np.sum(np.hypot(*np.diff(xy, axis=0).T))) if len(xy) > 1 else 0.0


class DispatcherNode(object):
    def __init__(self, world_file, policy="hungarian", cost="grid", stuck_timeout=30.0):
        import actionlib
        import tf2_ros
        from geometry_msgs.msg import PoseArray
        from move_base_msgs.msg import MoveBaseAction
        from std_msgs.msg import String

        if cost not in COSTS:
            raise DispatchError("unknown ~cost %r: expected one of %s" % (cost, ", ".join(COSTS)))
        self.world = load_world(world_file)
        self.robots = [r.name for r in self.world.robots]
        self.queue = DispatchQueue(self.robots, policy)   # DispatchError on an unknown policy
        self.cost = cost
        self.stuck_timeout = stuck_timeout
        m = self.world.map_data
        self.space = FreeSpace(m.occupancy, m.resolution, m.origin[:2],
                               DispatchConfig().robot_radius + DispatchConfig().margin)
        self.buffer = tf2_ros.Buffer()
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.clients = {r: actionlib.SimpleActionClient("/%s/move_base" % r, MoveBaseAction) for r in self.robots}
        self.lock = threading.RLock()
        self.poses = {}        # robot -> its newest (x, y)
        self.unlocated = set()  # robots whose pose was missing the last time (said once)
        self.progress = {}     # robot -> (sim time, (x, y)) when it last moved PROGRESS while driving
        self.String = String
        self.pub = rospy.Publisher("/dispatch/assignment", String, queue_size=1, latch=True)
        rospy.Subscriber("/dispatch/goals", PoseArray, self.on_goals, queue_size=10)
        # Goals are sent from a thread of the node's own: actionlib's SimpleActionClient (Noetic
        # 1.13) marks its goal DONE after the done callback returns, so a goal sent from inside
        # that callback would be marked done at once and its own result never reported.
        self.work = threading.Event()
        threading.Thread(target=self._work, name="dispatch", daemon=True).start()
        self.timer = rospy.Timer(rospy.Duration(1.0), self.check)
        rospy.loginfo("dispatcher: %d robots (%s), policy %s, cost %s", len(self.robots), ", ".join(self.robots),
                      policy, cost)

    # --- input -------------------------------------------------------------------------------

    def on_goals(self, msg):
        if msg.header.frame_id.lstrip("/") not in ("map", ""):
            rospy.logerr("dispatcher: /dispatch/goals: expected frame map, got %r; ignored", msg.header.frame_id)
            return
        goals = []
        for k, p in enumerate(msg.poses):
            x, y = p.position.x, p.position.y
            yaw = yaw_of(p.orientation) if all(math.isfinite(v) for v in (p.orientation.z, p.orientation.w)) \
                else math.nan
            if not all(math.isfinite(v) for v in (x, y, yaw)):
                rospy.logerr("dispatcher: goal %d of the message (%r, %r) is not a finite pose; refused", k, x, y)
            elif not self.space.is_free(x, y):
                rospy.logerr("dispatcher: goal %d of the message (%.2f, %.2f) is in a wall or too close to one "
                             "(the map, robot radius + margin); refused", k, x, y)
            else:
                goals.append((x, y, yaw))
        with self.lock:
            added = self.queue.add(goals)
            if added:
                rospy.loginfo("dispatcher: queued %s", ", ".join(map(repr, added)))
        self.work.set()

    # --- choosing ----------------------------------------------------------------------------

    def _locate(self):
        """{robot: (x, y)} of the robots whose pose is current. A robot's pose lost or found again
        is said once (while goals wait or robots drive)."""
        now = rospy.Time.now()
        found = {}
        for r in self.robots:
            try:
                pose, _ = lookup_pose(self.buffer, "map", "%s/base_link" % r, now, MAX_POSE_AGE)
            except StalePose as error:
                if r not in self.unlocated:
                    self.unlocated.add(r)
                    rospy.logwarn("dispatcher: %s gets no goal while its pose is unknown: %s", r, error)
                continue
            if r in self.unlocated:
                self.unlocated.discard(r)
                rospy.loginfo("dispatcher: %s located again", r)
            found[r] = (pose.x, pose.y)
        self.poses = found
        return found

    def _costs(self, robots, goals):
        """Table robots x goals [m]: each robot's way to each goal, inf where it has none."""
        if self.cost == "grid":
            return path_length_table(self.space.free, self.space.resolution, self.space.origin_xy,
                                     [self.poses[r] for r in robots], [(g.x, g.y) for g in goals])
        table = np.full((len(robots), len(goals)), np.inf)
        for i, r in enumerate(robots):
            for j, g in enumerate(goals):
                table[i, j] = self._plan_length(r, self.poses[r], g)
        return table

    def _plan_length(self, robot, start, goal):
        from nav_msgs.srv import GetPlan

        name = "/%s/move_base/make_plan" % robot
        try:
            rospy.wait_for_service(name, timeout=5.0)
            request = GetPlan._request_class()
            for stamped, (x, y) in ((request.start, start), (request.goal, (goal.x, goal.y))):
                stamped.header.frame_id = "map"
                stamped.pose.position.x, stamped.pose.position.y = x, y
                stamped.pose.orientation.w = 1.0
            request.tolerance = 0.0
            return plan_length(rospy.ServiceProxy(name, GetPlan)(request).plan.poses)
        except (rospy.ROSException, rospy.ServiceException) as error:
            rospy.logwarn("dispatcher: %s: no plan to %r (%s): it does not get that goal", name, goal, error)
            return math.inf

    def _work(self):
        while not rospy.is_shutdown():
            if self.work.wait(0.5):
                self.work.clear()
                with self.lock:
                    self.dispatch()

    def dispatch(self):
        """Give the waiting goals to the free robots (under the lock; in the dispatch thread)."""
        poses = self._locate()
        free = self.queue.free_robots(poses)
        given = self.queue.assign(free, self._costs) if free and self.queue.pending else []
        from mbot_navigation.move_base_client import make_goal

        for robot, goal, cost in given:
            if not self.clients[robot].wait_for_server(rospy.Duration(5.0)):
                rospy.logerr("dispatcher: no move_base server for %s; %r back in the queue", robot, goal)
                self.queue.done(robot, False)
                continue
            self.progress[robot] = (rospy.get_time(), poses[robot])
            self.clients[robot].send_goal(make_goal(goal.x, goal.y, goal.yaw),
                                          done_cb=functools.partial(self.on_done, robot, goal))
            rospy.loginfo("dispatcher: %s -> %r, %.2f m", robot, goal, cost)
        self._publish()

    def _publish(self):
        lines = ["%s -> %r" % (r, g) for r, g in sorted(self.queue.active.items())]
        lines += ["waiting: %r" % g for g in self.queue.pending]
        self.pub.publish(self.String("\n".join(lines)))

    # --- results and failures ----------------------------------------------------------------

    def on_done(self, robot, goal, state, _result):
        with self.lock:
            if self.queue.active.get(robot) is not goal:
                return   # cancelled by check() and handed on already
            succeeded = state == SUCCEEDED
            dropped = self.queue.done(robot, succeeded)
            if not succeeded:
                rospy.logwarn("dispatcher: %s did not reach %r (move_base state %d)%s", robot, goal, state,
                              "; dropped: " + dropped if dropped else "; back in the queue for the others")
            self._publish()
        self.work.set()

    def check(self, _event=None):
        """Every second: a driving robot that is lost or stuck gives its goal back."""
        with self.lock:
            if not self.queue.active and not self.queue.pending:
                return
            poses = self._locate()
            now = rospy.get_time()
            changed = False
            for robot in list(self.queue.active):
                goal = self.queue.active[robot]
                since, where = self.progress.get(robot, (now, poses.get(robot)))
                here = poses.get(robot)
                if here is not None and (where is None or math.dist(here, where) >= PROGRESS):
                    self.progress[robot] = (now, here)
                    continue
                if now - since < self.stuck_timeout:
                    continue
                if here is not None and math.dist(here, (goal.x, goal.y)) < NEAR_GOAL:
                    continue   # at its goal, move_base still finishing: giving the goal away would be worse
                why = "lost (no pose)" if here is None else "stuck (moved < %.1f m)" % PROGRESS
                rospy.logwarn("dispatcher: %s %s for %.0f s: %r goes to another robot", robot, why, now - since, goal)
                self.clients[robot].cancel_goal()
                dropped = self.queue.done(robot, False)
                if dropped:
                    rospy.logerr("dispatcher: %r dropped: %s", goal, dropped)
                changed = True
            if changed or self.queue.pending:
                self.work.set()


def main():
    rospy.init_node("dispatcher")
    world_file = rospy.get_param("~world", "")
    if not world_file:
        rospy.logfatal("dispatcher: set ~world (the world file of the run)")
        raise SystemExit(1)
    try:
        DispatcherNode(world_file, rospy.get_param("~policy", "hungarian"), rospy.get_param("~cost", "grid"),
                       float(rospy.get_param("~stuck_timeout", 30.0)))
    except DispatchError as error:
        rospy.logfatal("dispatcher: %s", error)
        raise SystemExit(1)
    rospy.spin()
