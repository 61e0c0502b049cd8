"""mbot_common.world: the 3D lidar and height keys (valid_lidar.world.yaml; the invalid_lidar_*,
invalid_wall_height and invalid_obstacle_height fixtures are checked with the others)."""
import os

from common_fixture_cases import WORLDS
from mbot_common.world import NO_LIDAR, load_world


def test_lidar_and_heights():
    w = load_world(os.path.join(WORLDS, "valid_lidar.world.yaml"))
    assert w.wall_height == 3.0
    first, second, third = (r.lidar for r in w.robots)
    assert first.enabled
    assert (first.rate, first.points_per_frame, first.min_elevation, first.max_elevation) == (20.0, 1000, -10.0, 45.0)
    assert (first.range_min, first.range_max, first.range_noise, first.range_quantization) == (0.2, 30.0, 0.01, 0.002)
    assert second == NO_LIDAR._replace(enabled=True)  # lidar: true: the Mid-360 defaults
    assert third == NO_LIDAR
    assert w.obstacles[0].height == 0.3
    assert w.moving_obstacles[0].height == 1.8


def test_defaults():
    w = load_world(os.path.join(WORLDS, "valid_minimal.world.yaml"))
    assert w.wall_height == 2.5
    assert w.robots == [] or all(r.lidar == NO_LIDAR for r in w.robots)
