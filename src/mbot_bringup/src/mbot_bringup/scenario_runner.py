"""Run a scenario (scenario.py) on a fleet and judge it: the ROS side.

    scripts/scenario office_route [--run-dir DIR] [--no-rviz] [--real-time] [--list]
    rosrun mbot_bringup scenario_runner triangle_trio --run-dir /tmp/run

The runner
1. reads the scenario and the run's world (robots placed as fleet.launch will place them) and
   checks the scenario against it, before anything starts;
2. starts `roslaunch mbot_bringup fleet.launch` with its own master on a free port (lockstep at
   real_time_factor 0 unless --real-time, rviz if there is a DISPLAY and not --no-rviz, a rosbag);
3. plays the timeline in sim time (ScenarioPlayer), showing one status line, and takes rviz
   screenshots at moments (forming, mid_route: halfway along the timeline's longest route,
   switch_<formation>, loss, arrival, and the timeline's own `screenshot` steps);
4. stops what it started (by PID: SIGINT to roslaunch, which stops its nodes; later signals only
   to its own process group) at the end, on a timeout or on Ctrl-C;
5. judges the criteria from the metrics collector's files (load_run / summarize), writes
   RUN_DIR/criteria.json and prints PASS/FAIL per criterion. Exit status 0: passed, 1: a
   criterion failed, 2: a bad scenario or command line, 3: the fleet did not come up.

Run dir: scenario.yaml (a copy), world.yaml, metrics/, run.bag, criteria.json, timeline.json (what
each step did and when), screenshots/*.png, launch.log, ros_logs/.

ScenarioPlayer is also what the scenario rostests use (test/rostest/scenario_check.py).
"""
import contextlib
import json
import math
import os
import shutil
import signal
import subprocess
import sys
import threading
import time

from mbot_bringup.processes import descendants, start_time, stop_pids
from mbot_bringup.scenario import (CRITERIA, Timeline, TimelineConfig, check_against_world, evaluate, load_scenario,
                                   loss_detection_times, scenario_window, summary_lines)
from mbot_common.strict_yaml import ConfigError

WALL_PER_SIM = 20.0        # a run gives up after time_limit x this + START_WALL wall seconds
START_WALL = 180.0         # [s wall] for a fleet of up to START_ROBOTS robots to come up
START_ROBOTS = 20
START_WALL_PER_ROBOT = 6.0  # [s wall] more per robot beyond: 40 robots took 177 s on 2 cores


def start_wall(robots):
    """How long [s wall] a fleet of `robots` robots may take to come up: every robot's processes
    start on the same cores (a 40-robot fleet starts about 200 processes)."""
    return START_WALL + START_WALL_PER_ROBOT * max(0, robots - START_ROBOTS)


STATUS_PERIOD = 10.0       # [s wall] a new status line when the output is not a terminal
STATE_EVENTS = {"FORMING": "forming", "NAVIGATING": "navigating", "ARRIVED": "arrived", "DEGRADED": "degraded",
                "ABORTED": "aborted"}
SUCCEEDED = 3              # actionlib_msgs/GoalStatus
TERMINAL = (2, 3, 4, 5, 8)  # PREEMPTED, SUCCEEDED, ABORTED, REJECTED, RECALLED


def round_ended(results, round_goals):
    """The results [(t, robot, status, goal id)] that ended a goal of `round_goals` (ids)."""
    return [x for x in results if x[3] in round_goals and x[2] in TERMINAL]


def say(text):
    sys.stderr.write("\033[1m[mbot]\033[0m %s\n" % text)
    sys.stderr.flush()


# --- finding scenarios ----------------------------------------------------------------------

def scenarios_directory():
    """The package's scenarios/ folder (source or installed)."""
    import rospkg

    return os.path.join(rospkg.RosPack().get_path("mbot_bringup"), "scenarios")


def scenario_path(name_or_path):
    """A name means scenarios/NAME.yaml of the package; anything with a / or .yaml is a path."""
    if "/" in name_or_path or name_or_path.endswith(".yaml"):
        return os.path.abspath(name_or_path)
    path = os.path.join(scenarios_directory(), name_or_path + ".yaml")
    if not os.path.isfile(path):
        raise ConfigError('scenario "%s": no file %s (scenarios: %s)'
                          % (name_or_path, path, ", ".join(list_scenarios())))
    return path


