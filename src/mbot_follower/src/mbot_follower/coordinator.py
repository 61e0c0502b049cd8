"""The fleet coordinator's state machine, without ROS (the node is coordinator_node.py).

States (``FleetStatus``)::

    IDLE --goal--> FORMING --shape reached--> NAVIGATING --leader at goal, shape stable--> ARRIVED
                      ^                            |
                      +------- new goal -----------+--- leader's navigation gives up --> ABORTED

    DEGRADED: a member is lost (no pose or, for a follower, no controller for ``loss_timeout``).
    The slots are re-planned for the robots left and the goal is kept: the fleet goes on forming
    or navigating, and the state reads DEGRADED until the lost robot comes back (it rejoins a
    slot) or the fleet arrives. A lost leader is replaced by the follower nearest its slot, which
    takes over the leader's navigation goal.

While NAVIGATING, the leader waits (its goal is cancelled and sent again) whenever a follower is
more than ``regroup_error`` off its slot, until all are within ``resume_error``: after a sharp
turn, or a formation switch on the move, the slots move faster than a follower can drive, and a
fleet that drives on while its shape is broken is not a formation (a column must stand before a
corridor). Followers that follow the leader's trail past a wall, or that their safety layer holds
(something in their way, e.g. a lost robot standing still), are excused: the leader's waiting
would not bring them closer. While the leader waits, an excuse counts once it has lasted
``excuse_time``: a follower turning away from a wall is held by its safety layer for a moment,
and that moment must not send the leader off without it. A regroup that starts within
``regroup_rejoin`` of the end of one that ended on an excuse (a follower still off its slot)
continues it: its ``regroup_timeout`` counts from the first (a follower whose excuse ends as soon
as the leader drives again would otherwise stop it every cycle, for ever). After a regroup that
ended with every follower back in its slot, a new one is a new one: at a sharp turn the leader
waits, turns a little, waits again, and each wait has its full time. A waiting leader is never paused (it
has no goal): a follower passing in front of it to its slot is not an obstacle to go around.

Except right after a formation switch on the move: the followers change places, and on the way they
block each other (the safety layer holds one, or another robot blocks its way to the slot and it
takes the trail): those are the robots the leader waits for. A follower's mode flickers between
slot, trail, safety_stop and give_way while robots pass each other, and an excused follower let
the leader drive on every time it flickered (the corridor column formed past the entrance). So
the first regroup after a switch waits for every follower, excused or not, until all are within
``resume_error`` or ``regroup_timeout`` passes; held followers give way meanwhile (GiveWay), so
they do not jam for good.

A switch is done by the one rule of the metrics (mbot_follower.metrics.settle.SwitchSettle):
every follower whose slot is not blocked within 0.3 m of its new slot for 0.5 s. The event
"switched" says when the shape was reached, and `switching` (on /fleet/status) goes off when the
rule has held, so the metrics record the coordinator's own done time. FORMING and ARRIVED wait
for more, a stable formation (``form_edge_tolerance``, ``form_heading_tolerance`` for
``stable_time``): a follower that drove backwards into its slot has turned round.

Where the map is free ahead of the leader (``switch_room_ahead`` metres, a spacing to either
side), the leader drives on through a switch and waits only for followers that lag behind their
new slots (along the slot's heading): a slot behind its follower (a diamond's rear robots
dropping back into a column) comes to it as the leader drives, and a follower beside its slot
drives across to it; a standing leader made the rear robots of a 5-robot diamond -> column
switch drive the whole way back alone. Before a narrow passage the leader stands until the new
shape is there (a column must stand before a corridor). After ``regroup_timeout`` the whole
distance to the slot counts again. When every follower is ahead of (or beside) its new slot as
such a switch starts, the leader drives at ``switch_leader_vel`` (the robots' top speed, above
the fleet's usual leader speed) until the new shape is reached: the slots come to the followers
sooner. A follower that falls ``resume_error`` behind its slot ends it (at the robots' top
speed it could not catch up), as do a regroup, a pause, a new leader or a new phase. The action
``("leader_speed", robot, v)`` asks for that speed, ``v`` None for the usual one again.

A slot in a wall (a column's last slots behind a leader that starts near a wall, slots behind a
corner) cannot be held. Its follower is left out of the shape checks (FORMING, a switch,
ARRIVED) and of regrouping while its slot is blocked, and the reason names it: the fleet does not
wait for a place no robot can reach. The follower counts again ``free_hold`` after its slot is
clear (as in the metrics): a slot just out of the wall is still too close to it to drive into
(the follower's safety layer stops it 0.8 m short of a wall), so the leader does not stop for it
until the slot has moved on. A lost robot that still stands there (its controller died) blocks
the slots within ``lost_clearance`` of it in the same way: after a loss the re-planned slot of a
follower may lie beside the dead robot, where the follower's safety layer stops it, gives way and
tries again, and a leader waiting for it would wait for ever (until ``regroup_timeout``); once the
leader drives on, the slot moves away from the dead robot. Such a slot counts again as soon as it
is ``lost_clearance`` from the dead robot: that distance already leaves the follower's safety
layer room, and a follower that finds the robot on its way steers round it. While such a slot is
blocked the leader
waits for nobody: the follower held there also stands in the way of others (a 5-robot diamond
that loses a front robot: its rear neighbour gets the dead robot's slot, and the other rear robot's
new slot, the middle one, is 0.53 m beside that held neighbour), and only the leader driving on
frees them all (benchmark seeds 2 and 8 waited 8 and 19 s before). The standing leader blocks a
slot in the same way where its path folds back (``fold_ratio``): a column whose leader went round
a person in a U-turn has its next slot beside the leader, and a follower driving there is stopped
by its safety layer, gives way and tries again for the whole ``regroup_timeout``.

A formation along the path (a column) has its slots on the leader's path (trail.path_slot): the
coordinator records the leader's path (trail.LeaderTrail, as the metrics do) from the poses of
every update(), started anew with each assignment, and measures the followers against those
slots and their headings, so a column bent around a corner is formed.

A goal that cannot be reached as given (a NaN, off the map, in a wall) or an unknown formation
is refused at once: the state does not change and the message says why.

The node calls ``update()`` every cycle with what it sees (poses, when each robot was last
heard, the leader's navigation state, an obstacle in front of the leader) and carries out the
actions it returns: ``("goal", robot, Pose2D)`` send the leader its navigation goal,
``("cancel", robot)`` cancel it, ``("assignment",)`` publish the new slot assignment,
``("leader_speed", robot, v)`` set the speed limit of that robot's navigation (above).
"""
import math

