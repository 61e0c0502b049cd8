#!/usr/bin/python3
"""The checks a course runs on a formation fleet, as an outside client would run them: send
targets and switches on the public topics, kill nodes, set parameters, and measure the result
from the simulator's ground truth (not from what the coordinator says about itself).

The check is chosen by the private parameter ~check (one .test file per check):
  triangle  - the triangle drives to (5, 0) via /simulation/target_pose: slot RMS while moving
              < 0.15 m, ARRIVED, no contact (~formation, ~topology: another shape, a chain;
              ~omni: the followers are omni robots and must drive sideways too; ~controller:
              every FollowerState of the followers names this control law)
  obstacle  - a box appears in the leader's way while NAVIGATING: pause, go around, ARRIVED, no contact
  switch    - switch to `line` while moving: the line is reached; then to `column`: the leader
              drives faster until the column is there, then at its usual speed again (a switch
              is done by the metrics' rule, FleetProbe.wait_switch_done: every follower within
              0.3 m of its slot for 0.5 s, from ground truth)
  loss      - follower_1's controller is killed: DEGRADED within 1 s of the loss, the others ARRIVE
  limit     - max_linear_vel 0.3 on follower_1: its speed stays <= 0.3 m/s while the leader's does not
  corridor  - 4 robots diamond -> column -> diamond through the corridor, no contact
  leader_loss - the leader is removed from the simulator: a follower takes over, the fleet ARRIVES
  rejoin    - a follower removed and spawned again rejoins a slot
  wall      - a line abreast along the north wall: the slot beyond the wall is not chased into it
              (its follower follows the leader's path), no contact; it is taken again once free
  refuse    - unknown formation, NaN target, target in a wall: refused, state unchanged (also
              through the /fleet/goal action: ABORTED with the reason); then the fleet drives on
              /fleet/target_pose and by the action (feedback), the latched /fleet/assignment,
              the live /fleet/metrics and ~debug_mode's slot errors in cm and degrees are there
Everything waits in sim time with a wall-clock bound.
"""
import math
import subprocess
import sys
import unittest

import rospy
import rostest
from actionlib_msgs.msg import GoalStatus
from geometry_msgs.msg import Pose2D as Pose2DMsg
from std_msgs.msg import String

from mbot_follower.fleet_probe import FleetProbe
from mbot_follower.metrics.settle import SWITCH_TOLERANCE


def robots_param():
    return rospy.get_param("~robots")


