"""Node ``dispatcher``: sends every robot of a fleet its own move_base goal, chosen centrally
(dispatch.py: least total path length, Hungarian method). No formation: fleet.launch mode:=dispatch.

Input: ``/dispatch/goals`` (geometry_msgs/PoseArray in the map frame, at most one goal per robot);
the robots' poses from tf2 (``map -> <robot>/base_link``). Output: one goal per chosen robot
on its ``/<robot>/move_base`` action, and ``/dispatch/assignment`` (std_msgs/String, latched: one
line per goal, "robot_2 -> (3.00, 4.50) 7.35 m"). Parameter ``~world``: the world file (its map
and robots).
"""
import threading

import rospy

from mbot_common.geometry import yaw_of
from mbot_common.world import load_world
from mbot_follower.fleet_io import StalePose, lookup_pose
from mbot_bringup.dispatch import DispatchError, dispatch

MAX_POSE_AGE = 1.0   # [s sim] an older robot pose does not count: that robot gets no goal


class DispatcherNode(object):
    def __init__(self, world_file):
        import actionlib
        import tf2_ros
        from geometry_msgs.msg import PoseArray
        from move_base_msgs.msg import MoveBaseAction
        from std_msgs.msg import String

        self.world = load_world(world_file)
        self.robots = [r.name for r in self.world.robots]
        self.buffer = tf2_ros.Buffer()
        self.listener = tf2_ros.TransformListener(self.buffer)
        self.clients = {r: actionlib.SimpleActionClient("/%s/move_base" % r, MoveBaseAction) for r in self.robots}
        self.lock = threading.Lock()
        self.String = String
        self.pub = rospy.Publisher("/dispatch/assignment", String, queue_size=1, latch=True)
        rospy.Subscriber("/dispatch/goals", PoseArray, self.on_goals, queue_size=1)
        rospy.loginfo("dispatcher: %d robots (%s)", len(self.robots), ", ".join(self.robots))

    def on_goals(self, msg):
        from mbot_navigation.move_base_client import make_goal

        if msg.header.frame_id.lstrip("/") not in ("map", ""):
            rospy.logerr("dispatcher: /dispatch/goals: expected frame map, got %r; ignored", msg.header.frame_id)
            return
        goals = [(p.position.x, p.position.y, yaw_of(p.orientation)) for p in msg.poses]
        with self.lock:
            now = rospy.Time.now()
            names, positions = [], []
            for r in self.robots:
                try:
                    pose, _ = lookup_pose(self.buffer, "map", "%s/base_link" % r, now, MAX_POSE_AGE)
                except StalePose as error:
                    rospy.logwarn("dispatcher: %s gets no goal: %s", r, error)
                    continue
                names.append(r)
                positions.append((pose.x, pose.y))
            try:
                chosen, table = dispatch(self.world.map_data, self.world.map_data.occupancy, positions,
                                         [(g[0], g[1]) for g in goals])
            except DispatchError as error:
                rospy.logerr("dispatcher: %d goals refused: %s", len(goals), error)
                self.pub.publish(self.String("refused: %s" % error))
                return
            lines = []
            for j, i in sorted(chosen.items()):
                robot = names[i]
                x, y, yaw = goals[j]
                if not self.clients[robot].wait_for_server(rospy.Duration(5.0)):
                    rospy.logerr("dispatcher: no move_base server for %s; goal %d not sent", robot, j)
                    continue
                self.clients[robot].send_goal(make_goal(x, y, yaw))
                lines.append("%s -> (%.2f, %.2f) %.2f m" % (robot, x, y, table[i, j]))
            total = sum(table[i, j] for j, i in chosen.items())
            rospy.loginfo("dispatcher: %d goals, %.2f m of paths in all:\n  %s", len(lines), total, "\n  ".join(lines))
            self.pub.publish(self.String("\n".join(lines)))


def main():
    rospy.init_node("dispatcher")
    world_file = rospy.get_param("~world", "")
    if not world_file:
        rospy.logfatal("dispatcher: set ~world (the world file of the run)")
        raise SystemExit(1)
    DispatcherNode(world_file)
    rospy.spin()