def list_scenarios():
    return sorted(f[:-5] for f in os.listdir(scenarios_directory()) if f.endswith(".yaml"))


def world_argument(scenario):
    """The scenario's world for fleet.launch: a name as it is, a relative path from the scenario's folder."""
    world = scenario.world
    if ("/" in world or world.endswith(".yaml")) and not os.path.isabs(world):
        world = os.path.join(os.path.dirname(os.path.abspath(scenario.path)), world)
    return world


# --- screenshots ----------------------------------------------------------------------------

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


# --- playing a scenario ---------------------------------------------------------------------

class ScenarioPlayer(object):
    """Plays a scenario's timeline on a running fleet (rospy is initialised by the caller) and
    returns what happened. Events come from /fleet/status (state changes, pauses), from the
    ground truth (formed) and from the robots' move_base results (goals_done)."""

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
        self.t0 = None
        self.log = []              # what each step did: {t_s, step, when, action, ok, message}
        self.failed_steps = 0
        self.targets = 0
        self.dispatched = 0        # goals sent in all
        self.round_size = None     # goals of the newest dispatch step (their ids: round_goals)
        self.pending_shots = []    # (t, name)
        self.awaiting_formation = None
        self.formed_since = None
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
        within = current and bool(errors) and max(errors.values()) < self.config.formed_tolerance
        if not within:
            self.formed_since, self.formed = None, False
        elif self.formed_since is None:
            self.formed_since = t
        if within and not self.formed and t - self.formed_since >= self.config.formed_hold:
            self.formed = True
            self.timeline.observe("formed", t)

        if self.round_size is not None and not self.goals_done_sent:
            goals = self.round_size
            with self.probe.lock:
                round_goals = set(self.round_goals)
            if len(round_ended(results, round_goals)) >= goals:
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
                self.formed, self.formed_since = False, None
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
            self.dispatch_pub.publish(msg)
            self.dispatched += len(a)
            self.round_size = len(a)
            self.goals_done_sent = False
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


# --- judging --------------------------------------------------------------------------------

def judge(scenario, metrics_dir, facts):
    """(criteria results, summary or None): the criteria against the metrics files of the run,
    over the scenario's time (facts start_s to end_s, sim time)."""
    from mbot_follower.metrics import RunFileError, load_run, summarize

    try:
        run = scenario_window(load_run(metrics_dir), facts["start_s"], facts["start_s"] + facts["end_s"])
        summary = summarize(run)
    except (RunFileError, OSError) as error:
        say("no metrics to judge: %s" % error)
        return [{"name": n, "value": None, "threshold": v, "op": CRITERIA[n][0], "passed": False}
                for n, v in scenario.criteria.items()], None
    return evaluate(scenario.criteria, summary, run, facts), summary


def write_criteria(path, scenario, results, facts):
    with open(path, "w") as f:
        json.dump({"scenario": scenario.name, "passed": all(c["passed"] for c in results), "criteria": results,
                   "facts": facts}, f, indent=1)
        f.write("\n")


# --- the whole run --------------------------------------------------------------------------

def free_port():
    import socket

    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    port = s.getsockname()[1]
    s.close()
    return port


def prepare_run_dir(run_dir):
    """An empty run dir: a previous run's (it has scenario.yaml) is cleared; anything else that
    is not empty is refused, so a wrong --run-dir never deletes someone's files."""
    if os.path.isdir(run_dir) and os.listdir(run_dir):
        if not os.path.isfile(os.path.join(run_dir, "scenario.yaml")):
            raise ConfigError("%s: not empty and not a run dir (no scenario.yaml): choose another --run-dir" % run_dir)
        shutil.rmtree(run_dir)
    os.makedirs(run_dir, exist_ok=True)