import numpy as np

from mbot_common.geometry import normalize_angle, relative, transform_point
from mbot_follower.assignment import assign_single_file, assign_slots
from mbot_follower.fleet_io import Assignment
from mbot_follower.formations import FormationError, FormationLibrary
from mbot_follower.metrics.settle import SwitchSettle
from mbot_follower.shape import shape_errors
from mbot_follower.trail import LeaderTrail, slot_pose

IDLE, FORMING, NAVIGATING, ARRIVED, DEGRADED, ABORTED = (
    "IDLE", "FORMING", "NAVIGATING", "ARRIVED", "DEGRADED", "ABORTED")
#: When the robots left cannot take the formation (a diamond of 3), the first of these that fits.
FALLBACK_FORMATIONS = ("triangle", "wedge", "column")
#: How blocked_followers() names a slot blocked by a lost robot standing there, or by the standing
#: leader where its path folds back (_regroup reads them: only the leader driving on frees either).
BESIDE_LOST = "beside the lost "
BESIDE_LEADER = "beside the leader "
BESIDE = (BESIDE_LOST, BESIDE_LEADER)


class CoordinatorConfig(object):
    """Thresholds and times of the coordinator (sim time)."""

    def __init__(self):
        # a stable formation (FORMING ends, ARRIVED; a switch is done by metrics.settle's rule):
        self.form_edge_tolerance = 0.3             # below this edge-length error [m]
        self.form_heading_tolerance = math.radians(5.0)  # ... and this follower heading error [rad]
        self.stable_time = 0.5                     # ... for this long [s]
        self.forming_timeout = 60.0                # then navigate anyway, saying who is off [s]
        self.arrive_timeout = 30.0                 # leader at goal: ARRIVED after this at the latest [s]
        self.loss_timeout = 1.0                    # unheard this long = lost [s]
        self.pause_time = 1.0                      # obstacle in front of the leader: all stop this long [s]
        self.pause_cooldown = 5.0                  # no new pause this soon after one ends [s]
        self.regroup_error = 0.35                  # a follower this far off its slot: the leader waits [m]
        self.resume_error = 0.15                   # ... until every follower is this close again [m]
        self.regroup_timeout = 15.0                # ... or this long has passed [s]
        self.regroup_rejoin = 1.0                  # a regroup this soon after one that ended on an excuse: the same [s]
        self.excuse_time = 1.0                     # ... or the rest have been excused this long [s]
        self.free_hold = 3.0                       # a slot that was in a wall counts this long after [s]
        self.switch_room_ahead = 3.0               # free map this far ahead: the leader drives through a switch [m]
        self.switch_leader_vel = 0.5               # ... at this speed while the slots come; 0: off [m/s]
        # a slot this close to a lost robot standing there is blocked: a follower's safety layer
        # stops it 0.8 m short of what it drives towards, + the robot's radius 0.15 m [m]
        self.lost_clearance = 1.0
        # a path slot nearer the leader than this share of its distance along the path (and than
        # lost_clearance): the path folds back there (a U-turn around a person) and the slot is
        # beside the leader, out of the follower's reach while the leader stands [-]
        self.fold_ratio = 0.5
        self.topology = "star"                     # who follows whom: star or chain


