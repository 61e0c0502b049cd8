"""Playing a scenario's timeline (scenario.Timeline) on a running fleet: ScenarioPlayer sends
targets, formations, dispatches, obstacles and faults at their moments, watches the fleet's
events and returns the facts the judging needs. The scenario rostests use it too
(test/rostest/scenario_check.py)."""
import json
import math
import shutil
import sys
import time

from mbot_bringup.console import say
from mbot_bringup.fleet_launch import WALL_PER_SIM, start_wall
from mbot_bringup.scenario import Timeline, TimelineConfig, loss_detection_times
from mbot_follower.metrics.settle import SwitchSettle

STATUS_PERIOD = 10.0       # [s wall] a new status line when the output is not a terminal
STATE_EVENTS = {"FORMING": "forming", "NAVIGATING": "navigating", "ARRIVED": "arrived", "DEGRADED": "degraded",
                "ABORTED": "aborted"}
SUCCEEDED = 3              # actionlib_msgs/GoalStatus
TERMINAL = (2, 3, 4, 5, 8)  # PREEMPTED, SUCCEEDED, ABORTED, REJECTED, RECALLED


def round_ended(results, round_goals):
    """The results [(t, robot, status, goal id)] that ended a goal of `round_goals` (ids)."""
    return [x for x in results if x[3] in round_goals and x[2] in TERMINAL]


