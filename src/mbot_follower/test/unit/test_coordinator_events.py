"""The events of the metrics record (events.csv) come from what the coordinator really publishes:
the coordinator node's cycle runs (no master: its publishers, tf and move_base are stand-ins), its
FleetStatus and FleetAssignment messages go into the metrics collector node's callbacks, and
the record is written and read back. A leader pause keeps the state NAVIGATING, so the pause must
be an event of its own; so must the end of a switch, a loss and a rejoin."""
import math
import threading

import pytest
import rospy
from sensor_msgs.msg import LaserScan

from mbot_common.geometry import Pose2D
from mbot_follower import coordinator_node
from mbot_follower.coordinator import FleetCoordinator
from mbot_follower.coordinator_node import NODE_PARAMS, CoordinatorNode
from mbot_follower.metrics import MetricsCollector, RunWriter, load_run
from mbot_follower.metrics_node import MetricsNode

ROBOTS = ["robot_0", "robot_1", "robot_2"]
STEP = 0.1   # [s sim] the coordinator's cycle


class Capture(object):
    def __init__(self, sink=None):
        self.sink = sink

    def publish(self, msg):
        if self.sink is not None:
            self.sink(msg)

    sendTransform = publish


class NavClient(object):
    def __init__(self):
        self.goals = 0

    def send_goal(self, goal):
        self.goals += 1

    def cancel_all_goals(self):
        pass


class Fleet(object):
    """A coordinator node wired to a metrics collector node, and a world of perfect robots: the
    followers stand in their slots, the leader drives along x while it has a goal."""

    def __init__(self, monkeypatch):
        self.t = 10.0
        monkeypatch.setattr(rospy.Time, "now", staticmethod(lambda: rospy.Time.from_sec(self.t)))
        for name in ("logwarn_throttle", "loginfo_throttle", "logerr_throttle"):
            monkeypatch.setattr(rospy, name, lambda period, text: None)
        monkeypatch.setattr(coordinator_node.CoordinatorNode, "_follow_leader_scan", lambda n, leader, now: None)
        m = self.metrics = MetricsNode.__new__(MetricsNode)
        m.collector, m.lock, m.closed, m.fixed_robots = MetricsCollector(), threading.Lock(), False, True
        n = self.node = CoordinatorNode.__new__(CoordinatorNode)
        from mbot_msgs.msg import FleetStatus
        n._FleetStatus = FleetStatus
        n.params = dict(NODE_PARAMS)
        n.robots = ROBOTS
        n.core = FleetCoordinator(ROBOTS, "robot_0", "triangle", 1.5)
        n.lock = threading.RLock()
        n.last_heard_pose, n.last_heard_controller, n.controller_mode, n.poses = {}, {}, {}, {}
        n.leader_scan, n._scan_since, n._scan_robot = None, self.t, "robot_0"
        n._nav_robot = n._published_state = n._last_status = n._last_debug = n._last_nav = None
        n._startup_done, n._waited_for = True, set()
        n._wall_clock = lambda: 0.0
        n._init_params(n.core.config)
        n._param_cache = type("Cache", (), {"values": lambda c: {}})()
        n.status_pub = Capture(m.on_status)
        n.assignment_pub = Capture(m.on_assignment)
        n.marker_pub = n.tf_broadcaster = Capture()
        n._view_stamp = None
        n._nav_clients = {r: NavClient() for r in ROBOTS}
        n._nav_connected = set(ROBOTS)
        n._leader_speed = type("Speed", (), {"set": lambda s, robot, speed: None})()
        n._leader_nav = lambda: "ACTIVE" if n._nav_robot else None
        n._look_up_poses = self.look_up
        self.leader = Pose2D(0.0, 0.0, 0.0)
        self.silent = set()      # robots whose poses and controller states stop
        self.obstacle = False

    def look_up(self, now_ros):
        core = self.node.core
        poses = {"robot_0": self.leader, "robot_1": Pose2D(-1.5, 1.0, 0.0), "robot_2": Pose2D(-1.5, -1.0, 0.0)}
        poses.update({r: p for r, p in core.slot_poses(poses).items() if r != "robot_0"})
        poses = {r: p for r, p in poses.items() if r not in self.silent}
        for r in poses:
            self.node.last_heard_pose[r] = self.t
            self.node.last_heard_controller[r] = self.t
        return poses

    def run(self, seconds):
        for _ in range(int(round(seconds / STEP))):
            self.t += STEP
            if self.node._nav_robot and not self.node.core.paused:
                self.leader = Pose2D(self.leader.x + 0.03, 0.0, 0.0)
            scan = LaserScan()
            scan.header.stamp = rospy.Time.from_sec(self.t)
            scan.angle_min, scan.angle_increment = -1.0, 0.1
            scan.ranges = [0.8 if self.obstacle else 5.0] * 21
            self.node.leader_scan = scan
            self.node._step(None)


def test_pauses_switches_losses_and_rejoins_reach_the_record_from_the_coordinators_output(monkeypatch, tmp_path):
    fleet = Fleet(monkeypatch)
    n = fleet.node
    ok, text = n._set_goal(Pose2D(20.0, 0.0, 0.0))
    assert ok, text
    fleet.run(2.0)
    assert n.core.state() == "NAVIGATING"
    fleet.obstacle = True                    # something close in front of the leader
    fleet.run(0.3)
    assert n.core.paused and n.core.state() == "NAVIGATING"
    fleet.obstacle = False
    fleet.run(1.5)                           # pause_time 1 s: it ends
    assert not n.core.paused
    assert n._switch("line", 0.0)[0]
    fleet.run(2.0)                           # perfect followers: the new shape stands at once
    assert not n.core.switching
    fleet.silent = {"robot_2"}
    fleet.run(2.0)
    assert n.core.lost == ["robot_2"]
    fleet.silent = set()
    fleet.run(2.0)
    assert n.core.lost == []

    writer = RunWriter(str(tmp_path))
    run = fleet.metrics.collector.run
    writer.write(run, {})
    events = [(e.kind, e.name) for e in load_run(str(tmp_path)).events if e.kind not in ("state", "assignment")]
    assert events == [("pause", "start"), ("pause", "end"), ("switch", "line"), ("switch_done", "line"),
                      ("loss", "robot_2"), ("rejoin", "robot_2")]
    times = {k + "/" + name: e.t for e in run.events for k, name in [(e.kind, e.name)]}
    assert times["pause/end"] - times["pause/start"] == pytest.approx(n.core.config.pause_time, abs=STEP + 1e-6)
    assert times["switch_done/line"] >= times["switch/line"] + n.core.config.stable_time - 1e-6
    pause = next(e for e in run.events if e.kind == "pause" and e.name == "start")
    assert pause.detail == "paused: obstacle in front of the leader robot_0"
    # the state never left NAVIGATING for the pause: without the pause events it would not be seen
    states = [e.name for e in run.events if e.kind == "state" and times["pause/start"] <= e.t <= times["pause/end"]]
    assert states == []
    assert math.isfinite(pause.t)
