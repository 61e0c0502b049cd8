"""rviz screenshots during a scenario: taken in a thread (the timeline never waits), a blank one
(rviz not drawn yet) taken again, the simulator paused while one is taken (SimPause)."""
import contextlib
import os
import subprocess
import threading
import time

from mbot_bringup.console import say


def view_drawn(path, background=(48, 48, 48), share=0.05):
    """True when rviz has drawn its view: at least `share` of the middle of the screenshot differs
    from the view's empty background (fleet.rviz: 48, 48, 48). The toolbar's icons alone have
    many colours, so counting colours over the whole window does not tell."""
    import matplotlib.image as mpimg
    import numpy as np

    img = mpimg.imread(path)[..., :3]
    h, w = img.shape[:2]
    middle = img[h // 10: h - h // 10, w // 10: w - w // 10]
    if middle.dtype != np.uint8:
        middle = (middle * 255).astype(np.uint8)
    differs = np.abs(middle.astype(int) - np.array(background)).max(axis=2) > 30
    return differs.mean() >= share


class SimPause(object):
    """`with SimPause(settle)():` the simulator paused (/pause_physics), `settle` s of wall time
    for rviz to draw what it has, then the body (the capture), then /unpause_physics whatever
    happened. A simulator that does not answer is not waited for: the shot is taken anyway."""

    def __init__(self, settle=1.5, timeout=5.0):
        self.settle = settle     # [s wall] rviz draws 2-5 frames per second with software GL
        self.timeout = timeout   # [s wall] for the services to appear

    @contextlib.contextmanager
    def __call__(self):
        import rospy
        from std_srvs.srv import Empty

        paused = False
        try:
            rospy.wait_for_service("/pause_physics", self.timeout)
            rospy.ServiceProxy("/pause_physics", Empty)()
            paused = True
            time.sleep(self.settle)
        except (rospy.ROSException, rospy.ServiceException) as error:
            say("screenshot: could not pause the simulator (%s); taking it anyway" % error)
        try:
            yield
        finally:
            if paused:
                try:
                    rospy.ServiceProxy("/unpause_physics", Empty)()
                except rospy.ServiceException as error:
                    say("screenshot: could not unpause the simulator: %s" % error)


class Screenshots(object):
    """Takes rviz screenshots of the X display in a thread, so the timeline never waits for one.
    A blank image (rviz not drawn yet) is taken again, up to `attempts` times `retry` s apart.
    With `hold` (a context manager factory, e.g. SimPause), the simulator stands still while a
    shot is taken: at real_time_factor 0 sim time runs many times faster than software GL draws,
    and rviz would show a moment seconds old."""

    def __init__(self, display, directory, attempts=4, retry=3.0, hold=None):
        self.display = display
        self.directory = directory
        self.attempts = attempts
        self.retry = retry               # [s wall]
        self.hold = hold
        self.taken = []                  # paths of the good ones
        self.names = set()
        self.queue = []
        self.cv = threading.Condition()
        self.closed = False
        os.makedirs(directory, exist_ok=True)
        self.thread = threading.Thread(target=self._work, daemon=True)
        self.thread.start()

    def request(self, name):
        """Queue a screenshot NAME.png (NAME_2.png ... when the name was used)."""
        unique, k = name, 2
        while unique in self.names:
            unique, k = "%s_%d" % (name, k), k + 1
        self.names.add(unique)
        with self.cv:
            self.queue.append(unique)
            self.cv.notify()

    def wait_drawn(self, wall_timeout=90.0):
        """Wait until rviz shows the map (software GL takes its time), so that the screenshots
        show the moments they are named after. False if it does not within wall_timeout s."""
        from mbot_bringup.screenshot import capture

        path = os.path.join(self.directory, ".probe.png")
        end = time.time() + wall_timeout
        drawn = False
        while time.time() < end and not drawn:
            try:
                capture(self.display, path)
                drawn = view_drawn(path)
            except (subprocess.SubprocessError, OSError):
                pass
            if not drawn:
                time.sleep(1.0)
        if os.path.exists(path):
            os.remove(path)
        return drawn

    def _work(self):
        from mbot_bringup.screenshot import capture

        while True:
            with self.cv:
                while not self.queue and not self.closed:
                    self.cv.wait()
                if not self.queue:
                    return
                name = self.queue[0]
            path = os.path.join(self.directory, name + ".png")
            for attempt in range(self.attempts):
                try:
                    hold = self.hold() if self.hold is not None else contextlib.nullcontext()
                    with hold:
                        capture(self.display, path)
                    if view_drawn(path):
                        self.taken.append(path)
                        break
                except (subprocess.SubprocessError, OSError) as error:
                    say("screenshot %s failed: %s" % (name, error))
                time.sleep(self.retry)
            else:
                if os.path.exists(path):
                    os.remove(path)
                say("screenshot %s: rviz showed nothing after %d tries; none kept" % (name, self.attempts))
            with self.cv:
                self.queue.pop(0)
                self.cv.notify_all()

    def close(self, wall_timeout=90.0):
        """Finish the queued screenshots (at most wall_timeout s) and stop the thread."""
        with self.cv:
            self.closed = True
            self.cv.notify_all()
        self.thread.join(wall_timeout)
