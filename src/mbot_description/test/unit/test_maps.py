"""Tests of the maps and worlds in maps/: map_server files that load, closed walls, room for the
robots to move, default worlds whose robots stand free, the corridor's width."""
import glob
import math
import os
import subprocess
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from mbot_common.maps import FREE, OCCUPIED, load_map
from mbot_common.world import load_world as read_world_file
from scipy import ndimage

from paths import MAPS_DIR, MODELS, URDF_DIR

MAIN_MAPS = ("empty", "office", "cave", "corridor", "warehouse")
ALL_MAPS = MAIN_MAPS + ("bench_room", "bench_room_3x3", "field")
WORLDS = MAIN_MAPS + ("bench_room",)
CLEARANCE = 0.5       # [m] free space around each robot's footprint in a default world
ROBOT_MARGIN = 0.05   # [m] beyond the footprint radius when asking whether a robot can pass


class Map:
    """A map_server map as the robots get it (mbot_common.maps.load_map, strict): ``free[iy, ix]``
    with row 0 at the origin (as map_server flips it)."""

    def __init__(self, yaml_path):
        self.data = load_map(yaml_path)
        self.free = self.data.occupancy == FREE
        self.occupied = self.data.occupancy == OCCUPIED
        self.resolution = self.data.resolution
        self.origin = self.data.origin
        # Distance [m] from each cell centre to the nearest cell that is not free.
        self.distance = ndimage.distance_transform_edt(self.free) * self.resolution

    def cell(self, x, y):
        ix, iy = self.data.world_to_cell(x, y)
        assert self.data.contains(ix, iy), (x, y)
        return iy, ix

    def clearance(self, x, y):
        """Lower bound [m] of the distance from (x, y) to the nearest non-free space: a point and
        a cell centre are each up to res/sqrt(2) from what they stand for."""
        return self.distance[self.cell(x, y)] - self.resolution * math.sqrt(2.0)


def footprint_radius(model):
    """Circumscribed radius [m] of base_link's collision geometry in the model's URDF."""
    robot = ET.parse(os.path.join(URDF_DIR, model + ".urdf")).getroot()
    geometry = robot.find("link[@name='base_link']/collision/geometry")
    if geometry.find("cylinder") is not None:
        return float(geometry.find("cylinder").get("radius"))
    x, y, _ = (float(v) for v in geometry.find("box").get("size").split())
    return math.hypot(x, y) / 2.0


def load_world(name):
    """The world maps/NAME.world.yaml, read as strictly as stage_node reads it (mbot_common), and its map."""
    world = read_world_file(os.path.join(MAPS_DIR, name + ".world.yaml"))
    return world, Map(world.map_path)


def outer_radius(shape):
    """[m] the circle around an obstacle's shape: half a box's diagonal, a cylinder's radius."""
    return math.hypot(shape.length, shape.width) / 2 if shape.type == "box" else shape.radius


def segment_distance(p, a, b):
    ap, ab = np.subtract(p, a), np.subtract(b, a)
    t = np.clip(np.dot(ap, ab) / np.dot(ab, ab), 0.0, 1.0)
    return float(np.linalg.norm(ap - t * ab))


def path_segments(mover):
    points = mover.waypoints
    pairs = list(zip(points[:-1], points[1:]))
    if mover.mode == "loop":
        pairs.append((points[-1], points[0]))
    return pairs


# ---- maps


def test_every_map_has_a_yaml_and_nothing_else_is_there():
    yamls = [p for p in glob.glob(os.path.join(MAPS_DIR, "*.yaml")) if not p.endswith(".world.yaml")]
    found = sorted(os.path.basename(p)[: -len(".yaml")] for p in yamls)
    assert found == sorted(ALL_MAPS)


@pytest.mark.parametrize("name", ALL_MAPS)
def test_map_yaml_loads_and_matches_its_pgm(name):
    m = Map(os.path.join(MAPS_DIR, name + ".yaml"))
    assert m.data.image_path == os.path.join(MAPS_DIR, name + ".pgm")
    assert m.resolution == 0.05
    assert m.data.occupied_thresh == 0.65 and m.data.free_thresh == 0.196
    assert not m.data.negate and m.data.mode == "trinary"
    assert m.origin[2] == 0.0
    rows, cols = m.free.shape
    assert cols * m.resolution <= 60.0 and rows * m.resolution <= 60.0   # small PGMs
    # The map is centred on the map frame's origin.
    assert math.isclose(m.origin[0], -cols * m.resolution / 2, abs_tol=1e-9)
    assert math.isclose(m.origin[1], -rows * m.resolution / 2, abs_tol=1e-9)
    # Every cell is either free or occupied (no unknown), and the outer walls are closed.
    assert np.all(m.free ^ m.occupied)
    for edge in (m.occupied[0, :], m.occupied[-1, :], m.occupied[:, 0], m.occupied[:, -1]):
        assert edge.all()


