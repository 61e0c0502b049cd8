"""The metrics node's locking (no master needed: the node is built without its ROS connections).
The summary of a long run is slow on a loaded machine; computed under the lock that the pose
callbacks need, it stalled the lockstep heartbeat and the simulator went on without the node."""
import json
import os
import threading

from mbot_follower import metrics_node
from mbot_follower.metrics import MetricsCollector, RunWriter

from test_metrics import drive, wedge


class Publisher(object):
    def __init__(self):
        self.sent = []

    def publish(self, msg):
        self.sent.append(msg)


def node(output_dir):
    n = metrics_node.MetricsNode.__new__(metrics_node.MetricsNode)
    n.collector = MetricsCollector()
    n.writer = RunWriter(output_dir)
    n.lock, n.write_lock = threading.Lock(), threading.Lock()
    n.closed = False
    n.summary_due = 0.0
    n.pub = Publisher()
    n.collector.on_assignment(0.0, wedge())
    n.collector.on_status(0.0, "NAVIGATING", "goal", [])
    feed(n, 0.0, 2.0)
    return n


def feed(n, t_from, t_to):
    def poses(t):
        return {"robot_0": (t, 0.0, 0.0), "robot_1": (t - 1.0, 0.5, 0.0), "robot_2": (t - 1.0, -0.5, 0.0)}

    drive(n.collector, t_from, t_to, poses)


def summarized_without_the_lock(n, monkeypatch, call):
    """Run call() with a summarize that notes whether the node's lock was free meanwhile."""
    free = []
    real = metrics_node.summarize

    def watching(run):
        got = n.lock.acquire(blocking=False)
        if got:
            n.lock.release()
        free.append(got)
        return real(run)

    monkeypatch.setattr(metrics_node, "summarize", watching)
    call()
    return free


def test_the_live_summary_is_computed_outside_the_lock(tmp_path, monkeypatch):
    n = node(str(tmp_path))
    monkeypatch.setattr(metrics_node.rospy.Time, "now", staticmethod(lambda: metrics_node.rospy.Time(2, 0)))
    assert summarized_without_the_lock(n, monkeypatch, n.publish) == [True]
    assert n.pub.sent[0].state == "NAVIGATING" and n.pub.sent[0].slot_rms < 0.01


def test_the_record_is_written_outside_the_lock_and_a_save_after_finish_writes_nothing(tmp_path, monkeypatch):
    n = node(str(tmp_path))
    assert summarized_without_the_lock(n, monkeypatch, n.save) == [True]
    assert summarized_without_the_lock(n, monkeypatch, n.finish) == [True]
    with open(os.path.join(str(tmp_path), "metrics.json")) as f:
        written = json.load(f)
    feed(n, 2.0, 3.0)   # not through the callbacks, which ignore data after finish()
    n.save()            # a timer that fires after finish() must not overwrite its record
    with open(os.path.join(str(tmp_path), "metrics.json")) as f:
        assert json.load(f) == written


class Clocks(object):
    """time.monotonic and time.thread_time for the node, moved by the test."""

    def __init__(self):
        self.wall = 100.0
        self.cpu = 0.0

    def monotonic(self):
        return self.wall

    def thread_time(self):
        return self.cpu