def check_target(target, free_space=None):
    """None when the leader can be sent to `target`, else why not (one line)."""
    values = (target.x, target.y, target.theta)
    if not all(math.isfinite(v) for v in values):
        return "target (%s, %s, %s) is not a finite pose" % values
    if free_space is not None:
        if free_space.cell(target.x, target.y) is None:
            return "target (%.2f, %.2f) is off the map" % (target.x, target.y)
        if not free_space.is_free(target.x, target.y):
            return "target (%.2f, %.2f) is in a wall or too close to one for a robot" % (target.x, target.y)
    return None


class FleetCoordinator(object):
    """The fleet's state, formation and slot assignment; see the module docstring."""

    def __init__(self, robots, leader, formation, spacing, config=None, library=None, free_space=None):
        self.config = config or CoordinatorConfig()
        self.library = library or FormationLibrary()
        self.free_space = free_space
        if leader not in robots:
            raise ValueError("leader %r is not one of the robots (%s)" % (leader, ", ".join(robots)))
        self.robots = list(robots)
        self.leader = leader
        self.members = list(robots)          # in the formation now
        self.lost = []                       # lost and not back
        self.formation = formation
        self.requested_formation = formation  # what was asked for; a loss may force a fallback
        self.spacing = float(spacing)
        self.library.make(formation, len(self.members), self.spacing, topology=self.config.topology)  # validates
        self.phase = IDLE                    # what the fleet is doing; state() adds DEGRADED
        self.reason = "waiting for a target"
        self.target = None
        self.paused = False
        self.assignment = None
        self.errors = None                   # ShapeErrors of the last update
        self.blocked = []                    # followers whose slots are (or just were) blocked
        self._blocked_until = {}             # follower -> until when its slot counts as blocked
        self._blocked_by = {}                # follower -> what blocked it last ("in a wall", ...)
        self.events = []                     # (time, kind, text): switches, losses, rejoins, pauses
        self._stable_since = None
        self._phase_since = 0.0
        self._leader_done_at = None
        self._pause_until = None
        self._no_pause_before = -1e9
        self._switch_started = None
        self._switch_settle = SwitchSettle()  # when the switch under way is done
        self._switch_waits = False           # after a switch: the leader waits for every follower
        self._switch_drives = False          # ... but only for those behind their slots (room ahead)
        self._switch_fast = False            # ... at switch_leader_vel (every follower ahead of its slot)
        self._fast_leader = None             # the robot whose navigation drives at switch_leader_vel
        self._lost_at = {}
        self._last_leader_pose = None        # where the leader was last seen (for a replacement)
        self._regroup_since = None           # the leader waits for the followers since then
        self._regroup_ended = (-1e9, None)   # (when the last regroup ended, when it had begun)
        self._excused_since = {}             # follower -> since when it is excused (regrouping)
        self._no_regroup_before = -1e9
        self._trail = LeaderTrail()          # the leader's path since the assignment (path slots)

    # --- what the outside sees ----------------------------------------------------------------

    @property
    def switching(self):
        """A formation switch is under way: from its request until the new shape stands (metrics.settle)."""
        return self._switch_started is not None

    def state(self):
        if self.lost and self.phase not in (ARRIVED, ABORTED):
            return DEGRADED
        return self.phase

    # --- commands -----------------------------------------------------------------------------

    def set_goal(self, target, now, poses, formation="", spacing=0.0):
        """Start driving the formation to `target` (Pose2D, map). Returns (accepted, message,
        actions). A refused goal changes nothing."""
        problem = check_target(target, self.free_space)
        if problem is None and (formation or spacing):
            problem = self._formation_problem(formation or self.formation, spacing or self.spacing)
        if problem is not None:
            self.reason = "goal refused: " + problem
            return False, problem, []
        actions = []
        if self.phase == NAVIGATING:
            actions.append(("cancel", self.leader))
        self.formation = formation or self.formation
        self.requested_formation = self.formation
        self.spacing = spacing or self.spacing
        self.target = target
        self.paused = False
        self._pause_until = None
        self._set_phase(FORMING, now, "forming %s for the target (%.2f, %.2f)" % (self.formation, target.x, target.y))
        actions += self._reassign(poses, now)
        return True, "accepted", actions

    def cancel_goal(self, now, reason):
        """Give up the current goal: the leader stops and the fleet waits (IDLE)."""
        actions = [("cancel", self.leader)] if self.phase == NAVIGATING else []
        self.target = None
        self.paused = False
        self._set_phase(IDLE, now, reason)
        return actions

    def set_formation(self, name, now, poses, spacing=0.0):
        """Switch the formation now, moving or not. Returns (accepted, message, actions)."""
        spacing = spacing or self.spacing
        problem = self._formation_problem(name, spacing)
        if problem is not None:
            self.reason = "formation switch refused: " + problem
            return False, problem, []
        self.formation, self.spacing = name, spacing
        self.requested_formation = name
        self._switch_started = now
        self._switch_waits = self.phase == NAVIGATING  # (FORMING waits for every follower anyway)
        self._switch_drives = self._switch_waits and self.leader in poses and self._room_ahead(poses[self.leader])
        self.events.append((now, "switch", "%s, spacing %.2f m" % (name, spacing)))
        # While navigating, the state stays NAVIGATING: when the robots changing places fall far
        # behind their new slots, the leader waits for them (regrouping, see update()).
        self.reason = "switching to %s" % name
        actions = self._reassign(poses, now)
        lags = self._regroup_errors(now, poses).values() if self._switch_drives else ()
        self._switch_fast = bool(self._switch_drives and self.config.switch_leader_vel > 0
                                 and max(lags, default=0.0) <= self.config.resume_error)
        return True, "switching to %s (%d robots, spacing %.2f m)" % (name, len(self.members), spacing), \
            actions + self._leader_speed(now, poses)

    def _formation_problem(self, name, spacing):
        try:
            self.library.make(name, len(self.members), spacing, topology=self.config.topology)
        except (FormationError, ValueError) as error:
            return str(error)
        return None

    # --- the cycle ----------------------------------------------------------------------------

    def update(self, now, poses, last_heard, leader_nav=None, obstacle_ahead=False, excused=()):
        """One coordinator cycle.

        :param now: sim time [s]
        :param poses: {robot: Pose2D in the map} of the robots with a current pose
        :param last_heard: {robot: sim time [s] it was last complete (pose, and controller for a follower)}
        :param leader_nav: the leader's navigation: None (no goal), "ACTIVE", "SUCCEEDED" or
            "ABORTED: <why>"
        :param obstacle_ahead: something is close in front of the leader (True, or the reason as a
            str: the leader's view is stale)
        :param excused: followers off their slot for a reason the leader's waiting would not cure
            (following the leader's trail past a wall, held by their safety layer); not after a
            switch (module docstring)
        :returns: list of actions (module docstring)
        """
        actions = self._losses_and_rejoins(now, poses, last_heard)
        if self.assignment is None and all(r in poses for r in self.members):
            actions += self._reassign(poses, now)
        if self.assignment is not None and self.assignment.leader in poses:
            leader = poses[self.assignment.leader]
            self._trail.follow(leader.x, leader.y, leader.theta)
        blocked_now = self.blocked_followers(poses)
        for r, why in blocked_now.items():
            # a wall's slot counts again free_hold after it is clear; one beside a robot at once (module docstring)
            beside = why.startswith(BESIDE)
            self._blocked_until[r] = now if beside else now + self.config.free_hold
            self._blocked_by[r] = why
        self.blocked = sorted(r for r, until in self._blocked_until.items() if r in blocked_now or now < until)
        self.errors = self._shape_errors(poses)
        stable = self._stable(now)
        if self._switch_started is not None and self._switch_done(now, poses):
            self.events.append((now, "switched", "%s reached in %.1f s" % (
                self.formation, self._switch_settle.reached_at - self._switch_started)))
            self._switch_started = None
            self._switch_waits = self._switch_drives = False

        if self.phase == FORMING:
            timed_out = now - self._phase_since > self.config.forming_timeout
            if stable or timed_out:
                why = "formation reached" if stable else "formation not reached in %.0f s (%s); navigating anyway" % (
                    self.config.forming_timeout, self._worst_follower(poses))
                if self.blocked:
                    why += " (%s: joining on the way)" % self._blocked_text()
                self._set_phase(NAVIGATING, now, why)
                self._leader_done_at = None
                actions.append(("goal", self.leader, self.target))
        elif self.phase == NAVIGATING:
            actions += self._navigating(now, poses, leader_nav, obstacle_ahead, stable, excused)
        return actions + self._leader_speed(now, poses)

    def _leader_speed(self, now, poses):
        """The leader_speed actions that start or end driving at switch_leader_vel (module docstring)."""
        if self._switch_fast and self._switch_drives and \
                max(self._regroup_errors(now, poses).values(), default=0.0) > self.config.resume_error:
            # a follower fell behind its slot: at the robots' top speed it could not catch up
            self._switch_fast = False
        fast = self._switch_fast and self._switch_drives and self.phase == NAVIGATING and not self.paused \
            and self._regroup_since is None  # (a regroup of before the switch ends at the next update)
        want = self.leader if fast else None
        if want == self._fast_leader:
            return []
        actions = [("leader_speed", self._fast_leader, None)] if self._fast_leader is not None else []
        if want is not None:
            actions.append(("leader_speed", want, self.config.switch_leader_vel))
        self._fast_leader = want
        return actions

    def _navigating(self, now, poses, leader_nav, obstacle_ahead, stable, excused):
        actions = []
        if self.paused:
            if now >= self._pause_until:
                self.paused = False
                self._no_pause_before = now + self.config.pause_cooldown
                self.reason = "resuming: the leader's navigation goes around the obstacle"
                self.events.append((now, "resume", self.reason))
                actions.append(("goal", self.leader, self.target))
            return actions
        # A leader that waits for its followers (regrouping) has no goal: a follower passing in
        # front of it on the way to its slot is no reason to pause, and the pause's end would
        # send the leader off into the followers still taking their slots.
        if obstacle_ahead and now >= self._no_pause_before and self._leader_done_at is None \
                and self._regroup_since is None:
            self.paused = True
            self._switch_fast = False
            self._pause_until = now + self.config.pause_time
            self.reason = "paused: %s" % (obstacle_ahead if isinstance(obstacle_ahead, str) else
                                          "obstacle in front of the leader %s" % self.leader)
            self.events.append((now, "pause", self.reason))
            return [("cancel", self.leader)]
        if leader_nav is not None and leader_nav.startswith("ABORTED"):
            why = leader_nav[len("ABORTED"):].lstrip(": ")
            self._set_phase(ABORTED, now, "the leader's navigation gave up: %s" % why)
            return actions
        if self._leader_done_at is None and leader_nav != "SUCCEEDED":
            regroup = self._regroup(now, poses, excused)
            if regroup is not None:
                return actions + regroup
        if leader_nav == "SUCCEEDED" and self._leader_done_at is None:
            self._leader_done_at = now
        if self._leader_done_at is not None:
            if stable:
                why = "the leader is at the target and the formation is stable"
                if self.blocked:
                    why += " (%s)" % self._blocked_text()
                self._set_phase(ARRIVED, now, why)
            elif now - self._leader_done_at > self.config.arrive_timeout:
                self._set_phase(ARRIVED, now, "the leader is at the target; formation not stable after %.0f s (%s)" % (
                    self.config.arrive_timeout, self._worst_follower(poses)))
        return actions

    def _regroup(self, now, poses, excused):
        """The leader waits while a follower is far off its slot (after a sharp turn, or when a
        follower was held up) and drives on once all are close again. None: nothing to do;
        else the actions (possibly none) of waiting."""
        if self._switch_waits:
            excused = ()
        self._excused_since = {r: self._excused_since.get(r, now) for r in excused}
        if self._regroup_since is not None:
            # while the leader waits, a follower's excuse must last: one cycle held by its safety
            # layer (turning away from a wall) would let the leader drive off from it
            excused = [r for r in excused if now - self._excused_since[r] >= self.config.excuse_time]
        excused = set(excused) | set(self.blocked)
        errors = {r: e for r, e in self._regroup_errors(now, poses).items() if r not in excused}
        worst = max(errors.items(), key=lambda kv: kv[1]) if errors else None
        beside = [r for r in self.blocked if self._blocked_by[r].startswith(BESIDE)]
        if beside:
            # only driving on frees a slot beside a dead robot, and whoever waits behind its follower
            worst = None
        if self._regroup_since is None:
            if worst is None or worst[1] <= self.config.regroup_error or now < self._no_regroup_before:
                return None
            ended, began = self._regroup_ended
            self._regroup_since = began if now - ended <= self.config.regroup_rejoin else now
            self._switch_fast = False  # a follower lags: not faster again in this switch
            self.reason = "regrouping: the leader waits for %s (%.2f m off its slot)" % worst
            self.events.append((now, "regroup", self.reason))
            return [("cancel", self.leader)]
        timed_out = now - self._regroup_since > self.config.regroup_timeout
        if worst is not None and worst[1] >= self.config.resume_error and not timed_out:
            return []
        # ended on an excuse: an excused or blocked follower is still off its slot
        all_errors = self._regroup_errors(now, poses)
        on_excuse = any(all_errors.get(r, 0.0) >= self.config.resume_error for r in excused)
        self._regroup_ended = (now, self._regroup_since) if on_excuse else (-1e9, None)
        self._regroup_since = None
        self._switch_waits = False  # once: a follower that cannot reach its slot is excused again
        if timed_out:
            self._no_regroup_before = now + self.config.regroup_timeout
        if beside:
            held = beside[0]
            self.reason = "driving on: only that frees %s's slot, %s" % (held, self._blocked_by[held])
        elif timed_out and worst is not None:  # (None: every follower excused at the last moment)
            self.reason = "driving on after %.0f s of regrouping (%s %.2f m off its slot)" % (
                self.config.regroup_timeout, worst[0], worst[1])
        else:
            self.reason = "regrouped: driving on"
        self.events.append((now, "resume", self.reason))
        return [("goal", self.leader, self.target)]

    def _regroup_errors(self, now, poses):
        """{follower: how far off its slot it is for regrouping [m]}: the distance, or while the
        leader drives through a switch (module docstring) how far it lags behind its slot."""
        if not (self._switch_drives and self._switch_started is not None
                and now - self._switch_started < self.config.regroup_timeout):
            return {r: e for r, (e, _) in self.slot_errors(poses).items()}
        # the follower's x in its slot's frame: negative when it is behind the slot
        return {r: max(0.0, -relative(slot, poses[r]).x)
                for r, slot in self.slot_poses(poses).items() if r != self.assignment.leader and r in poses}

    def _room_ahead(self, leader):
        """The map is free for switch_room_ahead metres ahead of the leader, a spacing to either
        side (no map: free): room to change places on the move."""
        if self.free_space is None:
            return True
        for side in np.linspace(-self.spacing, self.spacing, 5):
            start = transform_point(leader, 0.0, side)
            end = transform_point(leader, self.config.switch_room_ahead, side)
            if not self.free_space.segment_free(start[0], start[1], end[0], end[1]):
                return False
        return True

    # --- losses -------------------------------------------------------------------------------

    def _losses_and_rejoins(self, now, poses, last_heard):
        actions = []
        newly_lost = [r for r in self.members
                      if now - last_heard.get(r, -1e9) > self.config.loss_timeout and self.assignment is not None]
        back = [r for r in self.lost if now - last_heard.get(r, -1e9) <= self.config.loss_timeout and r in poses]
        if not newly_lost and not back:
            return actions
        old_leader = self.leader
        for r in newly_lost:
            self.members.remove(r)
            self.lost.append(r)
            self._lost_at[r] = now
            self.events.append((now, "lost", r))
        for r in back:
            self.lost.remove(r)
            self.members.append(r)
            self.events.append((now, "rejoined", "%s after %.1f s" % (r, now - self._lost_at.pop(r, now))))
        if not self.members:
            self._set_phase(ABORTED, now, "every robot of the fleet is lost")
            self.assignment = None
            return actions
        if old_leader in newly_lost:
            self.leader = self._nearest_to_leader_slot(poses)
            if self.phase == NAVIGATING and not self.paused:
                actions.append(("goal", self.leader, self.target))
        words = []
        if newly_lost:
            words.append("lost %s" % ", ".join(newly_lost))
        if back:
            words.append("%s rejoined" % ", ".join(back))
        if self.leader != old_leader:
            words.append("%s leads now" % self.leader)
        if len(self.members) > 1:
            # the formation asked for if it fits the robots there are now, else a fallback
            for name in (self.requested_formation,) + FALLBACK_FORMATIONS:
                if self._formation_problem(name, self.spacing) is None:
                    if name != self.requested_formation:
                        words.append("%s does not fit %d robots: %s"
                                     % (self.requested_formation, len(self.members), name))
                    self.formation = name
                    break
        self.reason = "; ".join(words)
        actions += self._reassign(poses, now)
        return actions

    def _nearest_to_leader_slot(self, poses):
        """The member nearest to where the leader was (its slot), among those with a pose."""
        ref = self._last_leader_pose
        candidates = [r for r in self.members if r in poses]
        if not candidates:
            return self.members[0]
        if ref is None:
            return candidates[0]
        return min(candidates, key=lambda r: math.hypot(poses[r].x - ref.x, poses[r].y - ref.y))

    # --- slots and shape ----------------------------------------------------------------------

    def _reassign(self, poses, now):
        """Give every member a slot: the leader keeps slot 0, the others by least total travel.
        Needs every member's pose; without them the assignment waits for the next cycle."""
        self._switch_fast = False  # the slots change: set_formation decides again, a loss ends it
        if not all(r in poses for r in self.members):
            self.assignment = None
            return []
        leader_pose = poses[self.leader]
        self._blocked_until, self._blocked_by = {}, {}
        # the leader's path starts here: path slots are the rigid slots at first
        self._trail.restart(now, (leader_pose.x, leader_pose.y, leader_pose.theta))
        self._switch_settle.reset()   # new slots: a switch under way is measured against them
        if len(self.members) == 1:  # the leader alone: no shape to keep
            self.assignment = Assignment(self.leader, self.formation, self.spacing, {self.leader: (0.0, 0.0)},
                                         {self.leader: ""})
            self._stable_since = None
            return [("assignment",)]
        formation = self.library.make(self.formation, len(self.members), self.spacing, topology=self.config.topology)
        order = [self.leader] + [r for r in self.members if r != self.leader]
        slot_world = np.array([transform_point(leader_pose, *o) for o in formation.offsets])
        positions = np.array([[poses[r].x, poses[r].y] for r in order])
        single_file = formation.along_path and all(abs(o[1]) < 1e-9 for o in formation.offsets)
        slot_of = assign_single_file(positions, slot_world, leader_pose.theta) if single_file \
            else assign_slots(positions, slot_world, leader_index=0)
        robot_in_slot = {slot_of[i]: r for i, r in enumerate(order)}
        slots = {r: (float(formation.offsets[slot_of[i]][0]), float(formation.offsets[slot_of[i]][1]))
                 for i, r in enumerate(order)}
        follows = {}
        for i, r in enumerate(order):
            parent = formation.parents[slot_of[i]]
            follows[r] = robot_in_slot[parent] if parent >= 0 else ""
        self.assignment = Assignment(self.leader, self.formation, self.spacing, slots, follows,
                                     formation.along_path)
        self._stable_since = None
        return [("assignment",)]

    def _shape_errors(self, poses):
        a = self.assignment
        if a is None or a.leader not in poses:
            return None
        self._last_leader_pose = poses[a.leader]
        robots = [a.leader] + [r for r in a.slots if r != a.leader and r in poses and r not in self.blocked]
        if len(robots) < 2:
            return None
        slots = self.slot_poses(poses)
        actual = np.array([[poses[r].x, poses[r].y] for r in robots])
        desired = np.array([[slots[r].x, slots[r].y] for r in robots])
        headings = [poses[r].theta for r in robots]
        return shape_errors(actual, desired, headings=headings, desired_headings=[slots[r].theta for r in robots])

    def _stable(self, now):
        """The shape is within the FORMING tolerances and has been for stable_time."""
        e = self.errors
        ok = e is not None and e.edge_max < self.config.form_edge_tolerance and \
            e.heading_max < self.config.form_heading_tolerance
        if self.assignment is not None and all(r == self.assignment.leader or r in self.blocked
                                               for r in self.members):
            ok = True  # nobody but the leader can be checked (alone, or every other slot blocked)
        if not ok:
            self._stable_since = None
            return False
        if self._stable_since is None:
            self._stable_since = now
        return now - self._stable_since >= self.config.stable_time

    def _switch_done(self, now, poses):
        """The switch under way is done (metrics.settle's rule on the slot errors now)."""
        if self.assignment is None or self.assignment.leader not in poses:
            self._switch_settle.since = None   # nothing to measure is not within
            return False
        errors = {r: e for r, (e, _) in self.slot_errors(poses).items() if r in self.members}
        return self._switch_settle.update(now, errors, self.blocked)

    def slot_poses(self, poses):
        """{robot: Pose2D in the map} of every slot of the assignment, the leader's included: where
        each robot belongs and which way it should face ({} without an assignment or leader pose)."""
        a = self.assignment
        if a is None or a.leader not in poses:
            return {}
        trail = self._trail if a.along_path else None
        return {r: slot_pose(poses[a.leader], offset, trail) for r, offset in a.slots.items()}

    def slot_errors(self, poses):
        """{follower: (distance to its slot [m], heading error to its slot's heading [rad])}."""
        a = self.assignment
        result = {}
        for r, slot in sorted(self.slot_poses(poses).items()):
            if r == a.leader or r not in poses:
                continue
            result[r] = (math.hypot(poses[r].x - slot.x, poses[r].y - slot.y),
                         normalize_angle(poses[r].theta - slot.theta))
        return result

    def blocked_followers(self, poses):
        """{follower: why} for the followers whose slots (placed at the leader's pose now) cannot be
        driven into: "in a wall" of the map, or "beside the lost <robot>" that still stands there
        (it has a pose: its controller died, not the robot), or "beside the leader <robot>" where
        the leader's path folds back (a path slot much nearer the leader than along the path)."""
        a = self.assignment
        standing = [(r, poses[r]) for r in self.lost if r in poses]
        result = {}
        for r, slot in sorted(self.slot_poses(poses).items()):
            if r == a.leader:
                continue
            if self.free_space is not None and not self.free_space.is_free(slot.x, slot.y):
                result[r] = "in a wall"
                continue
            near = [lost for lost, p in standing
                    if math.hypot(p.x - slot.x, p.y - slot.y) < self.config.lost_clearance]
            if near:
                result[r] = BESIDE_LOST + near[0]
            elif a.along_path and self._folded(poses[a.leader], slot, a.slots[r]):
                result[r] = BESIDE_LEADER + a.leader
        return result

    def _folded(self, leader, slot, offset):
        """The path slot (`offset` from the leader's (0, 0)) lies beside the leader though far
        behind it along the path (config.fold_ratio)."""
        near = math.hypot(slot.x - leader.x, slot.y - leader.y)
        return near < min(self.config.fold_ratio * math.hypot(*offset), self.config.lost_clearance)

    def _blocked_text(self):
        return " and ".join("%s's slot is %s" % (r, self._blocked_by[r]) for r in self.blocked)

    def _worst_follower(self, poses):
        errors = self.slot_errors(poses)
        if not errors:
            return "no follower pose"
        r = max(errors, key=lambda k: errors[k][0])
        return "%s is %.2f m from its slot" % (r, errors[r][0])

    def _set_phase(self, phase, now, reason):
        if phase != self.phase:
            self.events.append((now, "state", "%s -> %s" % (self.phase, phase)))
        self.phase = phase
        self._phase_since = now
        self._regroup_since = None
        self._switch_waits = self._switch_drives = False
        self.reason = reason
