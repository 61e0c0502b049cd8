"""mbot_common.paths: names are looked up in the given maps directory, then in the workspace's
maps/; paths are made absolute; an unknown name names every place searched."""
import os

import pytest

from common_fixture_cases import FIXTURES
from mbot_common.paths import find_maps_directory, is_map_path, is_world_path, resolve_map, resolve_world
from mbot_common.strict_yaml import ConfigError

WORKSPACE_MAPS = os.path.normpath(os.path.join(FIXTURES, "..", "..", "..", "..", "maps"))


def test_finds_the_workspace_maps():
    assert os.path.isfile(os.path.join(WORKSPACE_MAPS, "office.world.yaml"))
    assert os.path.normpath(find_maps_directory()) == WORKSPACE_MAPS
    assert find_maps_directory(os.path.join(FIXTURES, "worlds")) == os.path.join(FIXTURES, "maps")
    assert find_maps_directory("/") is None


def test_names_and_paths():
    assert is_world_path("office.world.yaml") and is_world_path("worlds/office")
    assert not is_world_path("office")
    assert is_map_path("office.yaml") and not is_map_path("office")
    assert resolve_world("office") == os.path.join(WORKSPACE_MAPS, "office.world.yaml")
    assert resolve_map("office") == os.path.join(WORKSPACE_MAPS, "office.yaml")
    worlds = os.path.join(FIXTURES, "worlds")
    assert resolve_world("valid_minimal", worlds) == os.path.join(worlds, "valid_minimal.world.yaml")
    assert resolve_world("office", worlds) == os.path.join(WORKSPACE_MAPS, "office.world.yaml")
    assert resolve_map("tiny", os.path.join(FIXTURES, "maps")) == os.path.join(FIXTURES, "maps", "tiny.yaml")
    assert resolve_world("some/where.world.yaml") == os.path.abspath("some/where.world.yaml")


def test_an_unknown_name_names_what_was_searched():
    worlds = os.path.join(FIXTURES, "worlds")
    with pytest.raises(ConfigError) as info:
        resolve_world("atlantis", worlds)
    assert str(info.value) == 'world "atlantis": no world file of that name (searched %s, %s)' % (
        os.path.join(worlds, "atlantis.world.yaml"), os.path.join(WORKSPACE_MAPS, "atlantis.world.yaml"))
    with pytest.raises(ConfigError, match="expected a world name"):
        resolve_world("")