class FleetLaunch(object):
    """`roslaunch -p PORT mbot_bringup fleet.launch ...` in its own process group; stop() ends it by PID."""

    def __init__(self, port, args, log_path, env):
        self.log_path = log_path
        self.log = open(log_path, "w")
        command = ["roslaunch", "-p", str(port), "mbot_bringup", "fleet.launch"] + ["%s:=%s" % kv for kv in args]
        self.log.write("# %s\n" % " ".join(command))
        self.log.flush()
        self.process = subprocess.Popen(command, stdout=self.log, stderr=subprocess.STDOUT, env=env,
                                        start_new_session=True)

    def alive(self):
        return self.process.poll() is None

    def tail(self, lines=12):
        with open(self.log_path) as f:
            return "".join(f.readlines()[-lines:])

    def stop(self):
        """SIGINT (roslaunch stops its nodes, the metrics collector and rosbag write their files),
        then SIGTERM, then SIGKILL to the process group we started."""
        p = self.process
        # Every process of the fleet, taken before anything stops: once roslaunch is gone its
        # nodes' parent is init and nothing leads to them (an interrupted 40-robot run left 150
        # nav and localization nodes running).
        tree = [(pid, start_time(pid)) for pid in descendants(p.pid)]
        for sig, wait in ((signal.SIGINT, 60.0), (signal.SIGTERM, 15.0)):
            if p.poll() is not None:
                break
            p.send_signal(sig)
            try:
                p.wait(wait)
            except subprocess.TimeoutExpired:
                pass
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
        else:
            try:   # nodes that outlived roslaunch, in the group we started
                os.killpg(p.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        stop_pids(tree)  # and those in sessions of their own
        self.log.close()


def run(args):
    """The whole run (module docstring); returns the exit status."""
    from mbot_bringup.fleet_world import run_world
    from mbot_common.paths import resolve_world

    try:
        scenario = load_scenario(scenario_path(args.scenario))
        robots = run_world(resolve_world(world_argument(scenario)), scenario.robots)[1]
        check_against_world(scenario, robots)
        run_dir = os.path.abspath(args.run_dir or os.path.join(os.path.expanduser("~/.ros/mbot_runs"), scenario.name))
        prepare_run_dir(run_dir)
    except ConfigError as error:
        say("error: %s" % error)
        return 2
    shutil.copyfile(scenario.path, os.path.join(run_dir, "scenario.yaml"))

    rviz = not args.no_rviz and bool(os.environ.get("DISPLAY"))
    if not args.no_rviz and not rviz:
        say("no DISPLAY: no rviz and no screenshots (scripts/scenario starts Xvfb)")
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % port, ROS_LOG_DIR=os.path.join(run_dir, "ros_logs"))
    os.environ.update(ROS_MASTER_URI=env["ROS_MASTER_URI"], ROS_LOG_DIR=env["ROS_LOG_DIR"])
    launch_args = [("world", world_argument(scenario)), ("robots", "" if scenario.robots is None else scenario.robots),
                   ("mode", scenario.mode), ("localization", scenario.localization),
                   ("real_time_factor", 1 if args.real_time else 0),
                   ("lockstep", "false" if args.real_time else "true"),
                   ("rviz", "true" if rviz else "false"), ("record", "false" if args.no_record else "true"),
                   ("run_dir", run_dir)]
    if scenario.mode == "formation":
        launch_args += [("leader", scenario.leader), ("formation", scenario.formation), ("spacing", scenario.spacing),
                        ("topology", scenario.topology), ("controller", scenario.controller),
                        ("leader_max_vel", scenario.leader_max_vel)]
    say("scenario %s: %d robots in %s, %s; run dir %s (master on port %d)" % (
        scenario.name, len(robots), scenario.world,
        "%s %g m" % (scenario.formation, scenario.spacing) if scenario.mode == "formation" else "dispatch",
        run_dir, port))

    launch = FleetLaunch(port, launch_args, os.path.join(run_dir, "launch.log"), env)
    screenshots = None
    player = None
    status = 0
    try:
        import rosgraph
        import rospy

        end = time.time() + 60.0
        # rospy reads /use_sim_time once, in init_node: wait until roslaunch has set it, or the
        # runner would keep wall time while everything else runs on sim time.
        while not _sim_time_set(rosgraph):
            if not launch.alive() or time.time() > end:
                say("error: the fleet did not start; the end of %s:\n%s" % (launch.log_path, launch.tail()))
                return 3
            time.sleep(0.2)
        rospy.init_node("scenario_runner", disable_signals=True)
        if rviz:
            # lockstep runs far ahead of rviz: pause for each shot; real time needs no pause
            screenshots = Screenshots(os.environ["DISPLAY"], os.path.join(run_dir, "screenshots"),
                                      hold=None if args.real_time else SimPause())
        player = ScenarioPlayer(scenario, robots, run_dir, screenshots)
        try:
            player.wait_ready()
            if screenshots is not None and not screenshots.wait_drawn():
                say("rviz shows nothing after 90 s: the screenshots may be blank")
            player.t0 = rospy.get_time()   # the scenario's clock starts now
        except (RuntimeError, AssertionError) as error:
            say("error: the fleet did not come up: %s\nthe end of %s:\n%s" % (error, launch.log_path, launch.tail()))
            return 3
        say("fleet up; playing %d steps (time limit %g s sim)" % (len(scenario.timeline), scenario.time_limit))
        facts = player.play(alive=launch.alive)
        say("scenario over at %.1f s sim: stopping the fleet" % facts["end_s"])
        if screenshots is not None:
            screenshots.close()
    except KeyboardInterrupt:
        if player is not None:
            player.clear_status()
        say("interrupted: stopping everything this run started")
        status = 130
    finally:
        if "rospy" in sys.modules:
            sys.modules["rospy"].signal_shutdown("scenario over")
        launch.stop()
        if player is not None and player.t0 is not None:
            player.write_log(os.path.join(run_dir, "timeline.json"))
    if status:
        return status

    results, summary = judge(scenario, os.path.join(run_dir, "metrics"), facts)
    write_criteria(os.path.join(run_dir, "criteria.json"), scenario, results, facts)
    for line in summary_lines(scenario.name, results):
        print(line)
    if summary is not None:
        print("  %.1f s sim from the first step, %d steps (%d failed), %d/%d arrivals, %d goals reached, "
              "final state %s" % (facts["end_s"], len(player.log), facts["failed_steps"], facts["arrivals"],
                                  facts["targets"], facts["goals_reached"], facts["final_state"] or "-"))
    shots = screenshots.taken if screenshots is not None else []
    bag = "run.bag, " if os.path.exists(os.path.join(run_dir, "run.bag")) else ""
    print("run dir: %s (%s%d screenshots)" % (run_dir, bag, len(shots)))
    return 0 if all(c["passed"] for c in results) else 1


