"""Demo goals are looked up by world name or path, and a world without goals says so."""
import math
import os

import pytest

from mbot_bringup.goal_tour import load_goals
from mbot_navigation.move_base_client import make_goal

GOALS = os.path.join(os.path.dirname(__file__), "..", "..", "config", "demo_goals.yaml")


def test_goals_by_name_and_by_world_path():
    by_name = load_goals(GOALS, "office")
    assert by_name == load_goals(GOALS, "/anywhere/maps/office.world.yaml")
    assert sorted(by_name) == ["robot_0", "robot_1", "robot_2"]
    assert all(len(g) == 3 for goals in by_name.values() for g in goals)


def test_unknown_world_names_the_file_and_the_worlds():
    with pytest.raises(KeyError) as err:
        load_goals(GOALS, "moon")
    assert "no goals for world 'moon'" in str(err.value)
    assert "office" in str(err.value)


def test_make_goal_is_a_unit_quaternion_with_the_yaw():
    goal = make_goal(1.0, 2.0, math.pi / 2)
    q = goal.target_pose.pose.orientation
    assert goal.target_pose.header.frame_id == "map"
    assert math.hypot(q.z, q.w) == pytest.approx(1.0)
    assert 2 * math.atan2(q.z, q.w) == pytest.approx(math.pi / 2)
