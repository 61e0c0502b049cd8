"""Merging into a column in slot order (merge.py)."""
import math

import numpy as np
import pytest

from mbot_common.geometry import Pose2D, Twist2D, relative
from mbot_follower.control_laws import CommandFilter, ControlInput, ControllerConfig, SlotTracking, integrate, \
    safety_filter
from mbot_follower.merge import merge_target, robot_ahead

COLUMN = {"L": (0.0, 0.0), "a": (-1.5, 0.0), "b": (-3.0, 0.0), "c": (-4.5, 0.0)}


def test_robot_ahead_is_the_next_slot_towards_the_leader():
    assert robot_ahead(COLUMN, "a") == "L"
    assert robot_ahead(COLUMN, "b") == "a"
    assert robot_ahead(COLUMN, "c") == "b"
    assert robot_ahead(COLUMN, "L") is None


def test_a_follower_beside_the_path_waits_in_its_lane_while_the_robot_ahead_is_level_with_it():
    # a diamond's two rear corners: the one with the slot further back stays 0.7 m to its side
    target, waiting = merge_target((2.0, 0.53), (2.0, -0.53), lane=0.7, gap=0.6)
    assert waiting
    assert target == pytest.approx((0.0, 0.7))
    # the robot ahead 0.1 m behind it: still in the lane
    target, waiting = merge_target((2.0, -0.53), (1.9, 0.53), lane=0.7, gap=0.6)
    assert waiting and target == pytest.approx((0.0, -0.7))


def test_a_follower_further_out_keeps_its_distance_from_the_path_while_it_waits():
    target, waiting = merge_target((1.0, -1.06), (0.8, 1.06), lane=0.7, gap=0.6)
    assert waiting
    assert target == pytest.approx((0.0, -1.06))


@pytest.mark.parametrize("behind", [0.05, 0.2, 0.4, 0.55])
def test_behind_the_robot_ahead_a_follower_slides_in_keeping_the_gap_from_it(behind):
    target, waiting = merge_target((1.0, 1.06), (1.0 + behind, 0.0), lane=0.7, gap=0.6)
    assert waiting
    # on the path's side it was on, `gap` from the robot ahead, never further out than the lane
    assert target[0] == 0.0 and 0.0 < target[1] <= 0.7
    assert math.hypot(behind, target[1]) == pytest.approx(0.6) or target[1] == pytest.approx(0.7)
    closer = merge_target((1.0, 1.06), (1.0 + behind + 0.02, 0.0), lane=0.7, gap=0.6)[0]
    assert closer[1] < target[1] or target[1] == pytest.approx(0.7) and closer[1] <= 0.7


def test_a_follower_joins_the_path_once_the_robot_ahead_is_far_enough_ahead():
    assert merge_target((1.0, 1.06), (1.6, -0.2), lane=0.7, gap=0.6) == ((0.0, 0.0), False)
    # just short of the gap it still waits
    assert merge_target((1.0, 1.06), (1.55, -0.2), lane=0.7, gap=0.6)[1]


def test_a_follower_near_the_path_is_never_pulled_out_of_it():
    assert merge_target((0.5, 0.3), (0.5, 0.0), lane=0.7, gap=0.6) == ((0.0, 0.0), False)
    assert merge_target((0.5, -0.34), (0.0, 0.0), lane=0.7, gap=0.6) == ((0.0, 0.0), False)


def test_without_a_pose_of_the_robot_ahead_the_follower_drives_to_its_slot():
    assert merge_target((2.0, 1.0), None, lane=0.7, gap=0.6) == ((0.0, 0.0), False)


# ------------------------------------------------------------------ closed loop

RADIUS = 0.15   # the mbot's body


