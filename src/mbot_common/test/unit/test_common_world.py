"""mbot_common.world: the valid world fixtures read into the right values, and every
invalid_* fixture gives the message of its `# expect:` line, the same line test_world_file.cpp
checks the C++ reader against: the two readers agree."""
import os

import pytest

from common_fixture_cases import WORLDS, invalid_fixtures
from mbot_common.geometry import Pose2D
from mbot_common.strict_yaml import ConfigError
from mbot_common.world import IMU_DEFAULTS, Faults, ImuNoise, check_faults, check_name, load_world


def test_reads_every_key():
    path = os.path.join(WORLDS, "valid_full.world.yaml")
    w = load_world(path)
    assert w.file == path
    assert w.map == "room.yaml"
    assert w.map_path == os.path.join(WORLDS, "room.yaml")  # relative to the world file
    assert (w.map_data.width, w.map_data.height, w.map_data.resolution) == (20, 16, 0.5)
    assert w.map_data.occupancy[0, 0] == 100 and w.map_data.occupancy[1, 1] == 0
    assert (w.physics_step, w.real_time_factor, w.seed) == (0.005, 0.0, 7)
    assert [(r.name, r.model, r.key) for r in w.robots] == [("leader", "mbot", "robots[0]"),
                                                            ("follower_1", "mbot_omni", "robots[1]")]
    assert w.robots[0].pose == Pose2D(1.0, 1.0, 0.5) and isinstance(w.robots[0].pose, Pose2D)
    assert w.robots[1].pose.theta == -0.5
    crate, unnamed = w.obstacles
    assert (crate.name, crate.shape.type, crate.shape.length, crate.shape.width) == ("crate_1", "box", 0.5, 0.4)
    assert crate.pose.theta == 0.3
    assert (unnamed.name, unnamed.shape.type, unnamed.shape.radius) == ("obstacle_1", "cylinder", 0.2)
    person, cart = w.moving_obstacles
    assert (person.name, person.mode, person.speed) == ("person_1", "ping_pong", 0.6)
    assert person.waypoints == [(2.0, 6.0), (8.0, 6.0), (8.0, 7.0)]
    assert (cart.name, cart.mode, cart.shape.type) == ("moving_obstacle_1", "loop", "box")
    assert (person.yielding, person.personal_radius) == (0.5, 1.2)
    assert (cart.yielding, cart.personal_radius) == (1.0, 0.8)  # the defaults
    assert tuple(w.noise[:3]) == (0.01, 0.02, 0.03)
    assert w.noise.imu == ImuNoise(400.0, 0.001, 0.0001, 0.002, 0.01, 0.001, 0.03, 0.0002, 0.002, -0.004)
    assert len(w.faults) == 1 and w.faults[0].robot == "follower_1"
    assert w.faults[0].faults == Faults(0.1, 0.05, 0.01, 0.02, False, True)


@pytest.mark.parametrize("name", ["valid_minimal.world.yaml", "valid_empty_sections.world.yaml"])
def test_defaults_when_optional_keys_are_missing_or_empty(name):
    w = load_world(os.path.join(WORLDS, name))
    assert (w.physics_step, w.real_time_factor, w.seed) == (0.01, 1.0, 0)
    assert w.robots == [] and w.obstacles == [] and w.moving_obstacles == [] and w.faults == []
    assert tuple(w.noise[:3]) == (0.0, 0.0, 0.0)
    assert w.noise.imu == IMU_DEFAULTS  # the consumer MEMS defaults


def test_three_robots():
    w = load_world(os.path.join(WORLDS, "valid_three_robots.world.yaml"))
    assert [r.name for r in w.robots] == ["robot_0", "robot_1", "robot_2"]
    assert w.robots[2].pose == Pose2D(6.0, 1.5, 0.0)
    assert w.real_time_factor == 5.0


@pytest.mark.parametrize("path, expected", invalid_fixtures(WORLDS, ".world.yaml"),
                         ids=lambda v: os.path.basename(v) if v.startswith("/") else "")
def test_each_invalid_fixture_gives_its_message(path, expected):
    assert expected, "%s: no '# expect: ' first line" % path
    with pytest.raises(ConfigError) as info:
        load_world(path)
    assert expected in str(info.value)
    assert "\n" not in str(info.value)


def test_there_are_invalid_world_fixtures():
    assert len(invalid_fixtures(WORLDS, ".world.yaml")) >= 40


def test_every_workspace_world_loads():
    maps = os.path.join(os.path.dirname(os.path.dirname(os.path.dirname(WORLDS))), "..", "..", "maps")
    worlds = sorted(f for f in os.listdir(maps) if f.endswith(".world.yaml"))
    assert "office.world.yaml" in worlds
    for name in worlds:
        w = load_world(os.path.join(maps, name))
        assert w.map_data.width > 0 and w.map_data.height > 0, name


def test_names_and_fault_ranges():
    assert check_name("fleet/robot_3") == ""
    for bad in ["", "3robot", "/robot", "robot/", "a//b", "robot-1", "robot 1"]:
        assert check_name(bad) != "", bad
    assert check_faults(Faults(0.0, 0.0, 0.0, 0.0, False, False)) == ""
    assert check_faults(Faults(0.0, 0.0, 10.5, 0.0, False, False)) == \
        "sensor_jitter: expected a standard deviation in [0, 10] s, got 10.5"
