"""Formation shapes: where each robot's slot is, relative to the leader.

A formation of n robots is n slots in the LEADER FRAME (the leader's base_link: x forward,
y left [m]). Slot 0 is the leader itself at (0, 0); no slot is ahead of it (x <= 0), so the
leader always drives in front. `spacing` [m] is the distance between neighbouring slots.
Every follower also has a parent, the slot it keeps its distance to:
  star  - every follower follows the leader (slot 0);
  chain - every follower follows the nearest of the slots that are closer to the leader than
          itself (ties: the lower slot index), so each chain of parents ends at the leader.

The built-in shapes, drawn for spacing 1 with the leader L driving up the page (x up, y left);
numbers are slot indices. Followers are numbered from the leader back, left before right.

  line (n >= 2)      column (n >= 2)   wedge (n >= 2)      triangle (n >= 3)
  side by side,      one behind the    a V, arms 45 deg    rows of 1, 2, 3, ... places 1 apart
  leader in the      other             back from the       (rows sqrt(3)/2 apart: equilateral
  middle                               leader              triangles); a last row that is not
                                                           full fills from the middle out

  3  1  L  2  4           L                 L                   L            L
                          1               1   2               1   2        1   2
                          2             3       4           4   3   5    3       4
                          3                                   (n = 6)      (n = 5)

  rectangle (n = 4, 6, 8, ...)   diamond (n >= 4)              circle (n >= 3)
  two columns 1 apart, the       the outline of a square       a regular n-gon with side 1
  leader at the front-left       turned 45 deg, the leader     (chord = spacing), the leader
  corner; even n only: an odd    at its front corner; robots   on its front point
  count is no rectangle          1 apart along the outline
                                 (n = 4, 8, ...: on every
                                 corner; else less than 1
                                 straight across a corner)

     L  1                               L                             L
     2  3                             1   2                        1     2
     4  5                           3       4                      3     4
                                      5   6                           5
                                        7       (n = 8)                       (n = 6)

Along the path: the `column` drives along the leader's path. Its slots are not rigid points of
the leader frame but the points of the leader's path that many metres behind it (a slot (x, y)
with x < 0: -x metres of path back, y to the left of the path there; trail.path_slot), so in a
corridor that turns the followers stay in the corridor instead of swinging into its walls. The
other shapes are rigid. A custom formation drives along the path with `along_path: true`.

Not symmetric about the leader's x axis: the rectangle (leader at a corner), the line and the
wedge with an even n, and a triangle whose last row has an odd count and no middle place
(n = 7, 9): one side has a robot more, the left one. At most MAX_ROBOTS robots.

Custom formations come from YAML files (FormationLibrary, format in the package README):

  formations:
    arrow:
      slots: [[0, 0], [-1, 0.5], [-1, -0.5], [-2, 0]]   # [x, y] in units of spacing
      topology: chain            # star (default) or chain
      parents: [-1, 0, 0, 1]     # optional explicit who-follows-whom (overrides topology)
      along_path: false          # optional: true = slots behind the leader follow its path

Pure numpy, no ROS.
"""
import math
from collections import namedtuple

import numpy as np

from mbot_common.strict_yaml import Reader

FORMATION_NAMES = ("line", "column", "triangle", "wedge", "rectangle", "diamond", "circle")
TOPOLOGIES = ("star", "chain")
MAX_ROBOTS = 60          # as many as a run may have (mbot_bringup fleet_world): 40 for the scale benchmark
MIN_SLOT_DISTANCE = 0.5  # custom slots must be at least this far apart [spacing]

ALONG_PATH = ("column",)  # the built-in formations whose slots follow the leader's path
_MIN_ROBOTS = {"line": 2, "column": 2, "triangle": 3, "wedge": 2, "rectangle": 4,
               "diamond": 4, "circle": 3}


class FormationError(ValueError):
    """A formation that cannot be made: unknown name, wrong robot count, bad spacing."""


#: name; offsets: numpy (n, 2) slots in the leader frame [m], row 0 = the leader at (0, 0);
#: parents: tuple, parents[i] = the slot that slot i follows (-1 for the leader); spacing [m];
#: along_path: True when the slots behind the leader lie on its path (module docstring).
Formation = namedtuple("Formation", "name offsets parents spacing along_path", defaults=(False,))


