"""Built-in formation shapes, their parents, and custom formations read from YAML files."""
import math
import os

import numpy as np
import pytest

from mbot_common.strict_yaml import ConfigError
from mbot_follower.formations import (FORMATION_NAMES, MAX_ROBOTS, Formation, FormationError,
                                      FormationLibrary, chain_parents, make_formation, min_robots,
                                      world_slots)

FIXTURES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))),
                        "fixtures", "formations")
SPACING = 1.5


def all_builtin_cases(top=10):
    cases = []
    for name in FORMATION_NAMES:
        for n in range(min_robots(name), top + 1):
            if name == "rectangle" and n % 2:
                continue
            cases.append((name, n))
    return cases


def pair_distances(offsets):
    diff = offsets[:, None, :] - offsets[None, :, :]
    d = np.hypot(diff[:, :, 0], diff[:, :, 1])
    np.fill_diagonal(d, np.inf)
    return d


def is_mirror_symmetric(offsets):
    """True if mirroring about the x axis (y -> -y) maps the set of slots onto itself."""
    mirrored = offsets * np.array([1.0, -1.0])
    return all(np.min(np.hypot(*(offsets - m).T)) < 1e-9 for m in mirrored)


def follows_to_leader(parents):
    for i in range(len(parents)):
        seen = set()
        while i != 0:
            assert i not in seen, "cycle in %s" % (parents,)
            seen.add(i)
            i = parents[i]
    return True


def test_minimum_counts():
    assert [min_robots(name) for name in FORMATION_NAMES] == [2, 2, 3, 2, 4, 4, 3]


@pytest.mark.parametrize("name,n", all_builtin_cases())
def test_every_builtin_leader_in_front_and_neighbours_one_spacing_apart(name, n):
    f = make_formation(name, n, SPACING)
    assert isinstance(f, Formation) and f.name == name and f.spacing == SPACING
    assert f.offsets.shape == (n, 2)
    assert tuple(f.offsets[0]) == (0.0, 0.0)
    assert np.max(f.offsets[:, 0]) <= 0.0
    nearest = np.min(pair_distances(f.offsets), axis=1)
    if name == "diamond" and n % 4:
        # 1 spacing along the outline, straight across a 90 deg corner no less than 1/sqrt(2)
        assert np.all(nearest >= SPACING / math.sqrt(2) - 1e-9)
        assert np.all(nearest <= SPACING + 1e-9)
    else:
        np.testing.assert_allclose(nearest, SPACING, atol=1e-9)


@pytest.mark.parametrize("name,n", all_builtin_cases())
def test_symmetric_about_the_x_axis_where_possible(name, n):
    asymmetric = (name == "rectangle" or (name in ("line", "wedge") and n % 2 == 0)
                  or (name == "triangle" and n in (7, 9)))
    assert is_mirror_symmetric(make_formation(name, n, SPACING).offsets) == (not asymmetric)


def test_triangle_of_three_is_equilateral_and_circle_is_regular():
    d = pair_distances(make_formation("triangle", 3, 2.0).offsets)
    np.testing.assert_allclose(d[np.triu_indices(3, 1)], [2.0, 2.0, 2.0], atol=1e-12)
    circle = make_formation("circle", 7, 1.0).offsets
    centre = circle.mean(axis=0)
    radius = 0.5 / math.sin(math.pi / 7)
    np.testing.assert_allclose(centre, [-radius, 0.0], atol=1e-9)
    np.testing.assert_allclose(np.hypot(*(circle - centre).T), radius, atol=1e-9)


def test_exact_slots_of_a_few_shapes():
    np.testing.assert_allclose(make_formation("line", 4, 1.0).offsets, [[0, 0], [0, 1], [0, -1], [0, 2]])
    np.testing.assert_allclose(make_formation("column", 3, 0.5).offsets, [[0, 0], [-0.5, 0], [-1, 0]])
    np.testing.assert_allclose(make_formation("rectangle", 6, 1.0).offsets,
                               [[0, 0], [0, -1], [-1, 0], [-1, -1], [-2, 0], [-2, -1]])
    r = 1 / math.sqrt(2)
    np.testing.assert_allclose(make_formation("diamond", 4, 1.0).offsets,
                               [[0, 0], [-r, r], [-r, -r], [-2 * r, 0]], atol=1e-12)
    np.testing.assert_allclose(make_formation("wedge", 3, 1.0).offsets,
                               [[0, 0], [-r, r], [-r, -r]], atol=1e-12)
    h = math.sqrt(3) / 2   # triangle of 5: the last row keeps its middle place free
    np.testing.assert_allclose(make_formation("triangle", 5, 1.0).offsets,
                               [[0, 0], [-h, 0.5], [-h, -0.5], [-2 * h, 1], [-2 * h, -1]], atol=1e-12)


