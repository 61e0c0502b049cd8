"""The run's world: robots added on free, reachable cells near the first robot, apart from each
other and off the obstacles' paths; the copy works from anywhere."""
import math

import pytest
import yaml

from mbot_bringup.fleet_world import (PlacementConfig, main, obstacle_occupancy, parse_count, place_robots, run_world,
                                      write_run_world)
from mbot_common.geometry import relative
from mbot_common.paths import resolve_world
from mbot_common.strict_yaml import ConfigError
from mbot_common.world import load_world
from mbot_follower.free_space import FreeSpace


def placed(world_name, count, config=None):
    world = load_world(resolve_world(world_name))
    return world, place_robots(world, count, config or PlacementConfig())


def test_ten_robots_in_the_trio_room_are_apart_free_and_behind_the_leader_first():
    config = PlacementConfig()
    world, robots = placed("trio", 10, config)
    assert [r.name for r in robots] == ["leader", "follower_1", "follower_2"] + ["robot_%d" % i for i in range(3, 10)]
    m = world.map_data
    stand = FreeSpace(m.occupancy, m.resolution, m.origin[:2], config.robot_radius + config.wall_margin)
    for i, a in enumerate(robots):
        assert stand.is_free(a.pose.x, a.pose.y), a
        for b in robots[i + 1:]:
            assert math.hypot(a.pose.x - b.pose.x, a.pose.y - b.pose.y) >= config.spacing - 1e-9, (a, b)
    leader = robots[0].pose
    for r in robots[3:]:
        assert relative(leader, r.pose).x <= 1e-9, "%s is ahead of the leader" % r.name   # there is room behind
        assert r.pose.theta == leader.theta and r.model == "mbot"
        assert math.hypot(r.pose.x - leader.x, r.pose.y - leader.y) <= 3.0   # near: a 1 m lattice fills up close by


def test_no_robot_is_placed_on_the_moving_obstacle_path_or_the_crate():
    world, robots = placed("office", 20)
    occupancy = obstacle_occupancy(world)
    person = world.moving_obstacles[0]
    corners = person.waypoints
    assert occupancy[world.map_data.world_to_cell(*corners[1])[::-1]] == 100       # the path is painted
    crate = world.obstacles[0].pose
    assert occupancy[world.map_data.world_to_cell(crate.x, crate.y)[::-1]] == 100
    for r in robots:
        for (x0, y0), (x1, y1) in zip(corners, corners[1:] + corners[:1]):
            # distance of the robot from this side of the person's loop
            dx, dy = x1 - x0, y1 - y0
            u = max(0.0, min(1.0, ((r.pose.x - x0) * dx + (r.pose.y - y0) * dy) / (dx * dx + dy * dy)))
            d = math.hypot(r.pose.x - x0 - u * dx, r.pose.y - y0 - u * dy)
            assert d > 0.25 + 0.15, "%s stands on the person's path" % r.name
        assert math.hypot(r.pose.x - crate.x, r.pose.y - crate.y) > 0.5


def test_fewer_robots_keep_the_first_ones_and_too_many_is_an_error():
    world, robots = placed("office", 2)
    assert [r.name for r in robots] == ["robot_0", "robot_1"]
    with pytest.raises(ConfigError) as error:
        placed("corridor_fleet", 20, PlacementConfig(max_distance=2.0))
    assert "corridor_fleet.world.yaml: robots: room for only" in str(error.value)
    assert "asked for 20" in str(error.value)


def test_the_run_world_has_an_absolute_map_and_reads_back(tmp_path):
    out = str(tmp_path / "run" / "world.yaml")
    names = write_run_world("office", out, 5)
    world = load_world(out)
    assert [r.name for r in world.robots] == names == ["robot_0", "robot_1", "robot_2", "robot_3", "robot_4"]
    assert world.map.startswith("/") and world.map.endswith("maps/office.yaml")
    assert world.moving_obstacles[0].name == "person_1" and world.obstacles[0].name == "crate_1"
    text, same = run_world(resolve_world("office"))
    assert same == ["robot_0", "robot_1", "robot_2"]
    assert yaml.safe_load(text)["robots"][0] == {"name": "robot_0", "model": "mbot", "pose": [3.0, -4.0, 0.0]}


def test_the_command_line_prints_the_path_and_names_a_bad_count(tmp_path, capsys):
    out = str(tmp_path / "world.yaml")
    assert main(["--world", "trio", "--robots", "4", "--out", out]) == 0
    assert capsys.readouterr().out.strip() == out
    assert main(["--names", out]) == 0
    assert yaml.safe_load(capsys.readouterr().out) == ["leader", "follower_1", "follower_2", "robot_3"]
    assert main(["--world", "trio", "--robots", "many", "--out", out]) == 1
    assert 'robots: expected a number of robots from 1 to 60' in capsys.readouterr().err
    assert main(["--world", "trio", "--mode", "swarm", "--out", out]) == 1
    assert 'mode: expected formation or dispatch, got "swarm"' in capsys.readouterr().err
    assert parse_count("") is None and parse_count("7") == 7