def parse_args(argv):
    import argparse

    parser = argparse.ArgumentParser(prog="scenario", description="Run a fleet scenario and judge it (mbot_bringup).")
    parser.add_argument("scenario", nargs="?", help="a name (scenarios/NAME.yaml of mbot_bringup) or a path")
    parser.add_argument("--run-dir", help="where the run's files go (default ~/.ros/mbot_runs/NAME)")
    parser.add_argument("--no-rviz", action="store_true", help="no rviz, no screenshots")
    parser.add_argument("--no-record", action="store_true", help="no rosbag")
    parser.add_argument("--real-time", action="store_true", help="real_time_factor 1 without lockstep (to watch it)")
    parser.add_argument("--list", action="store_true", help="list the scenarios and exit")
    return parser.parse_args(argv)


def _sim_time_set(rosgraph):
    """True once the master is up and /use_sim_time is true."""
    try:
        return rosgraph.Master("/scenario_runner").getParam("/use_sim_time") is True
    except Exception:  # noqa: B902 (no master yet, or the parameter is not set yet)
        return False


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.list:
        for name in list_scenarios():
            try:
                s = load_scenario(scenario_path(name))
                first = " ".join(s.description.split()).split(". ")[0].rstrip(".")   # its first sentence
                print("%-16s %s" % (name, first if len(first) <= 100 else first[:97] + "..."))
            except ConfigError as error:
                print("%-18s (bad file) %s" % (name, error))
        return 0
    if not args.scenario:
        say("error: name a scenario (--list shows them)")
        return 2
    return run(args)


if __name__ == "__main__":
    sys.exit(main())