@pytest.mark.parametrize("name,n", all_builtin_cases())
def test_star_and_chain_parents(name, n):
    star = make_formation(name, n, SPACING, topology="star")
    assert star.parents == tuple([-1] + [0] * (n - 1))
    chain = make_formation(name, n, SPACING, topology="chain")
    np.testing.assert_array_equal(chain.offsets, star.offsets)
    assert chain.parents[0] == -1 and follows_to_leader(chain.parents)
    reach = np.hypot(*chain.offsets.T)
    for i in range(1, n):
        p = chain.parents[i]
        assert reach[p] < reach[i] - 1e-9            # the parent is closer to the leader
        closer = [j for j in range(n) if reach[j] < reach[i] - 1e-9]
        gap = np.hypot(*(chain.offsets[closer] - chain.offsets[i]).T)
        assert np.hypot(*(chain.offsets[p] - chain.offsets[i])) <= np.min(gap) + 1e-9


def test_chain_parents_of_a_few_shapes():
    assert make_formation("column", 4, 1.0, "chain").parents == (-1, 0, 1, 2)
    assert make_formation("line", 5, 1.0, "chain").parents == (-1, 0, 0, 1, 2)
    assert make_formation("wedge", 5, 1.0, "chain").parents == (-1, 0, 0, 1, 2)
    # the two back slots of a 5-diamond are equally far from the leader: mirror parents
    assert make_formation("diamond", 5, 1.0, "chain").parents == (-1, 0, 0, 1, 2)
    assert chain_parents([[0, 0], [-1, 0], [-1, -1]]) == (-1, 0, 1)


def test_unknown_name_lists_the_known_ones():
    with pytest.raises(FormationError) as e:
        make_formation("blob", 3, 1.0)
    assert str(e.value) == ("unknown formation 'blob' (known: line, column, triangle, wedge, "
                            "rectangle, diamond, circle)")
    with pytest.raises(FormationError):
        min_robots("blob")


@pytest.mark.parametrize("name,n,says", [
    ("triangle", 2, "formation 'triangle' takes at least 3 robots, got 2"),
    ("diamond", 3, "formation 'diamond' takes at least 4 robots, got 3"),
    ("line", 1, "formation 'line' takes at least 2 robots, got 1"),
    ("column", MAX_ROBOTS + 1, "formation 'column' takes at most 60 robots, got 61"),
    ("rectangle", 5, "formation 'rectangle' takes an even number of robots (4, 6, 8, ...), got 5"),
])
def test_robot_counts_the_shape_does_not_take(name, n, says):
    with pytest.raises(FormationError) as e:
        make_formation(name, n, 1.0)
    assert str(e.value) == says


@pytest.mark.parametrize("spacing", [0.0, -1.0, float("nan"), float("inf"), "1.0", True, None])
def test_bad_spacing(spacing):
    with pytest.raises(FormationError, match="spacing must be a finite number > 0"):
        make_formation("line", 3, spacing)


def test_bad_topology_and_count_type():
    with pytest.raises(FormationError, match="topology must be one of star, chain, got 'ring'"):
        make_formation("line", 3, 1.0, topology="ring")
    with pytest.raises(FormationError, match="must be an integer"):
        make_formation("line", 3.0, 1.0)


def test_world_slots_turn_and_move_with_the_leader():
    f = make_formation("wedge", 3, math.sqrt(2))   # slots (-1, 1), (-1, -1)
    np.testing.assert_allclose(world_slots(f, (2.0, 3.0, math.pi / 2)),
                               [[2, 3], [1, 2], [3, 2]], atol=1e-12)


# ------------------------------------------------------------------ custom formations

def fixture(name):
    return os.path.join(FIXTURES, name)


def loaded_library():
    library = FormationLibrary()
    assert library.load_file(fixture("valid_custom.yaml")) == ["arrow", "echelon", "tail"]
    return library