class ScenarioPlayer(object):
    """Plays a scenario's timeline on a running fleet (rospy is initialised by the caller) and
    returns what happened. Events come from /fleet/status (state changes, pauses), from the
    ground truth (formed: the metrics' switch rule, SwitchSettle) and from the robots' move_base
    results (goals_done)."""

    def __init__(self, scenario, robots, run_dir, screenshots=None, config=None, show_status=True):
        import rospy
        from geometry_msgs.msg import Pose2D as Pose2DMsg, PoseArray
        from move_base_msgs.msg import MoveBaseActionGoal, MoveBaseActionResult

        from mbot_follower.fleet_probe import FleetProbe

        self.rospy = rospy
        self.scenario = scenario
        self.robots = list(robots)
        self.run_dir = run_dir
        self.screenshots = screenshots
        self.config = config or TimelineConfig()
        self.show_status = show_status
        self.timeline = Timeline(scenario, self.config)
        self.probe = FleetProbe(self.robots)
        self.Pose2DMsg, self.PoseArray = Pose2DMsg, PoseArray
        self.target_pub = rospy.Publisher("/fleet/target_pose", Pose2DMsg, queue_size=1, latch=True)
        self.dispatch_pub = rospy.Publisher("/dispatch/goals", PoseArray, queue_size=1, latch=True)
        self.results = []          # (t, robot, status, goal id) of every move_base goal that ended
        # The goals of the newest dispatch, by id: a result counts for it only when its goal was
        # sent after the dispatch. By time alone, the previous round's last result, which set the
        # dispatch off in the same sim instant, counted for the new round too (ended it early).
        self.round_goals = set()
        for r in self.robots:
            rospy.Subscriber("/%s/move_base/result" % r, MoveBaseActionResult, self._on_result, callback_args=r,
                             queue_size=20)
            rospy.Subscriber("/%s/move_base/goal" % r, MoveBaseActionGoal, self._on_goal, queue_size=20)
        # The dispatcher's queue (dispatcher_node: a line per robot driving or goal waiting; empty: idle)
        self.dispatcher_idle = True
        self.busy_since_step = False   # the dispatcher had work after the newest dispatch step
        from std_msgs.msg import String
        rospy.Subscriber("/dispatch/assignment", String, self._on_dispatch_queue, queue_size=10)
        self.t0 = None
        self.log = []              # what each step did: {t_s, step, when, action, ok, message}
        self.failed_steps = 0
        self.targets = 0
        self.dispatched = 0        # goals sent in all
        self.round_size = None     # goals of the newest dispatch step (their ids: round_goals)
        self.pending_shots = []    # (t, name)
        self.awaiting_formation = None
        self.settle = SwitchSettle()   # the current formation stands (`formed`)
        self.formed = False
        self.paused = False
        self.states_seen = 0
        self.goals_done_sent = False
        self.mid_route = None      # (start (x, y), target (x, y)) of the route being shot, until its screenshot
        self.mid_route_taken = False
        # the legs between the timeline's targets: the mid-route shot goes to the longest route
        targets = [s.arg for s in self.timeline.steps if s.action == "target"]
        self.later_legs = [math.hypot(b[0] - a[0], b[1] - a[1]) for a, b in zip(targets, targets[1:])]
        self.forming_shot = False

    def _on_result(self, msg, robot):
        with self.probe.lock:
            self.results.append((self.rospy.get_time(), robot, msg.status.status, msg.status.goal_id.id))

    def _on_dispatch_queue(self, msg):
        with self.probe.lock:
            self.dispatcher_idle = not msg.data.strip()
            if not self.dispatcher_idle and self.round_size is not None:
                self.busy_since_step = True

    def _on_goal(self, msg):
        with self.probe.lock:
            self.round_goals.add(msg.goal_id.id)

    def now(self):
        return self.rospy.get_time() - self.t0

    # --- start ---------------------------------------------------------------------------------

    def wait_ready(self, wall_timeout=None):
        """Wait (wall time, start_wall() for this fleet unless given) until every robot, its
        controller and move_base answer (formation mode: and the coordinator); then the
        scenario's clock starts."""
        from mbot_navigation.move_base_client import connect_move_base

        wall_timeout = wall_timeout or start_wall(len(self.robots))
        if self.scenario.mode == "formation":
            self.probe.wait_for_fleet(wall_timeout)
        else:
            end = time.time() + wall_timeout
            while time.time() < end and not self.rospy.is_shutdown():
                with self.probe.lock:
                    if len(self.probe.truth) == len(self.robots):
                        break
                time.sleep(0.1)
            missing = sorted(set(self.robots) - set(self.probe.truth))
            if missing:
                raise RuntimeError("no ground truth of %s after %.0f s wall" % (", ".join(missing), wall_timeout))
            for r in self.robots:
                connect_move_base(r, max(1.0, end - time.time()))
        self.t0 = self.rospy.get_time()

    # --- events --------------------------------------------------------------------------------

    def _slot_errors(self):
        p = self.probe
        with p.lock:
            poses = {r: v[1] for r, v in p.truth.items()}
            assignment = p.assignment
        return p.slot_errors(poses, assignment), assignment

    def _observe(self, t):
        """Turn what the probe saw since the last call into timeline events at t [s]."""
        p = self.probe
        with p.lock:
            new_states = p.states[self.states_seen:]
            self.states_seen = len(p.states)
            status = p.status
            results = list(self.results)
        for (ts, state, _reason) in new_states:
            if state in STATE_EVENTS:
                self.timeline.observe(STATE_EVENTS[state], max(0.0, ts - self.t0))
                if state == "FORMING" and not self.forming_shot:
                    self.forming_shot = True
                    self._shot_later(t + 1.0, "forming")
        if status is not None:
            if status.paused and not self.paused:
                self.timeline.observe("paused", t)
            self.paused = status.paused

        errors, assignment = self._slot_errors()
        current = assignment is not None and (self.awaiting_formation is None
                                              or assignment.formation == self.awaiting_formation)
        if current and self.awaiting_formation is not None:
            self.awaiting_formation = None
        if not (current and errors and self.settle.within(errors)):
            self.settle.reset()   # formed again only after the rule held again
            self.formed = False
        elif self.settle.update(t, errors) and not self.formed:
            self.formed = True
            self.timeline.observe("formed", t)

        if self.round_size is not None and not self.goals_done_sent:
            # done: the dispatcher had the step's goals, has no goal left (none driven, none
            # waiting: it may queue more goals than robots, and refuse some) and every goal it
            # sent since the step has its result
            with self.probe.lock:
                round_goals = set(self.round_goals)
                idle = self.busy_since_step and self.dispatcher_idle
            if idle and round_goals and len(round_ended(results, round_goals)) >= len(round_goals):
                self.goals_done_sent = True
                self.timeline.observe("goals_done", t)

        if self.mid_route is not None and status is not None and status.state == "NAVIGATING":
            (sx, sy), (gx, gy) = self.mid_route
            with p.lock:
                lead = p.truth.get(status.leader)
            if lead is not None and math.hypot(lead[1].x - gx, lead[1].y - gy) <= 0.5 * math.hypot(gx - sx, gy - sy):
                self._shot_later(t, "mid_route")
                self.mid_route = None
                self.mid_route_taken = True

    def _shot_later(self, t, name):
        if self.screenshots is not None:
            self.pending_shots.append((t, name))

    def _take_due_shots(self, t):
        for due in [s for s in self.pending_shots if s[0] <= t]:
            self.pending_shots.remove(due)
            self.screenshots.request(due[1])

    # --- actions -------------------------------------------------------------------------------

    def _service(self, name, kind):
        self.rospy.wait_for_service(name, 10.0)
        return self.rospy.ServiceProxy(name, kind)

    def _do(self, step, t):
        """Carry out one step; returns (ok, message)."""
        rospy, a = self.rospy, step.arg
        if step.action == "target":
            self.target_pub.publish(self.Pose2DMsg(a[0], a[1], a[2]))
            self.targets += 1
            if not self.mid_route_taken:
                with self.probe.lock:
                    leader = self.probe.status.leader if self.probe.status else ""
                    lead = self.probe.truth.get(leader)
                # this route gets the shot unless a later leg of the timeline is longer
                later = self.later_legs[self.targets - 1:]
                if lead is not None and math.hypot(a[0] - lead[1].x, a[1] - lead[1].y) >= max(later + [0.0]):
                    self.mid_route = ((lead[1].x, lead[1].y), (a[0], a[1]))
            return True, "sent"
        if step.action == "formation":
            from mbot_msgs.srv import SetFormation

            answer = self._service("/fleet/set_formation", SetFormation)(formation=a["name"], spacing=a["spacing"])
            if answer.success:
                self.awaiting_formation = a["name"]
                self.formed = False
                self.settle.reset()
                self._shot_later(t + 3.0, "switch_%s" % a["name"])
            return answer.success, answer.message
        if step.action == "kill_controller":
            import rosnode

            node = "/%s/follower_controller" % a
            killed, failed = rosnode.kill_nodes([node])
            self._shot_later(t + 2.0, "loss")
            return bool(killed) and not failed, "killed %s" % node if killed else "could not kill %s" % node
        if step.action == "remove_robot":
            from mbot_msgs.srv import RemoveRobot

            answer = self._service("/remove_robot", RemoveRobot)(name=a)
            if answer.success:
                with self.probe.lock:
                    self.probe.truth.pop(a, None)
                self._shot_later(t + 2.0, "loss")
            return answer.success, answer.message
        if step.action == "spawn_robot":
            from mbot_msgs.srv import SpawnRobot

            answer = self._service("/spawn_robot", SpawnRobot)(name=a["name"], model=a["model"],
                                                               pose=self.Pose2DMsg(*a["pose"]))
            return answer.success, answer.message
        if step.action == "spawn_obstacle":
            from mbot_msgs.srv import SpawnObstacle

            answer = self._service("/spawn_obstacle", SpawnObstacle)(
                name=a["name"], shape=a["shape"], length=a["length"], width=a["width"], radius=a["radius"],
                pose=self.Pose2DMsg(*a["pose"]))
            return answer.success, answer.message
        if step.action == "remove_obstacle":
            from mbot_msgs.srv import RemoveObstacle

            answer = self._service("/remove_obstacle", RemoveObstacle)(name=a)
            return answer.success, answer.message
        if step.action == "set_param":
            rospy.set_param(a["name"], a["value"])
            return True, "%s = %r" % (a["name"], a["value"])
        if step.action == "fault":
            from mbot_msgs.srv import SetFault

            answer = self._service("/set_fault", SetFault)(**a)
            return answer.success, answer.message
        if step.action == "dispatch":
            from geometry_msgs.msg import Pose

            from mbot_common.geometry import quaternion_from_yaw

            msg = self.PoseArray()
            msg.header.frame_id = "map"
            msg.header.stamp = rospy.Time.now()
            for x, y, yaw in a:
                pose = Pose()
                pose.position.x, pose.position.y = x, y
                (pose.orientation.x, pose.orientation.y, pose.orientation.z,
                 pose.orientation.w) = quaternion_from_yaw(yaw)
                msg.poses.append(pose)
            with self.probe.lock:
                self.round_goals = set()  # before the dispatcher can send the first of them
                self.busy_since_step = False
                self.round_size = len(a)
                self.goals_done_sent = False
            self.dispatch_pub.publish(msg)
            self.dispatched += len(a)
            self._shot_later(t + 5.0, "dispatch")
            return True, "sent %d goals" % len(a)
        if step.action == "screenshot":
            self._shot_later(t, a)
            return True, "requested"
        raise AssertionError(step.action)

    def _run_step(self, step, t):
        try:
            ok, message = self._do(step, t)
        except Exception as error:  # a service that is not there, a refused call: the step failed
            ok, message = False, "%s: %s" % (type(error).__name__, error)
        self.timeline.done(step, self.now())
        if not ok:
            self.failed_steps += 1
        self.log.append({"t_s": round(t, 3), "step": step.key, "when": step.when(), "action": step.describe(),
                         "ok": ok, "message": message})
        text = "%6.1f s  %s %s: %s%s" % (t, step.key, step.describe(), "" if ok else "FAILED: ", message)
        if self.show_status:
            self.clear_status()
            say(text)
        else:
            (self.rospy.loginfo if ok else self.rospy.logerr)("scenario %s: %s", self.scenario.name, text)

    # --- the loop ------------------------------------------------------------------------------

    def goals_reached(self):
        with self.probe.lock:
            return sum(1 for (ts, _, s, _) in self.results if ts >= self.t0 and s == SUCCEEDED)

    def status_line(self, t):
        p = self.probe
        state = p.state() or "-"
        errors, _ = self._slot_errors()
        error = "%.2f m" % math.sqrt(sum(e * e for e in errors.values()) / len(errors)) if errors else "-"
        if self.scenario.mode == "formation":
            arrivals = sum(1 for (n, _) in self.timeline.events if n == "arrived")
            goals = "%d/%d" % (arrivals, len(self.scenario.steps("target")))
        else:
            goals = "%d/%d" % (self.goals_reached(), sum(len(s.arg) for s in self.scenario.steps("dispatch")))
        waiting = self.timeline.next_step()
        step = ("step %d/%d %s" % (waiting.index + 1, len(self.timeline.steps), waiting.when()) if waiting
                else "end: %s" % self.timeline.end_event)
        return "%s  %-10s t %6.1f/%g s  error %s  goals %s  %s" % (
            self.scenario.name, state, t, self.scenario.time_limit, error, goals, step)

    def clear_status(self):
        if self.show_status and sys.stderr.isatty():
            sys.stderr.write("\r\033[K")

    def show(self, t, last_shown):
        if not self.show_status:
            return last_shown
        line = self.status_line(t)
        if sys.stderr.isatty():
            width = shutil.get_terminal_size((120, 20)).columns
            sys.stderr.write("\r\033[K" + line[:width - 1])
            sys.stderr.flush()
            return time.time()
        if time.time() - last_shown >= STATUS_PERIOD:
            say(line)
            return time.time()
        return last_shown

    def play(self, wall_limit=None, alive=None):
        """Play the timeline until it finishes, the time limit passes (sim time), wall_limit
        [s wall] passes or alive() (the fleet's processes) turns False; returns the facts for
        the criteria."""
        rospy = self.rospy
        wall_end = time.time() + (wall_limit or self.scenario.time_limit * WALL_PER_SIM)
        last_shown = 0.0
        t = 0.0
        while not rospy.is_shutdown():
            t = self.now()
            self._observe(t)
            for step in self.timeline.due(t):
                self._run_step(step, t)
            self._take_due_shots(t)
            last_shown = self.show(t, last_shown)
            if self.timeline.finished(t) or self.timeline.timed_out(t) or time.time() > wall_end:
                break
            if alive is not None and not alive():
                self.clear_status()
                say("%s: the fleet stopped at %.1f s sim (a required node ended)" % (self.scenario.name, t))
                break
            time.sleep(0.05)
        self.clear_status()
        finished = self.timeline.finished(t)
        if not finished:
            waiting = self.timeline.next_step()
            say("%s: time is up at %.1f s sim (%s)" % (
                self.scenario.name, t, "waiting for %s: %s" % (waiting.key, waiting.when()) if waiting
                else "waiting for the end event %s" % self.timeline.end_event))
        if self.screenshots is not None:
            self.screenshots.request("arrival" if finished else "end")
        return self.facts(t, finished)

    def facts(self, t, finished):
        arrivals = sum(1 for (n, _) in self.timeline.events if n == "arrived")
        final = self.probe.state()
        with self.probe.lock:
            lost = list(self.probe.status.lost) if self.probe.status is not None else []
        return {"finished": finished,
                "arrived": final == "ARRIVED" and arrivals >= self.targets and self.targets > 0,
                "arrivals": arrivals, "targets": self.targets, "final_state": final or "",
                "goals_reached": self.goals_reached(), "goals": self.dispatched,
                "failed_steps": self.failed_steps, "lost_at_end": len(lost),
                "loss_detection_s": loss_detection_times(self.timeline),
                "start_s": self.t0, "end_s": t}

    def write_log(self, path):
        with open(path, "w") as f:
            json.dump({"scenario": self.scenario.name, "steps": self.log,
                       "events": [{"t_s": round(t, 3), "event": n} for (n, t) in self.timeline.events]}, f, indent=1)
            f.write("\n")