def test_the_live_summary_costs_at_most_its_share_of_a_core_and_the_final_one_is_always_made(tmp_path, monkeypatch):
    """A long run's summary costs more every second; recomputed every second it made the
    collector's cost grow with the square of the run. Now it waits 1 / SUMMARY_SHARE times its
    own CPU time; the files still get their new rows, and finish() always summarizes."""
    n = node(str(tmp_path))
    clocks = Clocks()
    monkeypatch.setattr(metrics_node, "time", clocks)
    monkeypatch.setattr(metrics_node.rospy.Time, "now", staticmethod(lambda: metrics_node.rospy.Time(2, 0)))
    real = metrics_node.summarize
    made = []

    def costly(run):           # each summary costs 0.1 s CPU: the next one is due 2 s later
        made.append(len(run.samples))
        clocks.cpu += 0.1
        return real(run)

    monkeypatch.setattr(metrics_node, "summarize", costly)
    n.publish()
    assert len(made) == 1 and len(n.pub.sent) == 1
    clocks.wall += 1.0
    n.publish()                # not due: nothing computed, nothing published
    n.save()                   # the rows go out, metrics.json waits for a summary
    assert len(made) == 1 and len(n.pub.sent) == 1
    assert not os.path.exists(os.path.join(str(tmp_path), "metrics.json"))
    with open(os.path.join(str(tmp_path), "metrics.csv")) as f:
        assert len(f.readlines()) > 10
    clocks.wall += 1.0 + 1e-6
    n.publish()
    assert len(made) == 2 and len(n.pub.sent) == 2
    feed(n, 2.0, 3.0)
    n.finish()                 # not due, but the final record is always summarized
    assert len(made) == 3
    with open(os.path.join(str(tmp_path), "metrics.json")) as f:
        assert json.load(f)["samples"] == made[-1] > made[0]   # the whole record, to its end


def truth(t, x, vx, wz=0.0):
    import rospy
    from nav_msgs.msg import Odometry

    msg = Odometry()
    msg.header.stamp = rospy.Time.from_sec(t)
    msg.header.frame_id = "map"
    msg.pose.pose.position.x = x
    msg.pose.pose.orientation.w = 1.0
    msg.twist.twist.linear.x, msg.twist.twist.angular.z = vx, wz
    return msg


def test_every_robot_gets_power_and_energy_from_its_measured_velocity_whoever_commands_it(tmp_path, monkeypatch):
    """No robot has a follower controller here (the leader and robots driven by move_base goals
    in dispatch mode publish nothing but their ground truth): a driving robot's energy grows by
    the power model of its velocity, one at rest stays at 0 J; /fleet/metrics has both."""
    import math

    import rospy

    n = metrics_node.MetricsNode.__new__(metrics_node.MetricsNode)
    n.collector = MetricsCollector()
    n.lock = threading.Lock()
    n.closed = False
    n.summary_due = 0.0
    n.pub = Publisher()
    n.heartbeat_pub = Publisher()
    n.heartbeat = metrics_node.Header()
    monkeypatch.setattr(rospy.Time, "now", staticmethod(lambda: rospy.Time.from_sec(10.0)))
    for k in range(101):             # 10 s at 10 Hz: leader drives 0.3 m/s turning 0.2 rad/s; robot_5 stands
        t = 1.0 + k * 0.1
        n.on_truth(truth(t, 0.03 * k, 0.3, 0.2), "leader")
        n.on_truth(truth(t, 4.0, 0.0), "robot_5")
    power = 4.0 * 0.3 ** 2 + 0.5 * 0.2 ** 2            # the power model's defaults [W]
    assert math.isclose(n.collector.energy["leader"], power * 10.0, rel_tol=1e-6)
    assert n.collector.energy["robot_5"] == 0.0
    n.publish()
    msg = n.pub.sent[-1]
    energy = dict(zip(msg.robots, msg.robot_energy))
    assert set(energy) == {"leader", "robot_5"}
    assert math.isclose(energy["leader"], power * 10.0, rel_tol=1e-3) and energy["robot_5"] == 0.0
    assert dict(zip(msg.robots, msg.robot_power)) == {"leader": power, "robot_5": 0.0}
    assert math.isclose(msg.energy, power * 10.0, rel_tol=1e-3)


