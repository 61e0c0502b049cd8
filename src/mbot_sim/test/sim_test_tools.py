"""Shared helpers of the mbot_sim rostest nodes: message recorders, sim-time driving, the fixture map.

Everything waits in sim time (rospy.sleep, rospy.Rate with /use_sim_time); wall clock is used
only as a safety timeout while waiting for the simulator to come up.
"""
import math
import os
import threading
import time

import rospy
from mbot_common.waits import wait_for_sim as wait_until  # noqa: F401 (the tests import it from here)

FIXTURES = os.path.join(os.path.dirname(os.path.abspath(__file__)), "fixtures")


class Recorder(object):
    """Subscribes to a topic and keeps every message with the sim time it arrived at."""

    def __init__(self, topic, msg_type):
        self._lock = threading.Lock()
        self.messages = []  # (receive sim time [s], message)
        self.sub = rospy.Subscriber(topic, msg_type, self._callback, queue_size=1000)

    def _callback(self, msg):
        with self._lock:
            self.messages.append((rospy.get_time(), msg))

    def latest(self):
        with self._lock:
            return self.messages[-1][1] if self.messages else None

    def since(self, t):
        """Messages received at or after sim time t."""
        with self._lock:
            return [m for (rt, m) in self.messages if rt >= t]

    def stamped_after(self, t):
        """Messages whose header stamp is later than sim time t (measured after t)."""
        with self._lock:
            return [m for (_, m) in self.messages if m.header.stamp.to_sec() > t]

    def received_since(self, t):
        with self._lock:
            return [(rt, m) for (rt, m) in self.messages if rt >= t]

    def first_stamped_after(self, t, sim_timeout=5.0):
        """The first message whose header stamp is later than sim time t (waits for it)."""
        def first():
            with self._lock:
                return next((m for (_, m) in self.messages if m.header.stamp.to_sec() > t), None)

        wait_until(lambda: first() is not None, sim_timeout,
                   "a message on %s stamped after t = %.2f" % (self.sub.name, t))
        return first()

    def wait_for_first(self, wall_timeout=30.0):
        end = time.time() + wall_timeout
        while not rospy.is_shutdown() and time.time() < end:
            if self.latest() is not None:
                return self.latest()
            time.sleep(0.05)
        raise AssertionError("no message on %s within %.0f s (wall)" % (self.sub.name, wall_timeout))


def keep_pace(period=0.05):
    """Make this test node a pacer of the simulator's lockstep (launched with lockstep:=true): it
    sends its sim time on /lockstep/heartbeat every `period`, and sim time waits for it. On a
    busy machine a starved test process would otherwise fall seconds behind: the simulator's
    publisher queues drop messages it has not read yet, and a robot it drives is stopped by the
    watchdog between two of its commands."""
    from std_msgs.msg import Header

    pub = rospy.Publisher("/lockstep/heartbeat", Header, queue_size=10)
    name = rospy.get_name()
    return rospy.Timer(rospy.Duration(period), lambda _: pub.publish(Header(stamp=rospy.Time.now(), frame_id=name)))


def wait_for_connection(publisher, wall_timeout=10.0):
    end = time.time() + wall_timeout
    while publisher.get_num_connections() == 0 and time.time() < end:
        time.sleep(0.02)
    if publisher.get_num_connections() == 0:
        raise AssertionError("nobody subscribes to %s" % publisher.name)


def publish_for(publisher, msg, seconds, rate_hz=50.0):
    """Publish msg at rate_hz for `seconds` of sim time; return the sim time of the last one."""
    rate = rospy.Rate(rate_hz)
    start = rospy.get_time()
    last = start
    while not rospy.is_shutdown() and rospy.get_time() - start < seconds:
        publisher.publish(msg)
        last = rospy.get_time()
        rate.sleep()
    return last


def drive_until(publisher, cmd, condition, sim_timeout, rate_hz=20.0, stop=True):
    """Publish cmd at rate_hz (sim time) until condition() holds or sim_timeout passes; then a
    stop command unless stop=False.

    Robust against this process being starved for a while on a busy machine: the watchdog may
    stop the robot in between, but driving goes on until the condition holds.
    """
    from geometry_msgs.msg import Twist
    rate = rospy.Rate(rate_hz)
    deadline = rospy.get_time() + sim_timeout
    while not rospy.is_shutdown() and not condition() and rospy.get_time() < deadline:
        publisher.publish(cmd)
        rate.sleep()
    if stop:
        publisher.publish(Twist())


def load_pgm_map(yaml_name):
    """The fixture map as (occupied(ix, iy) -> bool, resolution, origin_x, origin_y, width, height),
    read by mbot_common.maps as map_server reads it (occupied: value 100)."""
    from mbot_common.maps import OCCUPIED, load_map
    m = load_map(os.path.join(FIXTURES, yaml_name))

    def occupied(ix, iy):
        return m.contains(ix, iy) and m.occupancy[iy, ix] == OCCUPIED

    return occupied, m.resolution, m.origin[0], m.origin[1], m.width, m.height


def map_range(occupied, res, ox, oy, x, y, angle, max_range):
    """Distance from (x, y) along `angle` to the first occupied cell of the map (fine march)."""
    step = res / 20.0
    d = 0.0
    dx, dy = math.cos(angle), math.sin(angle)
    while d < max_range:
        px, py = x + d * dx, y + d * dy
        if occupied(int(math.floor((px - ox) / res)), int(math.floor((py - oy) / res))):
            return d
        d += step
    return float("inf")
