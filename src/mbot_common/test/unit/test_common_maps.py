"""mbot_common.maps: map_server's values for every mode, negate, thresholds, the image flip,
every PGM flavour, cell <-> world, and each invalid map fixture's message (the same numbers and
the same `# expect:` lines as the C++ test_map_io.cpp)."""
import os

import numpy as np
import pytest

from common_fixture_cases import MAPS, invalid_fixtures
from mbot_common.maps import load_map, occupancy_from_image, read_pgm
from mbot_common.strict_yaml import ConfigError


def data_of(name):
    """The occupancy as the C++ test compares it: row-major, row 0 at the bottom."""
    return load_map(os.path.join(MAPS, name)).occupancy.ravel().tolist()


def test_trinary_values_and_flip_as_map_server():
    m = load_map(os.path.join(MAPS, "tiny.yaml"))
    assert (m.width, m.height) == (3, 2)
    assert m.resolution == 0.1 and m.origin == (-1.0, 2.0, 0.0)
    assert (m.occupied_thresh, m.free_thresh, m.negate, m.mode) == (0.65, 0.196, False, "trinary")
    assert m.path == os.path.join(MAPS, "tiny.yaml")
    assert m.image_path == os.path.join(MAPS, "tiny.pgm")
    assert m.occupancy.dtype == np.int8 and m.occupancy.shape == (2, 3)
    # tiny.pgm top row first: 0 100 160 / 200 254 255; map row 0 is the image's bottom row
    assert m.occupancy.tolist() == [[-1, 0, 0], [100, -1, -1]]
    assert m.occupancy[1, 0] == 100  # the image's top-left pixel (black) is the top-left cell


def test_negate_and_thresholds():
    assert data_of("tiny_negate.yaml") == [100, 100, 100, 0, -1, -1]
    assert data_of("tiny_thresholds.yaml") == [0, 0, 0, 100, 100, -1]


def test_scale_and_raw_modes():
    # scale: 1 + 98 (p - 0.196) / (0.65 - 0.196) truncated: v 200 -> 5, v 100 -> 89, v 160 -> 39
    assert data_of("tiny_scale.yaml") == [5, 0, 0, 100, 89, 39]
    # raw: the grey value in an int8 as map_server stores it (200 -> -56)
    assert data_of("tiny_raw.yaml") == [-56, -2, -1, 0, 100, -96]
    assert data_of("tiny_raw_negate.yaml") == [55, 1, 0, -1, -101, 95]
    assert load_map(os.path.join(MAPS, "tiny_raw_negate.yaml")).negate is True


def test_every_image_flavour_gives_the_same_map():
    text = data_of("tiny.yaml")
    assert data_of("tiny_p5.yaml") == text
    assert data_of("tiny_maxval15.yaml") == text
    assert data_of("tiny_16bit.yaml") == text
    assert read_pgm(os.path.join(MAPS, "tiny_16bit.pgm")).tolist() == [[0, 99, 159], [199, 253, 255]]
    assert read_pgm(os.path.join(MAPS, "tiny_maxval15.pgm")).tolist() == [[0, 102, 170], [204, 255, 255]]


def test_occupancy_from_image_matches_map_server_on_every_grey_value():
    grey = np.arange(256, dtype=np.uint8).reshape(1, 256)
    occ = (255.0 - np.arange(256)) / 255.0
    trinary = occupancy_from_image(grey, 0.65, 0.196, False, "trinary")[0]
    assert (trinary[occ > 0.65] == 100).all() and (trinary[occ < 0.196] == 0).all()
    assert (trinary[(occ >= 0.196) & (occ <= 0.65)] == -1).all()
    scale = occupancy_from_image(grey, 0.65, 0.196, False, "scale")[0]
    between = (occ >= 0.196) & (occ <= 0.65)
    assert scale[between].min() == 1 and scale[between].max() == 98  # 99 only at p == occupied_thresh
    assert (np.diff(scale[between].astype(int)) <= 0).all()  # darker is more occupied
    negated = occupancy_from_image(grey, 0.65, 0.196, True, "trinary")[0]
    assert negated.tolist() == trinary[::-1].tolist()


def test_cells_and_world_points():
    m = load_map(os.path.join(MAPS, "tiny.yaml"))  # origin (-1, 2), 0.1 m/cell
    assert m.world_to_cell(-0.95, 2.15) == (0, 1)
    assert m.world_to_cell(-0.71, 2.01) == (2, 0)
    assert m.world_to_cell(-1.01, 2.0) == (-1, 0)
    assert not m.contains(-1, 0) and m.contains(2, 1)
    assert m.cell_to_world(2, 1) == pytest.approx((-0.75, 2.15))
    rotated = load_map(os.path.join(MAPS, "tiny_rotated.yaml"))  # origin (1, 1) turned by pi/2
    assert rotated.cell_to_world(2, 1) == pytest.approx((0.25, 2.25))
    assert rotated.world_to_cell(0.25, 2.25) == (2, 1)


@pytest.mark.parametrize("path, expected", invalid_fixtures(MAPS, ".yaml"),
                         ids=lambda v: os.path.basename(v) if v.startswith("/") else "")
def test_each_invalid_fixture_gives_its_message(path, expected):
    assert expected, "%s: no '# expect: ' first line" % path
    with pytest.raises(ConfigError) as info:
        load_map(path)
    assert expected in str(info.value)
    assert "\n" not in str(info.value)


def test_there_are_invalid_map_fixtures():
    assert len(invalid_fixtures(MAPS, ".yaml")) >= 14


def test_missing_map_file():
    path = os.path.join(MAPS, "no_such_map.yaml")
    with pytest.raises(ConfigError) as info:
        load_map(path)
    assert str(info.value) == path + ": cannot read the file (missing or unreadable)"
