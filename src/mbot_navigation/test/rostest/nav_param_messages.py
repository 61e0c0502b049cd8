#!/usr/bin/env python3
"""rostest: what move_base says about its parameters at start-up, on screen (its own output, as
with output="screen") and in /rosout. An unknown key is a warning that names it and the nearest
known key, and the node keeps running, as move_base does; a wrong value (type, range) stops the
node with exit code 1 and a fatal line naming the key, printed and sent to /rosout before it exits.
Each case starts the node itself, after this test has subscribed to /rosout_agg."""
import subprocess
import threading
import time
import unittest

import rospy
import rostest
from rosgraph_msgs.msg import Log
from roslib.packages import find_node


class NodeRun(object):
    """move_base started in namespace `ns` with `params` (keys under ~); its output is read as it comes."""

    def __init__(self, ns, params):
        self.node = "/%s/move_base" % ns
        for key, value in params.items():
            rospy.set_param("%s/%s" % (self.node, key), value)
        exe = find_node("mbot_navigation", "move_base")[0]
        self.process = subprocess.Popen([exe, "__ns:=/" + ns, "__name:=move_base"], stdout=subprocess.PIPE,
                                        stderr=subprocess.STDOUT, universal_newlines=True)
        self.lines = []
        self._reader = threading.Thread(target=self._read)
        self._reader.daemon = True
        self._reader.start()

    def _read(self):
        for line in self.process.stdout:
            self.lines.append(line.rstrip("\n"))

    def output(self):
        return "\n".join(self.lines)

    def stop(self):
        if self.process.poll() is None:
            self.process.terminate()
        self.process.wait(30)
        self._reader.join(10)


class Rosout(object):
    """The messages that reached rosout (/rosout_agg), as (node, level, text)."""

    def __init__(self):
        self.messages = []
        self._sub = rospy.Subscriber("/rosout_agg", Log, self._on_log, queue_size=1000)

    def _on_log(self, msg):
        self.messages.append((msg.name, msg.level, msg.msg))

    def find(self, node, level, text):
        return [m for m in self.messages if m[0] == node and m[1] == level and text in m[2]]


def wait_wall(condition, timeout):
    deadline = time.time() + timeout
    while time.time() < deadline and not condition():
        time.sleep(0.05)
    return condition()


class ParamMessages(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.rosout = Rosout()
        # The subscription must be connected before a node logs (rosout_agg is not latched).
        assert wait_wall(lambda: cls.rosout._sub.get_num_connections() > 0, 30.0), "no /rosout_agg publisher"

    def check_fatal(self, ns, params, key):
        run = NodeRun(ns, params)
        try:
            run.process.wait(120)
        finally:
            run.stop()
        self.assertEqual(run.process.returncode, 1, run.output())
        name = "/%s/move_base/%s" % (ns, key)
        fatal = [line for line in run.lines if "FATAL" in line]
        self.assertEqual(len(fatal), 1, run.output())
        self.assertIn(name, fatal[0])
        self.assertTrue(wait_wall(lambda: self.rosout.find(run.node, Log.FATAL, name), 20.0),
                        "no fatal line naming %s in /rosout: %s" % (name, self.rosout.messages))

    def test_wrong_type_stops_the_node_and_says_why(self):
        self.check_fatal("wrong_type", {"DWAPlannerROS/max_vel_x": "fast"}, "DWAPlannerROS/max_vel_x")

    def test_out_of_range_stops_the_node_and_says_why(self):
        self.check_fatal("out_of_range", {"controller_frequency": -1.0}, "controller_frequency")

    def test_unknown_key_is_a_warning_and_the_node_runs_on(self):
        run = NodeRun("unknown_key", {"DWAPlannerROS/max_rot_velx": 1.0, "local_costmap/inflation_raduis": 0.3})
        lines = ["unknown parameter /unknown_key/move_base/DWAPlannerROS/max_rot_velx (ignored; did you mean "
                 "max_rot_vel?)",
                 "unknown parameter /unknown_key/move_base/local_costmap/inflation_raduis (ignored; did you mean "
                 "inflation_radius?)"]
        try:
            for line in lines:
                self.assertTrue(wait_wall(lambda: self.rosout.find(run.node, Log.WARN, line), 120.0),
                                "no warning '%s' in /rosout: %s\n%s" % (line, self.rosout.messages, run.output()))
            time.sleep(2.0)
            self.assertIsNone(run.process.poll(), "the node stopped:\n" + run.output())
        finally:
            run.stop()
        for line in lines:
            self.assertEqual(len([x for x in run.lines if "WARN" in x and line in x]), 1, run.output())
        self.assertNotIn("FATAL", run.output())


if __name__ == "__main__":
    rospy.init_node("nav_param_messages_test")
    rostest.rosrun("mbot_navigation", "nav_param_messages", ParamMessages)
