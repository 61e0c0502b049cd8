"""Merging into a column in slot order (merge.py)."""
import pytest

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
    target, waiting = merge_target((2.0, -0.53), (2.1, 0.53), lane=0.7, gap=0.6)
    assert waiting and target == pytest.approx((0.0, -0.7))


def test_a_follower_further_out_keeps_its_distance_from_the_path_while_it_waits():
    target, waiting = merge_target((1.0, -1.06), (1.2, 1.06), lane=0.7, gap=0.6)
    assert waiting
    assert target == pytest.approx((0.0, -1.06))


def test_a_follower_joins_the_path_once_the_robot_ahead_is_far_enough_ahead():
    assert merge_target((1.0, 1.06), (1.6, -0.2), lane=0.7, gap=0.6) == ((0.0, 0.0), False)
    # just short of the gap it still waits
    assert merge_target((1.0, 1.06), (1.55, -0.2), lane=0.7, gap=0.6)[1]


def test_a_follower_near_the_path_is_never_pulled_out_of_it():
    assert merge_target((0.5, 0.3), (0.5, 0.0), lane=0.7, gap=0.6) == ((0.0, 0.0), False)
    assert merge_target((0.5, -0.34), (0.0, 0.0), lane=0.7, gap=0.6) == ((0.0, 0.0), False)


def test_without_a_pose_of_the_robot_ahead_the_follower_drives_to_its_slot():
    assert merge_target((2.0, 1.0), None, lane=0.7, gap=0.6) == ((0.0, 0.0), False)
