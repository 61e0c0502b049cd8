#!/usr/bin/python3
"""rostest (sim_lockstep.test): stage_node's lockstep at real_time_factor 0.

A deliberately slow controller answers every /clock advance past a lockstep boundary with a
cmd_vel for robot_0 (turning in place), 20 ms (wall) after it saw the boundary. stage_node, which
runs about 800x faster than real time without lockstep, must hold sim time for it: one cmd_vel
releases one boundary, so while the test drives, sim time never gets more than one period (+ one
physics step, for a boundary between two steps) past the last boundary the test answered. Without
lockstep sim time runs seconds ahead within the 20 ms.
When the test stops sending, robot_0 is no longer waited for: sim time runs on (> 5 s sim within
10 wall seconds: one 3 s wall timeout, then free), it does not hang.

A controller that holds its robot still sends zeros every cycle (the follower controllers do, so
that sim time waits for them): once a few of them have shown it (while the test holds sim time as a
pacer, as localization and the coordinator do in a fleet), it is waited for like a driving one, also
while it stalls for 1 s wall (less than the wall timeout) in the middle. A controller that has
stopped commanding is not:
move_base's end of a goal (a stop while the robot turns, its idle cycle's stop, then nothing) and
a single stop to a robot at rest, five times, each let sim time run on at once (> 5 s and > 2 s
sim within 1.5 s wall, where waiting for their next cmd_vel would take the 3 s wall timeout).

A slow localization for robot_1 (not driven) holds sim time the same way: it answers each boundary
20 ms late with map -> robot_1/odom stamped at that boundary, and sim time never gets more than
~lockstep_localization_lag + one period (+ one step) past the newest stamp. When it stops, sim time
runs on after one wall timeout.

A slow pacer (a node that sends its progress on /lockstep/heartbeat) holds sim time even when one
boundary takes it longer than the wall timeout: its heartbeat moves on, 2 ms of sim time every
0.25 s wall, so it is alive, and sim time never gets more than ~lockstep_pacer_lag + one period
(+ one step) past its newest stamp. (Ignoring it after one timeout left it behind for good: sim
time ran away from it.) When it falls silent, sim time runs on after one wall timeout.
"""
import math
import sys
import threading
import time
import unittest

import rospy
import rostest
import yaml
from geometry_msgs.msg import Twist
from geometry_msgs.msg import TransformStamped
from rosgraph_msgs.msg import Clock
from std_msgs.msg import Header
from tf2_msgs.msg import TFMessage

ANSWER_DELAY = 0.02  # [s wall] how long the controller "computes"
ANSWERS = 40         # boundaries answered while driving
WARM_UP = 3          # answers before the checks start


class ClockWatch(object):
    """The latest /clock and the largest lead of sim time over the last answered boundary."""

    def __init__(self, limit):
        self.lock = threading.Lock()
        self.limit = limit  # allowed lead [s sim]
        self.latest = None
        self.last_answered = None  # None: not driving, nothing is checked
        self.worst_lead = 0.0
        self.violations = []
        rospy.Subscriber("/clock", Clock, self._callback, queue_size=1, tcp_nodelay=True)

    def _callback(self, msg):
        t = msg.clock.to_sec()
        with self.lock:
            self.latest = t
            if self.last_answered is not None:
                lead = t - self.last_answered
                self.worst_lead = max(self.worst_lead, lead)
                if lead > self.limit:
                    self.violations.append((self.last_answered, t))

    def now(self):
        with self.lock:
            return self.latest


def wait_for(condition, wall_timeout, what):
    deadline = time.time() + wall_timeout
    while not condition():
        if time.time() > deadline:
            raise AssertionError("timed out after %.1f s wall waiting for %s" % (wall_timeout, what))
        time.sleep(0.001)


def sim_settings():
    """(lockstep period, physics step) of the running stage_node [s]."""
    with open(rospy.get_param("/stage_node/world")) as f:
        step = yaml.safe_load(f)["physics_step"]
    return rospy.get_param("/stage_node/lockstep_period"), step