class FormationChecks(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        rospy.init_node("formation_checks")
        cls.check = rospy.get_param("~check")
        cls.probe = FleetProbe(robots_param())
        cls.probe.wait_for_fleet()

    def assertNoContacts(self):
        self.assertEqual(self.probe.contacts, [], "contacts: %s" % [
            "%s-%s at t=%.1f" % (c.body_a, c.body_b, c.header.stamp.to_sec()) for c in self.probe.contacts])

    def drive_and_arrive(self, x, y, timeout=180.0):
        p = self.probe
        p.send_target(x, y)
        p.wait(lambda: p.state() in ("FORMING", "NAVIGATING"), 10.0, "the goal to be taken")
        t = p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), timeout, "ARRIVED")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        return t

    def steady_rms(self, since, moving=0.1):
        """RMS of the followers' slot errors while the fleet moves: NAVIGATING samples after
        `since` in which the leader drives at `moving` [m/s] or more (its start and its final
        braking and turning on the spot are transients, not the steady state). Logs the error
        every 2 s so that a failure shows where it grew."""
        errors = []
        for (t, state, poses, speeds, a) in self.probe.samples_in(("NAVIGATING", "DEGRADED"), since):
            e = self.probe.slot_errors(poses, a)
            if int(t * 10) % 20 == 0:
                rospy.loginfo("t=%.1f %s leader speed %.2f m/s, slot errors %s", t, state,
                              speeds.get(a.leader, 0.0) if a else 0.0, {k: round(v, 3) for k, v in e.items()})
            if a is not None and speeds.get(a.leader, 0.0) >= moving:
                errors += e.values()
        self.assertGreater(len(errors), 20, "too few samples while NAVIGATING")
        return math.sqrt(sum(e * e for e in errors) / len(errors))

    def leader_at(self, x, y, tolerance=0.35):
        p = self.probe
        leader = p.status.leader
        pose = p.truth[leader][1]
        self.assertLess(math.hypot(pose.x - x, pose.y - y), tolerance, "%s ended at (%.2f, %.2f)" % (
            leader, pose.x, pose.y))

    def test_check(self):
        getattr(self, "run_" + self.check)()

    # --- the checks ---------------------------------------------------------------------------

    def run_triangle(self):
        p = self.probe
        self.assertEqual(p.state(), "IDLE")
        sideways = self.record_sideways_commands() if rospy.get_param("~omni", False) else None
        laws = self.record_controllers()
        self.drive_and_arrive(5.0, 0.0)
        self.check_controllers(laws)
        if sideways is not None:   # omni followers run the omni law: they drive sideways too
            rospy.loginfo("triangle: largest sideways command per follower %s", sideways)
            for robot, largest in sideways.items():
                self.assertGreater(largest, 0.05, "%s never drove sideways (max |vy| %.3f m/s)" % (robot, largest))
        self.assertEqual(p.assignment.formation, rospy.get_param("~formation", "triangle"))
        if rospy.get_param("~topology", "star") == "chain":
            # the last robot of the chain tracks the one ahead of it, not the leader
            slots = sorted(p.assignment.slots, key=lambda s: math.hypot(s.offset.x, s.offset.y))
            self.assertEqual(slots[-1].follows, slots[-2].robot)
        # steady: from 3 s after the leader set off (it accelerates, the followers catch up); it
        # may stand a few seconds in NAVIGATING first (its plan), so not from NAVIGATING's start
        set_off = [t for (t, _, _, speeds, a) in p.samples_in(("NAVIGATING",))
                   if a is not None and speeds.get(a.leader, 0.0) >= 0.1]
        self.assertTrue(set_off, "the leader never drove at 0.1 m/s or more while NAVIGATING")
        rms = self.steady_rms(set_off[0] + 3.0)
        rospy.loginfo("triangle: steady slot RMS while moving %.3f m", rms)
        self.assertLess(rms, 0.15)
        self.leader_at(5.0, 0.0)
        final = p.slot_errors({r: v[1] for r, v in p.truth.items()}, p.assignment)
        self.assertLess(max(final.values()), 0.3, "final slot errors %s" % final)
        self.assertNoContacts()
        self.check_view_frame()

    def record_sideways_commands(self):
        """{follower: largest |linear.y| [m/s] it was commanded so far} (a diff-drive law sends 0)."""
        from geometry_msgs.msg import Twist

        largest = {}

        def on_cmd(msg, robot):
            largest[robot] = max(largest[robot], abs(msg.linear.y))

        for robot in robots_param()[1:]:
            largest[robot] = 0.0
            rospy.Subscriber("/%s/cmd_vel" % robot, Twist, on_cmd, callback_args=robot, queue_size=50)
        return largest

    def record_controllers(self):
        """{follower: {law named in its FollowerState: [modes of those cycles]}} from now on."""
        from mbot_msgs.msg import FollowerState

        laws = {robot: {} for robot in robots_param()[1:]}

        def on_state(msg, robot):
            laws[robot].setdefault(msg.controller, []).append(msg.mode)

        for robot in laws:
            rospy.Subscriber("/%s/follower_controller/state" % robot, FollowerState, on_state, callback_args=robot,
                             queue_size=50)
        return laws

    def check_controllers(self, laws):
        """With ~controller set: each follower's every state named it, and it drove to its slot
        (mode slot) in many of those cycles: the law ran, not only its name."""
        expected = rospy.get_param("~controller", "")
        if not expected:
            return
        for robot, seen in laws.items():
            rospy.loginfo("%s: states per control law %s", robot, {law: len(modes) for law, modes in seen.items()})
            self.assertEqual(set(seen), {expected}, "%s's states name %s" % (robot, sorted(seen)))
            self.assertGreater(seen[expected].count("slot"), 200, "%s: too few cycles in mode slot" % robot)

    def check_view_frame(self):
        """The coordinator's `fleet` frame (rviz follows it) is the middle of the resting fleet."""
        import tf2_ros

        buffer = tf2_ros.Buffer()
        listener = tf2_ros.TransformListener(buffer)  # noqa: F841 (fills the buffer)
        t = buffer.lookup_transform("map", "fleet", rospy.Time(0), rospy.Duration(5.0)).transform
        xs = [v[1].x for v in self.probe.truth.values()]
        ys = [v[1].y for v in self.probe.truth.values()]
        middle = (0.5 * (min(xs) + max(xs)), 0.5 * (min(ys) + max(ys)))
        self.assertLess(math.hypot(t.translation.x - middle[0], t.translation.y - middle[1]), 0.1,
                        "fleet frame at (%.2f, %.2f), the fleet's middle (%.2f, %.2f)"
                        % (t.translation.x, t.translation.y, middle[0], middle[1]))
        self.assertAlmostEqual(t.rotation.w, 1.0)

    def run_switch(self):
        p = self.probe
        p.send_target(5.0, 0.0)
        p.wait(lambda: p.state() == "NAVIGATING" and p.truth[p.status.leader][1].x > -3.5, 120.0,
               "the leader on its way")
        t_switch = rospy.get_time()
        p.formation_pub.publish(String("line"))
        p.wait(lambda: p.assignment.formation == "line", 5.0, "the line assignment")
        slots = [s for s in p.assignment.slots if s.robot != p.assignment.leader]
        self.assertTrue(all(abs(s.offset.x) < 1e-6 for s in slots), "line slots are beside the leader")
        t_reached, t_done = p.wait_switch_done("line", t_switch, 60.0)
        rospy.loginfo("switch: line reached %.1f s after the switch", t_reached - t_switch)
        # the followers were behind the line's slots: the leader kept its usual speed
        usual = rospy.get_param("/%s/move_base/DWAPlannerROS/max_vel_x" % p.status.leader)
        self.assertLess(self.leader_top_speed(t_switch, t_done), usual + 0.02)

        # line -> column: both followers are ahead of their new slots, so the leader drives
        # faster (~switch_leader_vel) until the column is there, then as before
        t_switch = rospy.get_time()
        p.formation_pub.publish(String("column"))
        p.wait(lambda: p.assignment.formation == "column", 5.0, "the column assignment")
        t_reached, t_done = p.wait_switch_done("column", t_switch, 60.0)
        top = self.leader_top_speed(t_switch, t_done)
        rospy.loginfo("switch: column reached %.1f s after the switch, the leader at up to %.2f m/s",
                      t_reached - t_switch, top)
        self.assertGreater(top, usual + 0.05)
        self.drive_and_arrive_after_switch("column")
        self.assertAlmostEqual(rospy.get_param("/%s/move_base/DWAPlannerROS/max_vel_x" % p.status.leader), usual)
        self.assertNoContacts()

    def leader_top_speed(self, since, until):
        return max(speeds.get(a.leader, 0.0) for (t, _, _, speeds, a) in
                   self.probe.samples_in(("NAVIGATING", "ARRIVED"), since) if t <= until and a is not None)

    def drive_and_arrive_after_switch(self, formation="line"):
        p = self.probe
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 180.0, "ARRIVED")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        self.assertEqual(p.status.formation, formation)
        self.leader_at(5.0, 0.0)

    def run_loss(self):
        p = self.probe
        p.send_target(5.0, 0.0)
        p.wait(lambda: p.state() == "NAVIGATING" and p.truth[p.status.leader][1].x > -3.5, 120.0,
               "the leader on its way")
        t_kill = rospy.get_time()  # before: sim time goes on while rosnode kill runs
        subprocess.check_call(["rosnode", "kill", "/follower_1/follower_controller"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        p.wait(lambda: p.state() == "DEGRADED", 10.0, "DEGRADED")
        # when the coordinator said so (its stamp), not when this process noticed: under load
        # sim time runs on while a starved test process sleeps
        t_degraded = next(t for (t, s, _) in reversed(p.states) if s == "DEGRADED")
        # The controller's last word marks the loss (sim time runs on while rosnode kill does its
        # work); a loss is 1 s of silence, and DEGRADED must follow within 1 s of that.
        silent_since = p.last_heard("follower_1")
        rospy.loginfo("loss: DEGRADED %.2f s after follower_1's controller fell silent (%.2f s after the kill "
                      "command)", t_degraded - silent_since, t_degraded - t_kill)
        self.assertLess(t_degraded - silent_since, 2.0)
        self.assertIn("follower_1", p.status.lost)
        self.assertNotIn("follower_1", [s.robot for s in p.assignment.slots])
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 180.0, "ARRIVED")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        self.leader_at(5.0, 0.0)
        final = p.slot_errors({r: v[1] for r, v in p.truth.items()}, p.assignment)
        self.assertEqual(set(final), {"follower_2"})
        self.assertLess(final["follower_2"], 0.3)
        self.assertNoContacts()

    def run_limit(self):
        p = self.probe
        p.send_target(5.0, 0.0)
        p.wait(lambda: p.state() == "NAVIGATING", 120.0, "NAVIGATING")
        subprocess.check_call(["rosparam", "set", "/follower_1/follower_controller/max_linear_vel", "0.3"])
        t_set = rospy.get_time()  # after: the parameter is set once the command returns
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 240.0, "ARRIVED")
        after = [s for s in p.samples if s[0] >= t_set + 1.0]
        f1 = max(s[3].get("follower_1", 0.0) for s in after)
        leader = max(s[3].get("leader", 0.0) for s in after)
        rospy.loginfo("limit: follower_1 max speed %.3f m/s, leader max speed %.3f m/s", f1, leader)
        self.assertLessEqual(f1, 0.3 + 0.02)
        self.assertGreater(f1, 0.2, "follower_1 should still drive")
        self.assertGreater(leader, 0.33, "the leader must keep its own speed (0.35 m/s)")
        self.assertNoContacts()

    def run_obstacle(self):
        from mbot_msgs.srv import SpawnObstacle

        p = self.probe
        rospy.wait_for_service("/spawn_obstacle", 30.0)
        spawn = rospy.ServiceProxy("/spawn_obstacle", SpawnObstacle)
        p.send_target(5.0, 0.0)
        p.wait(lambda: p.state() == "NAVIGATING" and p.truth["leader"][1].x > -3.0, 120.0, "the leader on its way")
        leader = p.truth["leader"][1]
        box = (leader.x + 2.0, leader.y)
        answer = spawn(name="box_1", shape="cylinder", radius=0.25, pose=Pose2DMsg(box[0], box[1], 0.0))
        self.assertTrue(answer.success, answer.message)
        p.wait(lambda: p.status.paused, 20.0, "the fleet to pause for the obstacle")
        t_pause = rospy.get_time()
        p.wait(lambda: not p.status.paused, 20.0, "the fleet to resume")
        rospy.loginfo("obstacle: paused for %.1f s", rospy.get_time() - t_pause)
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 240.0, "ARRIVED")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        self.leader_at(5.0, 0.0)
        # Everyone got past the box: nobody ends up west of it.
        for r, (_, pose, _) in p.truth.items():
            self.assertGreater(pose.x, box[0] - 3.0, "%s stayed behind the obstacle at x = %.2f" % (r, pose.x))
        self.assertNoContacts()

    def run_corridor(self):
        """Diamond -> column before the 1.5 m corridor, through it, back to diamond after; the
        goal through the action /fleet/goal, the switches through the service."""
        import actionlib
        from mbot_msgs.msg import FleetGoalAction, FleetGoalGoal
        from mbot_msgs.srv import SetFormation

        p = self.probe
        client = actionlib.SimpleActionClient("/fleet/goal", FleetGoalAction)
        self.assertTrue(client.wait_for_server(rospy.Duration(30.0)), "no /fleet/goal action server")
        rospy.wait_for_service("/fleet/set_formation", 30.0)
        switch = rospy.ServiceProxy("/fleet/set_formation", SetFormation)
        client.send_goal(FleetGoalGoal(target=Pose2DMsg(13.0, 0.0, 0.0), formation="diamond", spacing=1.2))
        p.wait(lambda: p.state() == "NAVIGATING", 120.0, "NAVIGATING in a diamond")
        self.assertEqual(p.assignment.formation, "diamond")
        t_switch = rospy.get_time()
        answer = switch(formation="column", spacing=0.0)
        self.assertTrue(answer.success, answer.message)
        p.wait(lambda: p.assignment.formation == "column", 5.0, "the column assignment")
        t_reached, _ = p.wait_switch_done("column", t_switch, 60.0)
        rospy.loginfo("corridor: the column stood %.1f s after the switch", t_reached - t_switch)
        leader_x = next(poses[a.leader].x for (t, _, poses, _, a) in p.samples_in(("NAVIGATING", "FORMING"), t_reached))
        self.assertLess(leader_x, -9.8, "the column must form before the corridor:\n%s\n%s" % (
            p.describe(), "\n".join("t=%.1f %s (%s)" % s for s in p.states[-10:])))
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 300.0, "ARRIVED through the corridor")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        self.assertTrue(client.wait_for_result(rospy.Duration(10.0)))
        result = client.get_result()
        self.assertTrue(result.success, result.message)
        t_switch = rospy.get_time()
        answer = switch(formation="diamond", spacing=0.0)
        self.assertTrue(answer.success, answer.message)
        p.wait(lambda: p.assignment.formation == "diamond", 5.0, "the diamond assignment")
        p.wait_switch_done("diamond", t_switch, 90.0)
        self.leader_at(13.0, 0.0)
        self.assertNoContacts()

    def formed(self):
        """Every follower within the switch tolerance of its slot now (ground truth)."""
        errors = self.probe.slot_errors({r: v[1] for r, v in self.probe.truth.items()}, self.probe.assignment)
        return bool(errors) and max(errors.values()) < SWITCH_TOLERANCE

    def run_leader_loss(self):
        from mbot_msgs.srv import RemoveRobot

        p = self.probe
        p.send_target(5.0, 0.0)
        p.wait(lambda: p.state() == "NAVIGATING" and p.truth["leader"][1].x > -3.5, 120.0, "the leader on its way")
        remove = rospy.ServiceProxy("/remove_robot", RemoveRobot)
        answer = remove(name="leader")
        self.assertTrue(answer.success, answer.message)
        with p.lock:
            t_loss = p.truth["leader"][0]   # its last ground truth: when it left the simulation
            del p.truth["leader"]
        t_degraded = p.wait(lambda: p.state() == "DEGRADED" and p.status.leader != "leader", 10.0,
                            "a new leader")
        rospy.loginfo("leader_loss: %s leads %.2f s after the loss", p.status.leader, t_degraded - t_loss)
        self.assertLess(t_degraded - t_loss, 2.0)
        self.assertIn(p.status.leader, ("follower_1", "follower_2"))
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 240.0, "ARRIVED under the new leader")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        self.leader_at(5.0, 0.0)
        self.assertTrue(self.formed(), "the two left are not in formation:\n%s" % p.describe())
        self.assertNoContacts()

    def run_rejoin(self):
        from mbot_msgs.srv import RemoveRobot, SpawnRobot

        p = self.probe
        p.send_target(5.0, 0.0)
        p.wait(lambda: p.state() == "NAVIGATING" and p.truth["leader"][1].x > -3.5, 120.0, "the leader on its way")
        answer = rospy.ServiceProxy("/remove_robot", RemoveRobot)(name="follower_2")
        self.assertTrue(answer.success, answer.message)
        t_lost = p.wait(lambda: p.state() == "DEGRADED" and "follower_2" in p.status.lost, 10.0, "follower_2 lost")
        t_loss = p.truth["follower_2"][0]   # its last ground truth: when it left the simulation
        self.assertLess(t_lost - t_loss, 2.0)
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 240.0, "ARRIVED without follower_2")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        # follower_2 comes back near the fleet and takes a slot again, without restarting anyone
        spawn = rospy.ServiceProxy("/spawn_robot", SpawnRobot)
        answer = spawn(name="follower_2", model="mbot", pose=Pose2DMsg(1.0, -3.0, 0.0))
        self.assertTrue(answer.success, answer.message)
        t_back = rospy.get_time()
        t_rejoined = p.wait(lambda: "follower_2" not in p.status.lost and "follower_2" in [
            s.robot for s in p.assignment.slots], 20.0, "follower_2 to rejoin")
        p.wait_switch_done("triangle", t_rejoined, 90.0)   # the new slots, as after a switch
        rospy.loginfo("rejoin: back in formation %.1f s after the respawn", rospy.get_time() - t_back)
        self.assertNoContacts()

    def run_wall(self):
        from mbot_msgs.msg import FollowerState

        p = self.probe
        north_y = 10.0 - 0.4   # the room's north wall (inner face) less a robot's size
        modes = {}             # follower -> its controller's modes while its slot lay beyond the wall

        def on_state(msg):
            slots = p.slot_poses({r: v[1] for r, v in p.truth.items()}, p.assignment)
            if msg.robot in slots and slots[msg.robot].y > north_y:
                modes.setdefault(msg.robot, []).append(msg.mode)

        for robot in robots_param()[1:]:
            rospy.Subscriber("/%s/follower_controller/state" % robot, FollowerState, on_state, queue_size=20)
        p.formation_pub.publish(String("line"))
        p.wait(lambda: p.assignment is not None and p.assignment.formation == "line", 10.0, "the line")
        # the leader 1.8 m from the wall, facing east: its left slot (2.5 m) lies beyond the wall
        self.drive_and_arrive(0.0, 8.2)
        self.assertTrue(modes, "no slot lay beyond the wall")
        for robot, seen in modes.items():
            rospy.loginfo("wall: %s's modes while its slot lay beyond the wall: %s", robot,
                          {m: seen.count(m) for m in set(seen)})
            self.assertIn("trail", seen, "%s chased its slot beyond the wall" % robot)
            self.assertLess(p.truth[robot][1].y, north_y, "%s went into the wall" % robot)
        self.assertNoContacts()
        # back south-east, away from the wall: the slot is free again and taken again. The leader
        # turns across its trailing follower, which must pass in front of it to its new slot.
        self.drive_and_arrive(5.0, 2.0)
        final = p.slot_errors({r: v[1] for r, v in p.truth.items()}, p.assignment)
        self.assertLess(max(final.values()), 0.3, "final slot errors %s" % final)
        self.assertNoContacts()

    def run_refuse(self):
        from mbot_msgs.srv import SetFormation

        p = self.probe
        rospy.wait_for_service("/fleet/set_formation", 30.0)
        switch = rospy.ServiceProxy("/fleet/set_formation", SetFormation)
        before = (p.state(), p.assignment.formation if p.assignment else None)
        answer = switch(formation="hexagon", spacing=0.0)
        self.assertFalse(answer.success)
        self.assertIn("hexagon", answer.message)
        self.assertIn("triangle", answer.message, "the refusal should list the known formations")
        for target, words in (((float("nan"), 0.0), "not a finite pose"), ((10.5, 0.0), "off the map"),
                              ((9.95, 0.0), "in a wall")):
            p.send_target(*target)
            p.wait(lambda: words in p.status.reason, 10.0, "the refusal %r in the status" % words)
            self.assertEqual((p.state(), p.assignment.formation if p.assignment else None), before)
        p.formation_pub.publish(String("hexagon"))
        p.wait(lambda: "hexagon" in p.status.reason, 10.0, "the refusal of hexagon in the status")
        self.assertEqual(p.state(), "IDLE")
        client = self.fleet_goal_client()
        result = self.fleet_goal(client, 9.95, 0.0)
        self.assertEqual(client.get_state(), GoalStatus.ABORTED)
        self.assertFalse(result.success)
        self.assertIn("in a wall", result.message)
        self.assertEqual(p.state(), "IDLE")
        # and the fleet still works afterwards: on /fleet/target_pose, then by the action
        debug_lines = self.collect_debug_lines()
        target_pub = rospy.Publisher("/fleet/target_pose", Pose2DMsg, queue_size=1, latch=True)
        target_pub.publish(Pose2DMsg(2.0, 0.0, 0.0))
        p.wait(lambda: p.state() in ("FORMING", "NAVIGATING"), 10.0, "the goal on /fleet/target_pose")
        p.wait(lambda: p.state() in ("ARRIVED", "ABORTED"), 180.0, "ARRIVED")
        self.assertEqual(p.state(), "ARRIVED", p.status.reason)
        self.leader_at(2.0, 0.0)
        feedback = []
        result = self.fleet_goal(client, 3.5, 0.0, feedback)
        self.assertTrue(result.success, result.message)
        self.leader_at(3.5, 0.0)
        self.assertIn("NAVIGATING", [f.state for f in feedback])
        self.assertTrue(any(0.0 < f.distance_to_goal < 1.6 and math.isfinite(f.rms_error) for f in feedback),
                        "no feedback with the distance to the goal and the slot error")
        self.check_outputs(debug_lines)

    def fleet_goal_client(self):
        import actionlib
        from mbot_msgs.msg import FleetGoalAction

        client = actionlib.SimpleActionClient("/fleet/goal", FleetGoalAction)
        self.assertTrue(client.wait_for_server(rospy.Duration(30.0)), "no /fleet/goal action server")
        return client

    def fleet_goal(self, client, x, y, feedback=None):
        """Send the action goal (x, y) and wait (in sim time, with a wall bound) for its result."""
        from actionlib import SimpleGoalState
        from mbot_msgs.msg import FleetGoalGoal

        client.send_goal(FleetGoalGoal(target=Pose2DMsg(x, y, 0.0)),
                         feedback_cb=feedback.append if feedback is not None else None)
        # DONE once the result itself is here (the status array may say SUCCEEDED before it)
        self.probe.wait(lambda: client.simple_state == SimpleGoalState.DONE, 180.0,
                        "the result of the goal (%.1f, %.1f)" % (x, y))
        return client.get_result()

    def collect_debug_lines(self):
        from rosgraph_msgs.msg import Log

        lines = []
        rospy.Subscriber("/rosout", Log, lambda m: lines.append(m.msg) if "slot error" in m.msg else None,
                         queue_size=100)
        return lines

    def check_outputs(self, debug_lines):
        """What a student looks at: the latched assignment (a late subscriber gets it), the live
        metrics, and ~debug_mode's slot errors (this test's launch sets it)."""
        from mbot_msgs.msg import FleetAssignment, FleetMetrics

        latched = rospy.wait_for_message("/fleet/assignment", FleetAssignment, 10.0)
        self.assertEqual(latched.formation, self.probe.assignment.formation)
        self.assertEqual(latched.leader, "leader")
        metrics = rospy.wait_for_message("/fleet/metrics", FleetMetrics, 10.0)
        self.assertEqual((metrics.state, metrics.contacts), ("ARRIVED", 0))
        self.assertTrue(math.isfinite(metrics.slot_rms), metrics.slot_rms)
        self.assertGreater(metrics.distance, 3.0)   # the leader alone drove 3.5 m
        for robot in ("follower_1", "follower_2"):
            self.assertTrue([line for line in debug_lines if robot + " slot error" in line and " cm, " in line
                             and line.endswith(" deg")], "no debug_mode line for %s in %s" % (robot, debug_lines[-4:]))


if __name__ == "__main__":
    rostest.rosrun("mbot_follower", "formation_checks", FormationChecks, sys.argv)