# ------------------------------------------------------------------ the shapes (spacing 1)

def _line(n):
    slots = [(0.0, 0.0)]
    for k in range(1, n):
        rank = (k + 1) // 2
        slots.append((0.0, rank if k % 2 == 1 else -rank))   # left, right, left, ...
    return slots


def _column(n):
    return [(-float(k), 0.0) for k in range(n)]


def _wedge(n):
    slots = [(0.0, 0.0)]
    for k in range(1, n):
        rank = (k + 1) // 2
        d = rank / math.sqrt(2.0)
        slots.append((-d, d if k % 2 == 1 else -d))
    return slots


def _centre_out(ys):
    """Order the y values of one row: the middle first, then left (+y) before right."""
    return sorted(ys, key=lambda y: (round(abs(y), 9), -y))


def _triangle(n):
    row_gap = math.sqrt(3.0) / 2.0   # rows of an equilateral lattice with side 1
    slots = []
    row = 0
    while len(slots) < n:
        places = _centre_out([j - row / 2.0 for j in range(row + 1)])   # row + 1 places, 1 apart
        count = min(row + 1, n - len(slots))
        if count % 2 == 0 and len(places) % 2 == 1:
            # an even count in a row with a middle place: leave the middle empty, so the row
            # stays symmetric
            places = places[1:]
        # (an odd count in a row without a middle place cannot be symmetric: left gets one more)
        slots.extend((-row * row_gap, y) for y in places[:count])
        row += 1
    return slots


