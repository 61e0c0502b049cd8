#!/usr/bin/env python3
"""rostest: the nav node's services and action feedback, called as an outside client would
(robot_0 in the office, test/fixtures/worlds/nav_office.world.yaml): action feedback while driving,
~make_plan with and without its tolerance search, and ~clear_costmaps forgetting what the laser
marked while the map stays.

For clear_costmaps the test adds a laser beam of its own (on /robot_0/scan, beside the
simulator's scans) that ends behind a wall: the mark it leaves there is never cleared by the real
beams, which stop at the wall, so only clear_costmaps can take it away."""
import math
import threading
import unittest

import rospy
import rostest
import tf2_ros
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import PoseStamped
from nav_msgs.msg import OccupancyGrid, Odometry
from nav_msgs.srv import GetPlan, GetPlanRequest
from sensor_msgs.msg import LaserScan
from std_srvs.srv import Empty

from mbot_common.geometry import normalize_angle, yaw_of
from mbot_common.waits import wait_for_wall
from nav_test_tools import Track, action_client, make_goal, state_name, wait_until

ROBOT = "robot_0"
START = (3.0, -4.0)             # the world file's
NEAR_WALL = (1.2, -3.0, 0.0)    # 1 m east of the wall x = 0 .. 0.2 that separates two rooms
PHANTOM = (-0.6, -3.0)          # behind that wall, in free space of the map, 1.8 m from the robot


class Costmap(object):
    """The latest /robot_0/move_base/global_costmap/costmap and how many have arrived."""

    def __init__(self):
        self._lock = threading.Lock()
        self.msg, self.count = None, 0
        rospy.Subscriber("/%s/move_base/global_costmap/costmap" % ROBOT, OccupancyGrid, self._on_grid, queue_size=1)

    def _on_grid(self, msg):
        with self._lock:
            self.msg, self.count = msg, self.count + 1

    def value(self, x, y):
        m = self.msg
        i = int((x - m.info.origin.position.x) / m.info.resolution)
        j = int((y - m.info.origin.position.y) / m.info.resolution)
        return m.data[j * m.info.width + i]

    def centre(self, x, y):
        """The centre of the cell that holds (x, y). A beam aimed at a cell corner (such as the
        round (-0.6, -3.0)) ends in any of four cells, as float32 ranges and angles round."""
        m = self.msg
        res, ox, oy = m.info.resolution, m.info.origin.position.x, m.info.origin.position.y
        return (ox + (int((x - ox) / res) + 0.5) * res, oy + (int((y - oy) / res) + 0.5) * res)

    def after(self, n):
        """True once the n-th message after now has arrived."""
        seen = self.count
        return lambda: self.count >= seen + n


class Truth(object):
    """The robot's ground-truth positions by stamp, to compare a feedback pose with."""

    def __init__(self):
        self._lock = threading.Lock()
        self.samples = []  # (stamp [s], x, y)
        rospy.Subscriber("/%s/base_pose_ground_truth" % ROBOT, Odometry, self._on_odom, queue_size=100)

    def _on_odom(self, msg):
        with self._lock:
            self.samples.append((msg.header.stamp.to_sec(), msg.pose.pose.position.x, msg.pose.pose.position.y))

    def at(self, stamp):
        with self._lock:
            return min(self.samples, key=lambda s: abs(s[0] - stamp))


def phantom_scan(tf_buffer, x, y):
    """A LaserScan of one beam from robot_0's laser to (x, y) in map, at the laser's latest pose."""
    t = tf_buffer.lookup_transform("map", "%s/base_laser" % ROBOT, rospy.Time(0), rospy.Duration(1.0))
    lx, ly = t.transform.translation.x, t.transform.translation.y
    bearing = math.atan2(y - ly, x - lx) - yaw_of(t.transform.rotation)
    scan = LaserScan()
    scan.header.frame_id = "%s/base_laser" % ROBOT
    scan.header.stamp = t.header.stamp
    scan.angle_min = scan.angle_max = normalize_angle(bearing)
    scan.angle_increment = 0.01
    scan.range_min, scan.range_max = 0.12, 8.0
    scan.ranges = [math.hypot(x - lx, y - ly)]
    return scan


def nearest_wall(grid, x, y):
    """The centre of the occupied map cell nearest to (x, y)."""
    info = grid.info
    best = None
    for j in range(info.height):
        for i in range(info.width):
            if grid.data[j * info.width + i] >= 65:
                wx = info.origin.position.x + (i + 0.5) * info.resolution
                wy = info.origin.position.y + (j + 0.5) * info.resolution
                d = math.hypot(wx - x, wy - y)
                if best is None or d < best[0]:
                    best = (d, wx, wy)
    return best[1], best[2]


