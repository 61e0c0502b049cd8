"""Formation metrics: what the fleet did, measured in sim time, from plain samples.

`MetricsCollector` is fed with the contents of messages (ground-truth poses, the slot
assignment, the coordinator's status, the follower controllers' states, power, contacts, the
leader's plan) and keeps a `Run`:
  * one `Sample` at every multiple of 1/rate sim seconds, with the newest ground-truth pose of
    every robot at or before that time (taken when the first later pose arrives),
  * the `Event`s: state changes, assignments, switches (the formation changed; switch_done when
    the coordinator's switch was done, by the rule below), pauses (start, end), losses, rejoins,
    contacts,
  * one `ControllerSample` per follower controller cycle.
`summarize(run)` turns a Run into the numbers of metrics.json. `RunWriter` writes a Run to
metrics.csv, events.csv, controller.csv and metrics.json; `load_run(output_dir)` reads them back
into the same Run, so a report computes the same summary offline. Nothing here knows ROS.

What the numbers mean (all times sim time unless marked wall):
  slot error        distance of a follower's ground-truth position from its slot, the slot being
                    leader pose (+) offset of the current assignment; for a formation along the
                    path (a column) the slot on the leader's ground-truth path since the
                    assignment (trail.path_slot), and the heading errors are to each slot's
                    heading. A lost robot (in the status' `lost`) is excluded while lost; so is
                    a robot without a fresh pose.
  fit error         the same after the best rigid fit (rotation + translation) of the desired
                    shape onto the actual positions (shape.rigid_fit): the shape alone.
  slot free         whether a follower's slot keeps slot_clearance to the walls of the map and
                    to the simulator's static obstacles, spawned ones from their spawn on (1/0;
                    NaN without a map or obstacles): a slot in a wall or a box (a column's slots
                    behind a corner, a wide formation in a doorway, a box in the way) cannot be
                    held, the follower drives the free path instead (the leader's trail). The
                    obstacles are `obstacle` and `obstacle_removed` events (shape, size, centre).
  steady slot RMS   the slot RMS restricted to NAVIGATING while the leader moves, and to ARRIVED;
                    while navigating, a follower's sample counts once its slot has been free
                    for free_hold (the time to get back from the trail). slot_blocked_share
                    says how much of the navigating time the slots were in walls or obstacles.
                    A follower whose controller has gone silent for controller_silence (killed,
                    before the coordinator declares it lost) does not count: that error is the loss
                    detection time, measured by the recovery figures.
  leader lateral    distance of the leader from the polyline of its global plan (the newest one not
                    later than the leader's pose; a new goal, FORMING, forgets the old plans); the
                    summary counts it while the leader follows the plan (NAVIGATING, DEGRADED).
  latency           end to end: the age of the pose a command was computed from (FollowerState
                    pose_stamp) at the moment the simulator applied that command (the start of
                    the first physics step that used it, from its report /stage/applied_commands).
                    A cycle takes the first command of its robot applied at or after its stamp
                    whose twist equals FollowerState.cmd exactly (a cycle replaced by an
                    identical twist before a step shares that one's time); one not applied
                    within command_wait (dropped, replaced before a step) has no latency and
                    counts in commands_not_applied. Without the report (a real robot) it is the
                    pose's age when the command was computed (header.stamp - pose_stamp); the
                    `latency_method` event and the summary say which. Only cycles that used a
                    pose (active) count.
  tf success rate   1 - lookup_failures / lookups, from the newest FollowerState of each robot.
  cycle time        the controller's computation time per cycle [ms wall], p99.
  clearance         robot-robot centre distance - 2 x robot_radius, over the samples.
  distance          path length of each robot's ground truth (jumps faster than teleport_speed
                    and gaps longer than stale_after are not travel).
  energy            integral of each robot's power over sim time: every power value holds until
                    the next one, for at most stale_after. [J] if power is in [W]. The power is
                    the power model (control_laws.energy_rate, energy_k_v, energy_k_w) of the
                    velocity each ground-truth pose carries: what the robot really does, whoever
                    commands it (its follower controller, its move_base, nothing).
  sampling          a sample at t uses every robot's newest pose not later than t (and not older
                    than stale_after). Each robot's poses come on their own topic, and a busy
                    machine delivers one stream later than another (at real_time_factor 0 a
                    tenth of a wall second is seconds of sim time), so the sample at t waits
                    until every robot's stream has passed t; a stream more than hold_back
                    behind the newest pose (a removed robot) is not waited for.
  switch done       the one rule (settle.py, SWITCH_TOLERANCE, SWITCH_HOLD): every follower whose
                    slot is not blocked within 0.3 m of its new slot, held 0.5 s; the switch time
                    runs from the switch until that hold began. The coordinator applies it online
                    (SwitchSettle; its switch_done event), switch_done_times(run) to a recorded
                    run's samples (and gives the coordinator's time beside it); the scenario
                    judge, the runner's `formed` event, the report, the benchmark and the
                    rostests use them. Not the same as a stable formation (the coordinator's
                    FORMING and ARRIVED also wait for headings) nor the report's settling (slot
                    RMS under recovered_rms for recovered_hold, another figure).
  leader's path     the path slots of a formation along the path lie on (trail.LeaderTrail): from
                    the leader's pose at the assignment's time on, points 0.05 m apart, 50 m long;
                    the coordinator, this collector, the fleet probe and the report build it alike.
  time in state     sim time between the coordinator's state changes, the last one up to the end.
  recovery          per loss (the status shows a new `lost` member at t0): time from t0 to the
                    state DEGRADED (0 if it already was), and the time from t0 until the slot RMS
                    falls under recovered_rms and then stays under it for recovered_hold.

Offline: `/usr/bin/python3 -m mbot_follower.metrics OUTPUT_DIR` prints the summary of a run.

The code is split by role: `records` (the record types, MetricsConfig, Run), `collector` (the
live recorder), `summary` (the statistics), `files` (CSV/JSON in and out), `settle` (when a
switch is done); all of it is importable from mbot_follower.metrics.
"""
import argparse
import json
import sys

from mbot_follower.metrics.collector import MetricsCollector, distance_to_polyline  # noqa: F401
from mbot_follower.metrics.files import (CONTROLLER_COLUMNS, EVENT_COLUMNS, FILES, OLD_ROBOT_COLUMNS,  # noqa: F401
                                         ROBOT_COLUMNS, SAMPLE_COLUMNS, RunFileError, RunWriter, load_run,
                                         sample_columns)
from mbot_follower.metrics.records import (NAN, PLAN_STATES, ControllerSample, Event, MetricsConfig,  # noqa: F401
                                           RobotSample, Run, Sample)
from mbot_follower.metrics.settle import SWITCH_HOLD, SWITCH_TOLERANCE, SwitchSettle, switch_done_times  # noqa: F401
from mbot_follower.metrics.summary import (_holds_under, finite_rms, leader_speed, recoveries,  # noqa: F401
                                           run_span, state_at, summarize, time_in_states)


def main(argv=None):
    """Print the summary of a run folder (as the collector computed it) as JSON."""
    parser = argparse.ArgumentParser(description="Summary of a formation metrics run folder.")
    parser.add_argument("output_dir", help="folder with metrics.csv, events.csv, controller.csv")
    args = parser.parse_args(argv)
    try:
        summary = summarize(load_run(args.output_dir))
    except RunFileError as error:
        print(error, file=sys.stderr)
        return 1
    json.dump(summary, sys.stdout, indent=1)
    print()
    return 0
