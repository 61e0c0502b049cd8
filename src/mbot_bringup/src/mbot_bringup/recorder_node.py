"""recorder node: records what the simulation does for `~duration` sim seconds, prints a summary,
writes `~output` (JSON) and shuts down (mark it required in a launch file to end the run)."""
import functools
import threading
import time

import rospy
from mbot_msgs.msg import Contact
from move_base_msgs.msg import MoveBaseActionGoal, MoveBaseActionResult
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from mbot_bringup.fleet_topics import discover_robots
from mbot_bringup.goal_tour import STATUS_NAMES
from mbot_bringup.recording import Recording
from mbot_common.geometry import yaw_of


def locked(method):
    """Run a callback under the recorder's lock, and not at all once the recording is closed
    (subscriber threads may still deliver messages while the node saves and shuts down)."""
    @functools.wraps(method)
    def wrapper(self, *args):
        with self.lock:
            if not self.closed:
                method(self, *args)
    return wrapper


class Recorder(object):
    def __init__(self, recording):
        self.rec = recording
        self.subs = {}
        self.lock = threading.Lock()
        self.closed = False

    def close(self):
        with self.lock:
            self.closed = True

    def attach_new_robots(self):
        for name in discover_robots("/base_pose_ground_truth"):
            if name in self.subs:
                continue
            self.subs[name] = [
                rospy.Subscriber("/%s/base_pose_ground_truth" % name, Odometry, self.on_truth, name),
                rospy.Subscriber("/%s/odom" % name, Odometry, self.on_odom, name),
                rospy.Subscriber("/%s/scan" % name, LaserScan, self.on_scan, name),
                # Any move_base client (demo tour, rviz, a user's script) shows up here.
                rospy.Subscriber("/%s/move_base/goal" % name, MoveBaseActionGoal, self.on_goal, name),
                rospy.Subscriber("/%s/move_base/result" % name, MoveBaseActionResult, self.on_result, name),
            ]

    @locked
    def on_truth(self, msg, name):
        p = msg.pose.pose
        self.rec.add_pose(name, msg.header.stamp.to_sec(), p.position.x, p.position.y, yaw_of(p.orientation))

    @locked
    def on_odom(self, msg, name):
        self.rec.add_odom(name, msg.header.stamp.to_sec())

    @locked
    def on_scan(self, msg, name):
        self.rec.add_scan(name, msg.header.stamp.to_sec(), msg.ranges)

    @locked
    def on_goal(self, msg, name):
        p = msg.goal.target_pose.pose.position
        self.rec.add_goal(name, rospy.Time.now().to_sec(), p.x, p.y)

    @locked
    def on_result(self, msg, name):
        self.rec.add_nav_result(name, msg.header.stamp.to_sec(),
                                STATUS_NAMES.get(msg.status.status, str(msg.status.status)), msg.status.text)

    @locked
    def on_contact(self, msg):
        self.rec.add_contact(msg.header.stamp.to_sec(), msg.body_a, msg.body_b,
                             msg.position.x, msg.position.y)


def main():
    rospy.init_node("recorder")
    duration = rospy.get_param("~duration", 20.0)  # [s sim time]
    output = rospy.get_param("~output", "")
    recorder = Recorder(Recording(world=rospy.get_param("~world", "")))
    rospy.Subscriber("/contacts", Contact, recorder.on_contact)
    rospy.Timer(rospy.Duration(1.0), lambda _event: recorder.attach_new_robots())
    recorder.attach_new_robots()

    while rospy.Time.now().is_zero() and not rospy.is_shutdown():
        time.sleep(0.01)  # wall sleep: waiting for the first /clock message
    start_wall = time.time()

    def finish():
        # Runs once: at the end of ~duration, or when the launch shuts down earlier (a required
        # node such as the goal tour finished).
        if getattr(finish, "done", False):
            return
        finish.done = True
        recorder.close()
        recorder.rec.wall_seconds = time.time() - start_wall
        for line in recorder.rec.summary_lines():
            print(line)
        if output:
            recorder.rec.save(output)
            print("recording: %s" % output)

    rospy.on_shutdown(finish)
    end = rospy.Time.now() + rospy.Duration(duration)
    while not rospy.is_shutdown() and rospy.Time.now() < end:
        try:
            rospy.sleep(0.1)
        except rospy.ROSInterruptException:
            break
    finish()
    rospy.signal_shutdown("recorded %.1f sim seconds" % duration)