class NavServices(unittest.TestCase):
    def test_services_and_feedback(self):
        grid = rospy.wait_for_message("/map", OccupancyGrid, timeout=60.0)
        track = Track(ROBOT)
        costmap = Costmap()
        client = action_client(ROBOT)
        track.wait()

        # --- feedback: while driving, at about the control rate, in map, where the robot is
        truth = Truth()
        feedback = []  # (stamp, x, y, frame)

        def on_feedback(fb):
            p = fb.base_position.pose.position
            feedback.append((fb.base_position.header.stamp.to_sec(), p.x, p.y, fb.base_position.header.frame_id))

        start = rospy.Time.now()
        client.send_goal(make_goal(*NEAR_WALL), feedback_cb=on_feedback)
        self.assertTrue(client.wait_for_result(rospy.Duration(90.0)), "no result within 90 sim s")
        self.assertEqual(client.get_state(), GoalStatus.SUCCEEDED,
                         "%s: %s" % (state_name(client.get_state()), client.get_goal_status_text()))
        seconds = (rospy.Time.now() - start).to_sec()
        self.assertGreater(len(feedback), 5.0 * seconds, "%d feedback messages in %.1f sim s (20 Hz control)"
                           % (len(feedback), seconds))
        self.assertTrue(all(f[3] == "map" for f in feedback), set(f[3] for f in feedback))
        # Each feedback is the robot's pose of its cycle: the ground truth at its stamp (fake
        # localization is exact: tf pairs truth and odometry by stamp).
        worst = 0.0
        for f in feedback:
            t = truth.at(f[0])
            worst = max(worst, math.hypot(f[1] - t[1], f[2] - t[2]))
        self.assertLess(worst, 0.03, "feedback up to %.3f m off the ground truth at its stamp" % worst)
        first, last = feedback[0], feedback[-1]
        self.assertLess(math.hypot(first[1] - START[0], first[2] - START[1]), 0.3, first)
        self.assertLess(math.hypot(last[1] - NEAR_WALL[0], last[2] - NEAR_WALL[1]), 0.3, last)

        # --- make_plan, from the robot (empty start frame), to a goal in a wall of the map
        make_plan = rospy.ServiceProxy("/%s/move_base/make_plan" % ROBOT, GetPlan)
        make_plan.wait_for_service(30.0)
        wall_x, wall_y = nearest_wall(grid, *track.pose[:2])
        request = GetPlanRequest()
        request.goal = PoseStamped()
        request.goal.header.frame_id = "map"
        request.goal.pose.position.x, request.goal.pose.position.y = wall_x, wall_y
        request.goal.pose.orientation.w = 1.0
        request.tolerance = 0.0
        self.assertEqual(len(make_plan(request).plan.poses), 0, "a plan into the wall at (%.2f, %.2f)"
                         % (wall_x, wall_y))
        request.tolerance = 0.6
        plan = make_plan(request).plan
        self.assertGreater(len(plan.poses), 1, "no plan within 0.6 m of the wall cell (%.2f, %.2f)" % (wall_x, wall_y))
        self.assertEqual(plan.header.frame_id, "map")
        p0, pn = plan.poses[0].pose.position, plan.poses[-1].pose.position
        x, y, _ = track.pose
        self.assertLess(math.hypot(p0.x - x, p0.y - y), 0.1, "the plan starts at (%.2f, %.2f), robot at (%.2f, %.2f)"
                        % (p0.x, p0.y, x, y))
        end_off = math.hypot(pn.x - wall_x, pn.y - wall_y)
        self.assertLessEqual(end_off, 0.6 + 1e-6, "the plan ends %.2f m from the requested goal" % end_off)
        self.assertLess(costmap.value(pn.x, pn.y), 99, "the plan ends in an obstacle (%.2f, %.2f)" % (pn.x, pn.y))
        # A start given explicitly is used
        request.start.header.frame_id = "map"
        request.start.pose.position.x, request.start.pose.position.y = START
        request.start.pose.orientation.w = 1.0
        plan = make_plan(request).plan
        self.assertGreater(len(plan.poses), 1)
        p0 = plan.poses[0].pose.position
        self.assertLess(math.hypot(p0.x - START[0], p0.y - START[1]), 0.1, (p0.x, p0.y))

        # --- a laser mark behind the wall, where the simulator's beams never reach
        tf_buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(tf_buffer)  # noqa: F841 (kept while the test runs)
        scan_pub = rospy.Publisher("/%s/scan" % ROBOT, LaserScan, queue_size=5)
        phantom = costmap.centre(*PHANTOM)
        self.assertLess(costmap.value(*phantom), 99, "(%.3f, %.3f) should be free before" % phantom)
        wait_for_wall(lambda: scan_pub.get_num_connections() > 0, 30.0, "the nav node to take our scans")
        tf_buffer.lookup_transform("map", "%s/base_laser" % ROBOT, rospy.Time(0), rospy.Duration(30.0))

        def marked():
            scan_pub.publish(phantom_scan(tf_buffer, *phantom))
            return costmap.value(*phantom) == 100

        wait_until(marked, 60.0, "the extra beam's mark at (%.3f, %.3f) in the global costmap" % phantom,
                   period=0.1)  # a scan per poll: at the laser's rate
        wait_until(costmap.after(2), 10.0, "two more global costmaps")
        self.assertEqual(costmap.value(*phantom), 100, "the mark should stay (no beam of the simulator gets there)")

        # --- clear_costmaps: the mark goes, the map's wall stays
        clear = rospy.ServiceProxy("/%s/move_base/clear_costmaps" % ROBOT, Empty)
        clear.wait_for_service(10.0)
        clear()
        wait_until(costmap.after(2), 10.0, "two more global costmaps")
        self.assertLess(costmap.value(*phantom), 99, "the mark at (%.3f, %.3f) is still there" % phantom)
        self.assertEqual(costmap.value(wall_x, wall_y), 100, "the map's wall went too")


if __name__ == "__main__":
    rospy.init_node("nav_services_test")
    rostest.rosrun("mbot_navigation", "nav_services", NavServices)
