"""Helpers shared by the localization rostests (test_fake_localization.py, test_pf_localization.py).
Those tests publish /clock themselves, so they wait on the wall clock: sim time only moves when
the test publishes it."""
import time


def wait_for_wall(condition, timeout, what):
    """Poll `condition` on the wall clock every 0.01 s for up to `timeout` seconds."""
    deadline = time.time() + timeout
    while time.time() < deadline:
        if condition():
            return
        time.sleep(0.01)
    raise AssertionError("timed out after %.0f s waiting for %s" % (timeout, what))