@pytest.mark.parametrize("name", ALL_MAPS)
def test_free_space_is_one_region_a_robot_can_reach(name):
    m = Map(os.path.join(MAPS_DIR, name + ".yaml"))
    passable = m.distance >= max(footprint_radius(model) for model in MODELS) + ROBOT_MARGIN
    _, regions = ndimage.label(passable)
    assert regions == 1
    share = passable.mean()
    assert share > 0.25, "only %.0f %% of %s is room to drive" % (100 * share, name)


def test_corridor_is_1_5_m_wide_and_20_m_long():
    m = Map(os.path.join(MAPS_DIR, "corridor.yaml"))
    _, middle = m.cell(0.0, 0.0)
    column = m.free[:, middle]
    assert column.sum() * m.resolution == pytest.approx(1.5)
    assert column[m.cell(0.0, 0.0)[0]]                         # the free cells are around y = 0
    narrow = np.flatnonzero(m.free.sum(axis=0) == column.sum())
    assert len(narrow) * m.resolution == pytest.approx(20.0)
    assert np.all(np.diff(narrow) == 1)                        # one straight piece
    # open areas at both ends: much wider than the corridor
    for x in (-12.5, 12.5):
        assert m.free[:, m.cell(x, 0.0)[1]].sum() * m.resolution > 5.0


def test_office_doors_are_at_least_1_m_wide():
    # The wall south of the corridor (y in [-1.15, -1]) has three doors; measure them.
    m = Map(os.path.join(MAPS_DIR, "office.yaml"))
    row = m.free[m.cell(0.0, -1.07)[0], :]
    edges = np.flatnonzero(np.diff(row.astype(int)))
    openings = (edges[1::2] - edges[0::2]) * m.resolution
    assert len(openings) == 3
    assert openings.min() >= 1.0


def test_maps_are_up_to_date_with_their_generator():
    result = subprocess.run(["/usr/bin/python3", os.path.join(MAPS_DIR, "make_maps.py"), "--check"],
                            capture_output=True, text=True)
    assert result.returncode == 0, result.stderr


# ---- worlds


@pytest.mark.parametrize("name", WORLDS)
def test_world_reads_strictly_with_known_models(name):
    # the reader refuses unknown keys, wrong types and names used twice
    world, _ = load_world(name)
    robots = world.robots
    assert len(robots) == (1 if name == "bench_room" else 3)
    for robot in robots:
        assert robot.model in MODELS
    if name != "bench_room":
        assert [r.name for r in robots] == ["robot_0", "robot_1", "robot_2"]


@pytest.mark.parametrize("name", WORLDS)
def test_robots_stand_free_with_clearance(name):
    world, m = load_world(name)
    robots = world.robots
    radius = {r.name: footprint_radius(r.model) for r in robots}
    for robot in robots:
        x, y = robot.pose.x, robot.pose.y
        r = radius[robot.name]
        assert m.free[m.cell(x, y)], robot.name
        assert m.clearance(x, y) - r >= CLEARANCE, (robot.name, m.clearance(x, y) - r)
        for other in robots:
            if other is not robot:
                gap = math.dist((x, y), (other.pose.x, other.pose.y)) - r - radius[other.name]
                assert gap >= CLEARANCE, (robot.name, other.name, gap)
        for obstacle in world.obstacles:
            gap = math.dist((x, y), (obstacle.pose.x, obstacle.pose.y)) - r - outer_radius(obstacle.shape)
            assert gap >= CLEARANCE, (robot.name, obstacle.name, gap)
        for mover in world.moving_obstacles:
            path = min(segment_distance((x, y), a, b) for a, b in path_segments(mover))
            gap = path - r - outer_radius(mover.shape)
            assert gap >= CLEARANCE, (robot.name, mover.name, gap)


@pytest.mark.parametrize("name", WORLDS)
def test_obstacles_are_in_free_space(name):
    world, m = load_world(name)
    for obstacle in world.obstacles:
        assert m.free[m.cell(obstacle.pose.x, obstacle.pose.y)]
    for mover in world.moving_obstacles:
        for a, b in path_segments(mover):
            steps = int(math.dist(a, b) / m.resolution) + 1
            for t in np.linspace(0.0, 1.0, steps + 1):
                x, y = np.add(a, t * np.subtract(b, a))
                assert m.clearance(x, y) >= outer_radius(mover.shape), (mover.name, x, y)


def test_office_world_has_a_walking_person_and_a_box():
    world, _ = load_world("office")
    assert [o.shape.type for o in world.obstacles] == ["box"]
    (person,) = world.moving_obstacles
    assert person.mode == "loop" and person.speed > 0 and len(person.waypoints) >= 3


def test_corridor_world_puts_robots_at_both_ends():
    world, _ = load_world("corridor")
    xs = [r.pose.x for r in world.robots]
    assert min(xs) < -10.0 and max(xs) > 10.0     # the corridor runs from x = -10 to 10