def disc_scan(me, others, beams=360, reach=8.0):
    """A full-circle laser scan (ranges, angle_min, angle_increment) of `me` (Pose2D) that sees
    the robots at `others` (Pose2Ds) as discs of RADIUS."""
    angles = -math.pi + np.arange(beams) * (2 * math.pi / beams)
    ranges = np.full(beams, math.inf)
    for o in others:
        p = relative(me, o)
        d = np.cos(angles) * p.x + np.sin(angles) * p.y          # along each beam
        miss = (p.x ** 2 + p.y ** 2) - d ** 2                      # squared distance off it
        hit = (d > 0) & (miss < RADIUS ** 2)
        r = d - np.sqrt(np.maximum(RADIUS ** 2 - miss, 0.0))
        ranges = np.where(hit & (r < ranges), r, ranges)
    return [min(r, math.inf) if r <= reach else math.inf for r in ranges], -math.pi, 2 * math.pi / beams


def switch_to_column(diamond_slots, column_slots, dt=0.05, duration=12.0):
    """A leader driving straight on at 0.35 m/s, its followers in `diamond_slots`, switches to
    `column_slots` (both {robot: (x, y)} in the leader frame). As the coordinator does, the
    leader speeds up to the robots' top speed (0.5 m/s) until a follower lags 0.15 m behind its
    slot; each follower merges as the follower node does, stopped by the safety layer on a scan
    of the other robots. Returns (seconds until every follower is within 0.3 m of its
    slot or None, the smallest distance between two robots' centres [m])."""
    config = ControllerConfig()
    law = SlotTracking()
    leader = Pose2D(0.0, 0.0, 0.0)
    robots = sorted(column_slots)
    poses = {r: Pose2D(x, y, 0.0) for r, (x, y) in diamond_slots.items()}
    filters = {r: CommandFilter(config) for r in robots}
    for f in filters.values():
        f.previous = Twist2D(0.35, 0.0, 0.0)
    slots = dict(column_slots, leader=(0.0, 0.0))
    closest, speed, fast = math.inf, 0.35, True
    for step in range(int(duration / dt)):
        fast = fast and all(leader.x + column_slots[r][0] - poses[r].x <= 0.15 for r in robots)
        speed = min(speed + dt, 0.5) if fast else max(speed - dt, 0.35)   # 1 m/s^2
        twist = Twist2D(speed, 0.0, 0.0)
        everyone = dict(poses, leader=leader)
        closest = min([closest] + [math.hypot(a.x - b.x, a.y - b.y) for i, a in enumerate(everyone.values())
                                   for b in list(everyone.values())[i + 1:]])
        errors = [math.hypot(poses[r].x - leader.x - column_slots[r][0], poses[r].y - leader.y - column_slots[r][1])
                  for r in robots]
        if max(errors) < 0.3:
            return step * dt, closest
        commands = {}
        for r in robots:
            slot = Pose2D(leader.x + column_slots[r][0], leader.y + column_slots[r][1], 0.0)
            me = relative(slot, poses[r])
            ahead = relative(slot, everyone[robot_ahead(slots, r)])
            goal, _ = merge_target((me.x, me.y), (ahead.x, ahead.y), lane=0.7, gap=0.6)
            cmd = filters[r].apply(law.compute(ControlInput(me, goal, twist, []), config), dt)
            scan = disc_scan(poses[r], [p for o, p in everyone.items() if o != r])
            cmd, held = safety_filter(cmd, *scan, config=config)
            if held:
                filters[r].sent(cmd)
            commands[r] = cmd
        poses = {r: integrate(poses[r], commands[r], dt) for r in robots}
        leader = integrate(leader, twist, dt)
    return None, closest


def test_a_diamond_of_five_becomes_a_column_on_the_move_without_a_sideways_step_at_the_end():
    a = 1.5 / math.sqrt(2)   # the diamond of 5 robots, spacing 1.5 m; the column's slots 1.5 m apart
    diamond = {"r1": (-2 * a, a / 2), "r2": (-2 * a, -a / 2), "r3": (-a, a), "r4": (-a, -a)}
    column = {"r1": (-6.0, 0.0), "r2": (-4.5, 0.0), "r3": (-1.5, 0.0), "r4": (-3.0, 0.0)}
    seconds, closest = switch_to_column(diamond, column)
    # the last follower drops 3.9 m back: it turns round (2 s) while its slot comes at 0.5 m/s;
    # waiting in the lane until the robot ahead was 0.6 m ahead took 5.55 s here
    assert seconds is not None and seconds < 5.3
    assert closest > 2 * RADIUS + 0.3
