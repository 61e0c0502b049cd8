"""Demo goals are looked up by world name or path, and a world without goals says so."""
import math
import os

import pytest

from mbot_bringup.goal_tour import check_goals, load_goals
from mbot_common.strict_yaml import ConfigError
from mbot_navigation.move_base_client import make_goal

GOALS = os.path.join(os.path.dirname(__file__), "..", "..", "config", "demo_goals.yaml")


def test_goals_by_name_and_by_world_path():
    by_name = load_goals(GOALS, "office")
    assert by_name == load_goals(GOALS, "/anywhere/maps/office.world.yaml")
    assert sorted(by_name) == ["robot_0", "robot_1", "robot_2"]
    assert all(len(g) == 3 for goals in by_name.values() for g in goals)


def test_unknown_world_names_the_file_and_the_worlds():
    with pytest.raises(ConfigError) as err:
        load_goals(GOALS, "moon")
    assert "no goals for world 'moon'" in str(err.value)
    assert "office" in str(err.value)


def test_make_goal_is_a_unit_quaternion_with_the_yaw():
    goal = make_goal(1.0, 2.0, math.pi / 2)
    q = goal.target_pose.pose.orientation
    assert goal.target_pose.header.frame_id == "map"
    assert math.hypot(q.z, q.w) == pytest.approx(1.0)
    assert 2 * math.atan2(q.z, q.w) == pytest.approx(math.pi / 2)


@pytest.mark.parametrize("goals, problem", [
    ({"robot_0": [[1.0, 2.0]]}, "robot_0[0]: expected [x, y, yaw]"),
    ({"robot_0": [[1.0, "two", 0.0]]}, "robot_0[0]: expected [x, y, yaw]"),
    ({"robot_0": [[1.0, float("nan"), 0.0]]}, "three finite numbers"),
    ({"robot_0": [[0.0, 0.0, 0.0]], "robot_1": []}, "robot_1: expected a non-empty list"),
    ({"robot_0": [0.0, 0.0, 0.0]}, "robot_0[0]: expected [x, y, yaw]"),
    ([[0.0, 0.0, 0.0]], "expected a map robot -> list of goals"),
])
def test_a_bad_goal_is_an_error_naming_the_robot_and_the_goal(goals, problem):
    with pytest.raises(ConfigError) as err:
        check_goals(goals, "demo_goals.yaml: office")
    assert problem in str(err.value)
    assert str(err.value).startswith("demo_goals.yaml: office")


def test_a_missing_or_broken_goals_file_is_an_error_naming_it(tmp_path):
    with pytest.raises(ConfigError, match="cannot read the file"):
        load_goals(str(tmp_path / "none.yaml"), "office")
    broken = tmp_path / "broken.yaml"
    broken.write_text("office:\n  robot_0: [[1, 2, 3]\n")
    with pytest.raises(ConfigError, match="not valid YAML"):
        load_goals(str(broken), "office")
    bad_goal = tmp_path / "bad.yaml"
    bad_goal.write_text("office:\n  robot_0: [[1, 2, 3], [4, 5]]\n")
    with pytest.raises(ConfigError, match=r"bad.yaml: office: robot_0\[1\]"):
        load_goals(str(bad_goal), "office")
