"""Bounded waits on a condition, for tests.

wait_for_sim waits in sim time (what an integration test measures in); wait_for_wall waits on the
wall clock, for what happens outside sim time (a node coming up, a connection, or tests that
publish /clock themselves)."""
import time


def wait_for_wall(condition, timeout, what, period=0.01):
    """Poll `condition` every `period` seconds (wall) for up to `timeout` seconds; AssertionError
    naming `what` when it never held."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        if condition():
            return
        time.sleep(period)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))


def wait_for_sim(condition, timeout, what, period=0.01, stall_timeout=30.0):
    """Poll `condition` every `period` seconds of sim time for up to `timeout` sim seconds;
    AssertionError naming `what` when it never held, or when sim time stood still for
    `stall_timeout` seconds of wall time (a simulator that died or is paused)."""
    import rospy  # here: the module stays importable without ROS for wait_for_wall
    deadline = rospy.get_time() + timeout
    while not rospy.is_shutdown():
        if condition():
            return
        now = rospy.get_time()
        if now >= deadline:
            raise AssertionError("timed out after %.1f sim s waiting for %s" % (timeout, what))
        # (not rospy.sleep: it blocks for as long as sim time stands still)
        stalled_at = time.time() + stall_timeout
        while rospy.get_time() < now + period and not rospy.is_shutdown():
            if time.time() > stalled_at:
                raise AssertionError("sim time stood still at %.2f s for %.0f s wall while waiting for %s"
                                     % (rospy.get_time(), stall_timeout, what))
            time.sleep(0.002)
    raise AssertionError("shut down while waiting for %s" % what)
