"""recorder node: records what the simulation does for `~duration` sim seconds, prints a summary,
writes `~output` (JSON) and shuts down (mark it required in a launch file to end the run)."""
import math
import time

import rospy
from mbot_msgs.msg import Contact
from nav_msgs.msg import Odometry
from sensor_msgs.msg import LaserScan

from mbot_bringup.fleet_topics import discover_robots
from mbot_bringup.recording import Recording


def yaw_of(q):
    return math.atan2(2.0 * (q.w * q.z + q.x * q.y), 1.0 - 2.0 * (q.y * q.y + q.z * q.z))


class Recorder(object):
    def __init__(self, recording):
        self.rec = recording
        self.subs = {}

    def attach_new_robots(self):
        for name in discover_robots("/base_pose_ground_truth"):
            if name in self.subs:
                continue
            self.subs[name] = [
                rospy.Subscriber("/%s/base_pose_ground_truth" % name, Odometry, self.on_truth, name),
                rospy.Subscriber("/%s/odom" % name, Odometry, self.on_odom, name),
                rospy.Subscriber("/%s/scan" % name, LaserScan, self.on_scan, name),
            ]

    def on_truth(self, msg, name):
        p = msg.pose.pose
        self.rec.add_pose(name, msg.header.stamp.to_sec(), p.position.x, p.position.y, yaw_of(p.orientation))

    def on_odom(self, msg, name):
        self.rec.add_odom(name, msg.header.stamp.to_sec())

    def on_scan(self, msg, name):
        self.rec.add_scan(name, msg.header.stamp.to_sec(), msg.ranges)

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
    end = rospy.Time.now() + rospy.Duration(duration)
    while not rospy.is_shutdown() and rospy.Time.now() < end:
        rospy.sleep(0.1)
    recorder.rec.wall_seconds = time.time() - start_wall

    for line in recorder.rec.summary_lines():
        print(line)
    if output:
        recorder.rec.save(output)
        print("recording: %s" % output)
    rospy.signal_shutdown("recorded %.1f sim seconds" % duration)
