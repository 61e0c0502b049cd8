"""demo_drive node: every robot of the simulation wanders (one process for the whole fleet)."""
import rospy
from geometry_msgs.msg import Twist
from sensor_msgs.msg import LaserScan

from mbot_bringup.fleet_topics import discover_robots
from mbot_bringup.wander import WanderConfig, wander_command


class FleetWander(object):
    def __init__(self, config):
        self.config = config
        self.publishers = {}
        self.subscribers = {}

    def attach_new_robots(self):
        for name in discover_robots("/scan"):
            if name in self.publishers:
                continue
            rospy.loginfo("demo_drive: driving %s", name)
            self.publishers[name] = rospy.Publisher("/%s/cmd_vel" % name, Twist, queue_size=1)
            self.subscribers[name] = rospy.Subscriber(
                "/%s/scan" % name, LaserScan, self.on_scan, callback_args=name, queue_size=1)

    def on_scan(self, scan, name):
        v, w = wander_command(scan.ranges, scan.angle_min, scan.angle_increment, self.config)
        cmd = Twist()
        cmd.linear.x = v
        cmd.angular.z = w
        self.publishers[name].publish(cmd)


def main():
    rospy.init_node("demo_drive")
    config = WanderConfig(speed=rospy.get_param("~speed", 0.3),
                          safe_distance=rospy.get_param("~safe_distance", 0.6))
    fleet = FleetWander(config)
    # Robots may be spawned later: look for new ones every sim second.
    rospy.Timer(rospy.Duration(1.0), lambda _event: fleet.attach_new_robots())
    fleet.attach_new_robots()
    rospy.spin()