def answer_boundaries(watch, period, answer, warm_up=0, answers=ANSWERS, delay=lambda i: ANSWER_DELAY):
    """Play a slow node: `answers` times, wait until sim time passes a boundary, "compute" for
    delay(i) (ANSWER_DELAY) wall seconds, then call answer(boundary). The first `warm_up` answers
    are not checked; for the others `watch` records how far sim time gets past the last answer.
    @return (sim seconds, wall seconds, violations, largest lead) of the checked answers"""
    boundary = lambda: math.floor(watch.now() / period + 1e-6) * period  # noqa: E731
    answered = None
    for i in range(warm_up + answers):
        wait_for(lambda: answered is None or boundary() > answered + 1e-6, 2.0, "sim time to pass a boundary")
        b = boundary()
        if i == warm_up:
            wall_start, sim_start = time.time(), b
        time.sleep(delay(i))
        answered = b
        if i >= warm_up:
            with watch.lock:  # before answering: the sim cannot move on before it gets the answer
                watch.last_answered = b
        answer(b)
    sim_run, wall_run = watch.now() - sim_start, time.time() - wall_start
    with watch.lock:
        watch.last_answered = None
        return sim_run, wall_run, list(watch.violations), watch.worst_lead


def wait_for_release(watch, what):
    """After the slow node stopped: one wall timeout (3 s) later sim time runs on (5 s sim in < 10 s wall)."""
    t0, w0 = watch.now(), time.time()
    wait_for(lambda: watch.now() > t0 + 5.0, 10.0, "sim time to run 5 s on after %s stopped" % what)
    print("after the stop: 5 s sim in %.2f s wall" % (time.time() - w0))


def standing_still(watch, seconds=0.15):
    """Sim time stood still for `seconds` wall, twice, while this process was not starved (a
    starved process may not have read the newest /clock yet)."""
    stamp = watch.now()
    for _ in range(2):
        start = time.time()
        time.sleep(seconds)
        if time.time() - start > 2.0 * seconds or watch.now() != stamp:
            return False
    return True


def wait_until_held(watch, send, what):
    """Call send() until sim time waits for the sender."""
    deadline = time.time() + 20.0
    while True:
        send()
        time.sleep(ANSWER_DELAY)
        if standing_still(watch):
            return
        if time.time() > deadline:
            raise AssertionError("sim time did not hold for %s within 20 s wall" % what)


def runs_on(watch, what, sim_s=2.0, wall_s=1.5):
    """Sim time runs `sim_s` on within `wall_s` (less than the 3 s wall timeout: nobody waits)."""
    t0, w0 = watch.now(), time.time()
    wait_for(lambda: watch.now() > t0 + sim_s, wall_s, "sim time to run %g s on %s" % (sim_s, what))
    return watch.now() - t0, time.time() - w0


def turn(rate):
    msg = Twist()
    msg.angular.z = rate
    return msg