def _rectangle(n):
    slots = []
    for row in range(n // 2):
        slots.extend([(-float(row), 0.0), (-float(row), -1.0)])
    return slots


def _diamond(n):
    side = n / 4.0                        # the outline is n long: robots 1 apart along it
    r2 = math.sqrt(2.0)

    def left_half(arc):                   # arc length from the front corner, down the left
        return (-arc / r2, (side - abs(arc - side)) / r2)

    slots = [(0.0, 0.0)]
    for k in range(1, (n + 1) // 2):
        x, y = left_half(float(k))
        slots.extend([(x, y), (x, -y)])
    if n % 2 == 0:
        slots.append((-2.0 * side / r2, 0.0))   # the back corner
    return slots


def _circle(n):
    radius = 0.5 / math.sin(math.pi / n)        # chord between neighbours = 1
    slots = [(0.0, 0.0)]
    for k in range(1, (n + 1) // 2):
        phi = 2.0 * math.pi * k / n
        x, y = -radius + radius * math.cos(phi), radius * math.sin(phi)
        slots.extend([(x, y), (x, -y)])
    if n % 2 == 0:
        slots.append((-2.0 * radius, 0.0))
    return slots


_SHAPES = {"line": _line, "column": _column, "triangle": _triangle, "wedge": _wedge,
           "rectangle": _rectangle, "diamond": _diamond, "circle": _circle}


# ------------------------------------------------------------------ parents

def star_parents(n):
    """Every follower follows the leader."""
    return tuple([-1] + [0] * (n - 1))


def chain_parents(offsets):
    """parents[i] = the nearest of the slots closer to the leader than slot i (ties: the lower
    index). The leader (0, 0) is always closer and each step gets closer, so following the
    parents from any slot ends at slot 0. Slots as far from the leader as slot i (the mirror
    image of a symmetric shape) are not candidates: mirror images keep mirror parents.
    """
    points = np.asarray(offsets, dtype=float)
    reach = [round(float(np.hypot(*p)), 9) for p in points]   # distance to the leader
    parents = [-1]
    for i in range(1, len(points)):
        ahead = [j for j in range(len(points)) if reach[j] < reach[i]]
        parents.append(min(ahead, key=lambda j: (round(float(np.hypot(*(points[i] - points[j]))), 9), j)))
    return tuple(parents)


def _parents_problem(parents, n):
    """Why `parents` is not a valid who-follows-whom for n slots, or None."""
    if len(parents) != n:
        return "expected %d entries (one per slot), got %d" % (n, len(parents))
    if parents[0] != -1:
        return "the leader (slot 0) follows nobody: parents[0] must be -1, got %r" % (parents[0],)
    for i in range(1, n):
        p = parents[i]
        if not 0 <= p < n or p == i:
            return ("parents[%d] = %r: expected the index of another slot, 0 to %d (only the "
                    "leader follows nobody)" % (i, p, n - 1))
    for i in range(1, n):
        seen = [i]
        while seen[-1] != 0:
            nxt = parents[seen[-1]]
            if nxt in seen:
                loop = seen[seen.index(nxt):] + [nxt]
                return ("slots %s form a cycle: every chain of parents must reach the leader "
                        "(slot 0)" % " -> ".join(str(s) for s in loop))
            seen.append(nxt)
    return None


# ------------------------------------------------------------------ built-in formations

def _check_spacing(spacing):
    if isinstance(spacing, bool) or not isinstance(spacing, (int, float)) \
            or not math.isfinite(spacing) or spacing <= 0:
        raise FormationError("spacing must be a finite number > 0 [m], got %r" % (spacing,))
    return float(spacing)


def _check_count(n):
    if isinstance(n, bool) or not isinstance(n, (int, np.integer)):
        raise FormationError("the number of robots must be an integer, got %r" % (n,))
    return int(n)


def _check_topology(topology):
    if topology not in TOPOLOGIES:
        raise FormationError("topology must be one of %s, got %r" % (", ".join(TOPOLOGIES), topology))
    return topology


def _unknown(name, library):
    known = list(FORMATION_NAMES) + (list(library.names()) if library is not None else [])
    return FormationError("unknown formation %r (known: %s)" % (name, ", ".join(known)))


def min_robots(name, library=None):
    """The fewest robots the formation `name` takes (a custom one takes exactly its slots)."""
    if name in _MIN_ROBOTS:
        return _MIN_ROBOTS[name]
    if library is not None and name in library:
        return library.slot_count(name)
    raise _unknown(name, library)


def make_formation(name, n, spacing, topology="star", library=None):
    """The Formation `name` for n robots with neighbours `spacing` [m] apart.

    topology: "star" or "chain". Names not built in are looked up in `library` (a
    FormationLibrary); a custom formation's own `parents` or `topology` wins over the argument.
    FormationError for an unknown name, a robot count the shape does not take, a bad spacing.
    """
    if name not in _SHAPES:
        if library is not None and name in library:
            return library.make(name, n, spacing, topology)
        raise _unknown(name, library)
    n = _check_count(n)
    spacing = _check_spacing(spacing)
    topology = _check_topology(topology)
    least = _MIN_ROBOTS[name]
    if n < least:
        raise FormationError("formation %r takes at least %d robots, got %d" % (name, least, n))
    if n > MAX_ROBOTS:
        raise FormationError("formation %r takes at most %d robots, got %d" % (name, MAX_ROBOTS, n))
    if name == "rectangle" and n % 2:
        raise FormationError("formation 'rectangle' takes an even number of robots (4, 6, 8, ...), "
                             "got %d" % n)
    offsets = np.array(_SHAPES[name](n), dtype=float) * spacing
    offsets[offsets == 0.0] = 0.0   # no -0.0 in printouts
    parents = star_parents(n) if topology == "star" else chain_parents(offsets)
    return Formation(name, offsets, parents, spacing, name in ALONG_PATH)


def world_slots(formation, leader_pose):
    """The rigid slots of `formation` in the world: (n, 2) [m], for a leader at leader_pose
    (x, y, theta). (Where a formation along the path wants its slots depends on the leader's
    path as well: trail.path_slot.)"""
    x, y, theta = leader_pose
    c, s = math.cos(theta), math.sin(theta)
    rotation = np.array([[c, -s], [s, c]])
    return formation.offsets @ rotation.T + np.array([x, y])


# ------------------------------------------------------------------ custom formations

_Custom = namedtuple("_Custom", "slots topology parents along_path path")


class FormationLibrary(object):
    """Custom formations read from YAML files, made like the built-ins."""

    def __init__(self):
        self._formations = {}    # name -> _Custom, in load order

    def names(self):
        """The custom formation names loaded so far, in load order."""
        return tuple(self._formations)

    def __contains__(self, name):
        return name in self._formations

    def slot_count(self, name):
        return len(self._formations[name].slots)

    def load_file(self, path):
        """Read the formations of the YAML file `path`; returns their names.

        Strict: an unknown key, a wrong type or a shape that cannot be a formation is a
        ConfigError "<file>: formations.<name>.<key>: <problem>". Nothing of a bad file is kept.
        """
        reader = Reader.from_file(path)
        formations = reader.child("formations")
        if not formations.keys():
            formations.fail(None, "expected at least one formation")
        loaded = {}
        for name in formations.keys():
            if not isinstance(name, str) or not name:
                formations.fail(name, "a formation name must be a non-empty string")
            if name in _SHAPES:
                formations.fail(name, "%r is a built-in formation: choose another name" % name)
            if name in self._formations:
                formations.fail(name, "formation %r is already loaded from %s"
                                % (name, self._formations[name].path))
            loaded[name] = self._read_formation(formations.child(name), path)
        reader.finish()
        self._formations.update(loaded)
        return list(loaded)

    @staticmethod
    def _read_formation(r, path):
        raw = r.required("slots", list, what="a list of [x, y] slots")
        if not 2 <= len(raw) <= MAX_ROBOTS:
            r.fail("slots", "expected 2 to %d slots, got %d" % (MAX_ROBOTS, len(raw)))
        slots = []
        for i, item in enumerate(raw):
            key = "slots[%d]" % i
            if not isinstance(item, list) or len(item) != 2 or any(
                    isinstance(v, bool) or not isinstance(v, (int, float)) or not math.isfinite(v)
                    for v in item):
                r.fail(key, "expected [x, y] (two numbers, units of spacing), got %r" % (item,))
            slots.append((float(item[0]), float(item[1])))
        if slots[0] != (0.0, 0.0):
            r.fail("slots[0]", "the first slot is the leader and must be [0, 0], got %r" % (raw[0],))
        for i, (x, y) in enumerate(slots):
            if x > 0:
                r.fail("slots[%d]" % i, "[%g, %g] is ahead of the leader (x > 0): the leader drives "
                       "in front" % (x, y))
        for i in range(len(slots)):
            for j in range(i):
                d = math.hypot(slots[i][0] - slots[j][0], slots[i][1] - slots[j][1])
                if d < MIN_SLOT_DISTANCE:
                    r.fail("slots[%d]" % i, "only %.3g from slots[%d]: slots must be at least %g "
                           "spacing apart" % (d, j, MIN_SLOT_DISTANCE))
        topology = r.optional("topology", str, None, what="star or chain",
                              check=lambda v: v in TOPOLOGIES)
        parents = r.optional("parents", list, None, what="a list of slot indices")
        if parents is not None:
            if any(isinstance(p, bool) or not isinstance(p, int) for p in parents):
                r.fail("parents", "expected a list of slot indices (integers), got %r" % (parents,))
            problem = _parents_problem(parents, len(slots))
            if problem:
                r.fail("parents", problem)
            parents = tuple(parents)
        along_path = r.optional("along_path", bool, False)
        return _Custom(np.array(slots), topology, parents, along_path, path)

    def make(self, name, n, spacing, topology=None):
        """The Formation `name` for n robots `spacing` [m] apart (built-in names work too).

        A custom formation takes exactly as many robots as it has slots. Its parents: the
        file's `parents`, else the file's `topology`, else `topology` (None = star).
        """
        if name not in self._formations:
            if name in _SHAPES:
                return make_formation(name, n, spacing, topology or "star")
            raise _unknown(name, self)
        custom = self._formations[name]
        n = _check_count(n)
        spacing = _check_spacing(spacing)
        if topology is not None:
            _check_topology(topology)
        if n != len(custom.slots):
            raise FormationError("formation %r (%s) takes exactly %d robots, got %d"
                                 % (name, custom.path, len(custom.slots), n))
        offsets = custom.slots * spacing
        if custom.parents is not None:
            parents = custom.parents
        elif (custom.topology or topology or "star") == "chain":
            parents = chain_parents(offsets)
        else:
            parents = star_parents(n)
        return Formation(name, offsets, parents, spacing, custom.along_path)
