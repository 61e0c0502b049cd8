"""Waiting on the wall clock for something outside sim time (a node coming up, a connection):
tests use it where sim time may not run yet."""
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