class SimLockstep(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("test_sim_lockstep")

    def test_slow_localization_holds_sim_time_and_release(self):
        period, step = sim_settings()
        lag = rospy.get_param("/stage_node/lockstep_localization_lag")
        postdate = rospy.get_param("/stage_node/lockstep_localization_postdate")
        limit = lag + period + step + 1e-6  # past the time of the localization's data, not its stamp
        watch = ClockWatch(limit)
        pub = rospy.Publisher("/tf", TFMessage, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and watch.now() is not None, 20.0, "stage_node")

        def publish(stamp):  # data of time `stamp`, post-dated as amcl does
            t = TransformStamped()
            t.header.stamp = rospy.Time.from_sec(stamp + postdate)
            t.header.frame_id = "map"
            t.child_frame_id = "robot_1/odom"
            t.transform.rotation.w = 1.0
            pub.publish(TFMessage([t]))

        # Until the first transform arrives the sim runs free: warm up (unchecked) until it holds.
        sim_run, wall_run, violations, worst = answer_boundaries(watch, period, publish, warm_up=WARM_UP)
        print("localization: %.2f s sim in %.2f s wall (%d transforms); largest lead over the newest stamp %.3f s "
              "(allowed %.3f s)" % (sim_run, wall_run, ANSWERS, worst, limit))
        self.assertEqual(len(violations), 0, "sim time ran ahead of the localization (stamp, sim time): %s"
                         % violations[:5])
        # Each transform releases sim time up to the first boundary more than `lag` past its data (stamp - postdate).
        self.assertLess(sim_run, ANSWERS * limit + limit)
        wait_for_release(watch, "the localization")

    def test_slow_controller_holds_sim_time_and_release(self):
        period, step = sim_settings()
        limit = period + step + 1e-6
        watch = ClockWatch(limit)
        pub = rospy.Publisher("/robot_0/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and watch.now() is not None, 20.0, "stage_node")

        # Start driving; the first command makes robot_0 driven, from then on sim time waits.
        wait_until_held(watch, lambda: pub.publish(turn(0.2)), "the first command")
        sim_driven, wall_driven, violations, worst = answer_boundaries(watch, period,
                                                                       lambda _b: pub.publish(turn(0.2)))
        print("driving: %.2f s sim in %.2f s wall (%d answers); largest lead over the last answer %.3f s "
              "(allowed %.3f s)" % (sim_driven, wall_driven, ANSWERS, worst, limit))
        self.assertEqual(len(violations), 0, "sim time ran ahead of the answered boundary (answered, sim time): %s"
                         % violations[:5])
        # Each answer released about one period: sim time moved on, but only that far.
        self.assertGreater(sim_driven, (ANSWERS - 5) * period)
        self.assertLess(sim_driven, (ANSWERS + 3) * period)
        wait_for_release(watch, "the commands")

    def test_holding_controller_holds_sim_time_also_while_it_stalls_and_release(self):
        period, step = sim_settings()
        limit = period + step + 1e-6
        watch = ClockWatch(limit)
        pub = rospy.Publisher("/robot_2/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and watch.now() is not None, 20.0, "stage_node")

        # Zeros to robot_2, at rest: a single stop does not hold sim time, zeros repeated soon after
        # each other do. In a fleet other nodes hold sim time meanwhile (localization, the
        # coordinator's heartbeat); here the test does, as a pacer, for the first five zeros, and then
        # lets go (a heartbeat far ahead: never waited for again).
        beat = rospy.Publisher("/lockstep/heartbeat", Header, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: beat.get_num_connections() > 0, 20.0, "stage_node's heartbeat subscription")
        for _ in range(5):
            beat.publish(Header(stamp=rospy.Time.from_sec(watch.now()), frame_id="/holding_warm_up"))
            time.sleep(ANSWER_DELAY)
            pub.publish(Twist())
            time.sleep(ANSWER_DELAY)
        beat.publish(Header(stamp=rospy.Time.from_sec(1e6), frame_id="/holding_warm_up"))
        wait_until_held(watch, lambda: None, "the zeros")
        # Then one zero per boundary; the controller stalls for 1 s wall (less than the wall timeout) at answer 20.
        stall = 1.0
        sim_held, wall_held, violations, worst = answer_boundaries(
            watch, period, lambda _b: pub.publish(Twist()), delay=lambda i: stall if i == 20 else ANSWER_DELAY)
        print("holding still: %.2f s sim in %.2f s wall (%d zeros, a %.1f s wall stall); largest lead over the "
              "last answer %.3f s (allowed %.3f s)" % (sim_held, wall_held, ANSWERS, stall, worst, limit))
        self.assertEqual(len(violations), 0, "sim time ran ahead of the holding controller (answered, sim time): %s"
                         % violations[:5])
        self.assertGreater(sim_held, (ANSWERS - 5) * period)
        self.assertLess(sim_held, (ANSWERS + 3) * period)
        self.assertGreater(wall_held, stall)
        wait_for_release(watch, "the zeros")

    def test_stopped_controller_does_not_hold_sim_time(self):
        period, step = sim_settings()
        watch = ClockWatch(period + step + 1e-6)
        pub = rospy.Publisher("/robot_0/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and watch.now() is not None, 20.0, "stage_node")

        # move_base at the end of a goal: it drove (here: turned), stops, stops again in its idle
        # cycle one period later, then sends nothing until its next goal.
        wait_until_held(watch, lambda: pub.publish(turn(0.5)), "the first command")
        _, _, violations, _ = answer_boundaries(watch, period, lambda _b: pub.publish(turn(0.5)), answers=10)
        self.assertEqual(len(violations), 0, "sim time did not wait for the turning robot: %s" % violations[:5])
        t = watch.now()
        pub.publish(Twist())
        wait_for(lambda: watch.now() >= t + period - 1e-6, 2.0, "sim time to pass the next boundary")
        time.sleep(ANSWER_DELAY)
        pub.publish(Twist())
        sim_s, wall_s = runs_on(watch, "after move_base's stops", sim_s=5.0)
        print("after move_base's two stops: %.2f s sim in %.2f s wall" % (sim_s, wall_s))

    def test_single_stops_to_a_robot_at_rest_do_not_hold_sim_time(self):
        watch = ClockWatch(1.0)
        pub = rospy.Publisher("/robot_1/cmd_vel", Twist, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and watch.now() is not None, 20.0, "stage_node")
        # A single stop to a robot at rest, then silence, five times (apart in wall time, as move_base's
        # goals are): each lets sim time run on at once.
        sim_total, wall_total = 0.0, 0.0
        for i in range(5):
            time.sleep(1.0)
            pub.publish(Twist())
            sim_s, wall_s = runs_on(watch, "after a single stop (%d of 5)" % (i + 1))
            sim_total, wall_total = sim_total + sim_s, wall_total + wall_s
        print("after single stops: %.2f s sim in %.2f s wall (%.0f sim s per wall s)"
              % (sim_total, wall_total, sim_total / wall_total))

    def test_slow_pacer_holds_sim_time_past_the_wall_timeout_and_release(self):
        period, step = sim_settings()
        lag = rospy.get_param("/stage_node/lockstep_pacer_lag")
        timeout = rospy.get_param("/stage_node/lockstep_wall_timeout")
        limit = lag + period + step + 1e-6
        watch = ClockWatch(limit)
        pub = rospy.Publisher("/lockstep/heartbeat", Header, queue_size=10, tcp_nodelay=True)
        wait_for(lambda: pub.get_num_connections() > 0 and watch.now() is not None, 20.0, "stage_node")
        increment, interval = 0.002, 0.25   # a boundary (0.05 s sim) takes it 6.25 s wall
        self.assertGreater(period / increment * interval, timeout)
        # Sim time runs free (an earlier test's node stopped): keep up with it until it holds
        # for the pacer, which cannot start behind it (sim time cannot go back).
        deadline = time.time() + 20.0
        while True:
            stamp = watch.now()
            pub.publish(Header(stamp=rospy.Time.from_sec(stamp), frame_id="/slow_pacer"))
            time.sleep(0.2)
            if watch.now() <= stamp + limit:
                break
            self.assertLess(time.time(), deadline, "sim time did not hold for the pacer")
        with watch.lock:
            watch.last_answered = stamp
        wall_end = time.time() + 3.0 * timeout
        while time.time() < wall_end:
            time.sleep(interval)
            stamp += increment
            with watch.lock:  # before sending: the sim cannot move on before it gets the heartbeat
                watch.last_answered = stamp
            pub.publish(Header(stamp=rospy.Time.from_sec(stamp), frame_id="/slow_pacer"))
        with watch.lock:
            watch.last_answered = None
            violations, worst = list(watch.violations), watch.worst_lead
        print("slow pacer: heartbeat at %.3f s sim after %.0f s wall; largest lead over it %.3f s (allowed %.3f s)"
              % (stamp, 3.0 * timeout, worst, limit))
        self.assertEqual(len(violations), 0, "sim time ran ahead of the slow pacer (heartbeat, sim time): %s"
                         % violations[:5])
        wait_for_release(watch, "the pacer")


if __name__ == "__main__":
    rostest.rosrun("mbot_sim", "sim_lockstep", SimLockstep, sys.argv)