def test_the_simulators_report_gives_the_latency_and_finish_records_the_cycles_still_waiting(tmp_path, monkeypatch):
    """FollowerState and AppliedCommands messages through the callbacks: a cycle's latency is the
    pose's age when its command was applied; the method is logged once; at finish() the cycles
    whose report never came are recorded (latency and applied unknown), none lost."""
    from mbot_msgs.msg import AppliedCommand, AppliedCommands, FollowerState
    import rospy

    n = node(str(tmp_path))
    n.latency_method = None
    logged = []
    monkeypatch.setattr(metrics_node.rospy, "loginfo", lambda *a: logged.append(a))
    monkeypatch.setattr(metrics_node.rospy, "logwarn", lambda *a: logged.append(a))
    report = AppliedCommands()
    report.since, report.header.stamp = rospy.Time.from_sec(2.0), rospy.Time.from_sec(2.1)
    for k in range(4):   # cycles at 2.0, 2.05, 2.1, 2.15: only the first two are in the report
        t = 2.0 + 0.05 * k
        msg = FollowerState(robot="robot_1", active=True, mode="slot")
        msg.header.stamp, msg.pose_stamp = rospy.Time.from_sec(t), rospy.Time.from_sec(t - 0.03)
        msg.cmd.linear.x, msg.cmd.angular.z = 0.1 * (k + 1), 0.2
        n.on_state(msg, "robot_1")
        if t + 0.02 < 2.1:
            report.commands.append(AppliedCommand(robot="robot_1", received=msg.header.stamp,
                                                  applied=rospy.Time.from_sec(t + 0.02), cmd=msg.cmd))
    n.on_applied(report)
    assert [round(c.latency, 6) for c in n.collector.run.controller] == [0.05, 0.05]   # ROS time: whole ns
    n.finish()
    rows = n.collector.run.controller
    assert len(rows) == 4 and all(r != r for r in (rows[2].latency, rows[2].applied, rows[3].applied))
    said = [a for a in logged if "latency" in a[0]]
    assert len(said) == 1 and "/stage/applied_commands" in said[0][0]
    with open(os.path.join(str(tmp_path), "metrics.json")) as f:
        fleet = json.load(f)["fleet"]
    assert fleet["latency_method"] == "simulator" and fleet["commands_not_applied"] == 0


def test_the_fleets_ground_truth_in_one_message_measures_as_each_robots_own_topic(tmp_path, monkeypatch):
    """/stage/ground_truth (one RobotStates per step) and /<robot>/base_pose_ground_truth give the
    collector the same poses, distances and energy; a robot not measured is left out."""
    import rospy
    from mbot_msgs.msg import RobotState, RobotStates

    def fresh():
        n = metrics_node.MetricsNode.__new__(metrics_node.MetricsNode)
        n.collector = MetricsCollector()
        n.lock = threading.Lock()
        n.closed = False
        n.heartbeat_pub = Publisher()
        n.heartbeat = metrics_node.Header()
        n.subs = {"leader": [], "robot_5": []}
        return n

    monkeypatch.setattr(rospy.Time, "now", staticmethod(lambda: rospy.Time.from_sec(10.0)))
    one, each = fresh(), fresh()
    for k in range(101):
        t = 1.0 + k * 0.1
        own = {"leader": truth(t, 0.03 * k, 0.3, 0.2), "robot_5": truth(t, 4.0, 0.0), "robot_9": truth(t, 9.0, 0.0)}
        fleet = RobotStates()
        fleet.header.frame_id = "map"
        for name, msg in sorted(own.items()):
            p, v = msg.pose.pose, msg.twist.twist
            state = RobotState(name=name, stamp=msg.header.stamp)
            state.pose.x, state.pose.y = p.position.x, p.position.y
            state.pose.theta = metrics_node.yaw_of(p.orientation)
            state.twist = v
            fleet.robots.append(state)
        one.on_fleet_truth(fleet)
        for name in ("leader", "robot_5"):
            each.on_truth(own[name], name)
    assert set(one.collector.poses) == {"leader", "robot_5"}
    assert one.collector.poses == each.collector.poses
    assert one.collector.distance == each.collector.distance and one.collector.energy == each.collector.energy
    assert one.collector.distance["leader"] > 2.5
    assert [s.t for s in one.collector.run.samples] == [s.t for s in each.collector.run.samples]
    assert one.heartbeat_pub.sent and len(one.heartbeat_pub.sent) <= len(each.heartbeat_pub.sent)


def test_an_unknown_ground_truth_source_is_refused_by_name(monkeypatch):
    import pytest
    import rospy

    monkeypatch.setattr(rospy, "get_param", lambda key, default=None: {"ground_truth": "odom"})
    monkeypatch.setattr(rospy, "get_name", lambda: "/metrics_collector")
    with pytest.raises(ValueError, match="ground_truth: expected one of fleet, robots, got 'odom'"):
        metrics_node.read_config()
