"""screenshot node: at `~at` sim seconds after start, capture `~display` into `~output`."""
import os
import time

import rospy

from mbot_bringup.screenshot import capture, looks_rendered


def main():
    rospy.init_node("screenshot")
    at = rospy.get_param("~at", 10.0)              # [s sim time]
    output = rospy.get_param("~output")
    display = rospy.get_param("~display", os.environ.get("DISPLAY", ":0"))
    retries = rospy.get_param("~retries", 5)       # rviz may still be loading
    while rospy.Time.now().is_zero() and not rospy.is_shutdown():
        time.sleep(0.01)
    rospy.sleep(at)
    for attempt in range(retries):
        capture(display, output)
        if looks_rendered(output):
            rospy.loginfo("screenshot: %s", output)
            return
        rospy.logwarn("screenshot: display %s looks blank (attempt %d), retrying", display, attempt + 1)
        time.sleep(2.0)  # wall time: rviz renders in wall time
    rospy.logerr("screenshot: %s still looks blank after %d attempts", output, retries)