def test_custom_formations_are_scaled_and_keep_their_parents():
    library = loaded_library()
    assert library.names() == ("arrow", "echelon", "tail")
    arrow = library.make("arrow", 4, 2.0)
    np.testing.assert_allclose(arrow.offsets, [[0, 0], [-2, 1], [-2, -1], [-4, 0]])
    assert arrow.parents == (-1, 0, 0, 2)                  # explicit parents in the file
    assert library.make("arrow", 4, 2.0, topology="star").parents == (-1, 0, 0, 2)
    assert library.make("echelon", 4, 1.0).parents == (-1, 0, 1, 2)   # the file says chain
    assert library.make("tail", 3, 1.0).parents == (-1, 0, 0)         # nothing said: star
    assert library.make("tail", 3, 1.0, topology="chain").parents == (-1, 0, 1)
    # through make_formation, whose default topology "star" does not override the file
    echelon = make_formation("echelon", 4, 0.5, library=library)
    assert echelon.parents == (-1, 0, 1, 2)
    np.testing.assert_allclose(echelon.offsets[3], [-1.5, -1.5])
    assert min_robots("echelon", library) == 4
    # the library makes built-ins too
    assert library.make("column", 3, 1.0, topology="chain").parents == (-1, 0, 1)


def test_column_and_custom_formations_that_say_so_drive_along_the_path():
    library = loaded_library()
    assert library.make("tail", 3, 1.0).along_path                 # along_path: true in the file
    assert not library.make("arrow", 4, 1.0).along_path            # not said: rigid
    assert make_formation("column", 3, 1.0).along_path
    assert library.make("column", 3, 1.0, topology="chain").along_path
    for name in ("line", "triangle", "wedge", "rectangle", "diamond", "circle"):
        assert not make_formation(name, 4, 1.0).along_path, name


def test_custom_formation_takes_exactly_its_slot_count():
    library = loaded_library()
    with pytest.raises(FormationError) as e:
        library.make("arrow", 5, 1.0)
    assert "formation 'arrow'" in str(e.value) and "takes exactly 4 robots, got 5" in str(e.value)
    with pytest.raises(FormationError) as e:
        make_formation("kite", 4, 1.0, library=library)
    assert str(e.value).endswith("(known: line, column, triangle, wedge, rectangle, diamond, "
                                 "circle, arrow, echelon, tail)")
    with pytest.raises(FormationError, match="spacing"):
        library.make("arrow", 4, -1.0)


def test_a_file_loaded_twice_is_an_error_and_a_bad_file_adds_nothing():
    library = loaded_library()
    with pytest.raises(ConfigError, match="formations.arrow: formation 'arrow' is already loaded"):
        library.load_file(fixture("valid_custom.yaml"))
    with pytest.raises(ConfigError):
        library.load_file(fixture("invalid_slot_ahead.yaml"))
    assert library.names() == ("arrow", "echelon", "tail")


@pytest.mark.parametrize("name,key,problem", [
    ("invalid_unknown_key.yaml", "formations.arrow.topolgy", "unknown key"),
    ("invalid_slots_type.yaml", "formations.arrow.slots", "expected a list of [x, y] slots"),
    ("invalid_slot_not_xy.yaml", "formations.arrow.slots[2]", "expected [x, y] (two numbers"),
    ("invalid_slot_quoted_number.yaml", "formations.arrow.slots[1]", "expected [x, y] (two numbers"),
    ("invalid_leader_not_origin.yaml", "formations.arrow.slots[0]", "must be [0, 0]"),
    ("invalid_slot_ahead.yaml", "formations.arrow.slots[2]", "ahead of the leader (x > 0)"),
    ("invalid_slots_too_close.yaml", "formations.arrow.slots[2]",
     "only 0.283 from slots[1]: slots must be at least 0.5 spacing apart"),
    ("invalid_parents_cycle.yaml", "formations.arrow.parents", "slots 2 -> 3 -> 2 form a cycle"),
    ("invalid_parents_no_leader.yaml", "formations.arrow.parents",
     "parents[2] = -1: expected the index of another slot, 0 to 2 (only the leader follows nobody)"),
    ("invalid_parents_length.yaml", "formations.arrow.parents", "expected 3 entries (one per slot), got 2"),
    ("invalid_topology.yaml", "formations.arrow.topology", 'expected star or chain, got "ring"'),
    ("invalid_along_path_type.yaml", "formations.arrow.along_path", 'expected true or false, got "yes"'),
    ("invalid_shadows_builtin.yaml", "formations.wedge", "'wedge' is a built-in formation"),
    ("invalid_top_level_key.yaml", "spacing", "unknown key"),
    ("no_such_file.yaml", None, "cannot read the file"),
])
def test_invalid_files_name_the_file_and_the_key(name, key, problem):
    path = fixture(name)
    with pytest.raises(ConfigError) as e:
        FormationLibrary().load_file(path)
    message = str(e.value)
    assert "\n" not in message
    assert message.startswith(path + ": " + (key + ": " if key else "")), message
    assert problem in message, message
