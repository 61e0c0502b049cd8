#!/usr/bin/python3
"""rostest node for description.test: checks robot_3's description and frames."""
import unittest

import rospy
import rostest
import tf2_ros
from sensor_msgs.msg import JointState

ROBOT = "robot_3"


class DescriptionFrames(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.buffer = tf2_ros.Buffer()
        cls.listener = tf2_ros.TransformListener(cls.buffer)

    def lookup(self, parent, child, timeout=10.0):
        t = self.buffer.lookup_transform(
            ROBOT + "/" + parent, ROBOT + "/" + child, rospy.Time(0), rospy.Duration(timeout)
        )
        return t.transform.translation

    def test_description_is_prefixed(self):
        xml = rospy.get_param("/%s/robot_description" % ROBOT)
        self.assertIn('<link name="%s/base_link"' % ROBOT, xml)
        self.assertIn('<joint name="%s/left_wheel_joint"' % ROBOT, xml)
        self.assertNotIn('<link name="base_link"', xml)

    def test_fixed_frames(self):
        # urdf/mbot.urdf: base_link 0.04 m up, laser at (0.05, 0, 0.16) in base_footprint.
        base = self.lookup("base_footprint", "base_link")
        self.assertAlmostEqual(base.z, 0.04, places=6)
        laser = self.lookup("base_footprint", "base_laser")
        self.assertAlmostEqual(laser.x, 0.05, places=6)
        self.assertAlmostEqual(laser.y, 0.0, places=6)
        self.assertAlmostEqual(laser.z, 0.16, places=6)

    def test_wheels_follow_prefixed_joint_states(self):
        pub = rospy.Publisher("/%s/joint_states" % ROBOT, JointState, queue_size=1)
        deadline = rospy.Time.now() + rospy.Duration(10.0)
        left = None
        while left is None and rospy.Time.now() < deadline and not rospy.is_shutdown():
            msg = JointState()
            msg.header.stamp = rospy.Time.now()
            msg.name = [ROBOT + "/left_wheel_joint", ROBOT + "/right_wheel_joint"]
            msg.position = [0.3, -0.3]
            pub.publish(msg)
            try:
                left = self.lookup("base_link", "left_wheel", timeout=0.2)
            except tf2_ros.TransformException:
                pass
        self.assertIsNotNone(left, "no robot_3/base_link -> robot_3/left_wheel transform")
        self.assertAlmostEqual(left.y, 0.11, places=6)
        right = self.lookup("base_link", "right_wheel")
        self.assertAlmostEqual(right.y, -0.11, places=6)


if __name__ == "__main__":
    rospy.init_node("description_frames")
    rostest.rosrun("mbot_description", "description_frames", DescriptionFrames)
