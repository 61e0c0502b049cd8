"""Occupancy maps in map_server format: a yaml (image, resolution, origin, occupied_thresh,
free_thresh, negate, mode) and a PGM image (the C++ twin is map_io.h).

The values are the ones map_server publishes in nav_msgs/OccupancyGrid, computed the way its
image_loader does, so Python tools (plots, tests, goal samplers) see the map the robots see:

    grey value v in 0..255 (scaled from the PGM's maxval), v = 255 - v if negate,
    p = (255 - v) / 255                    (black = 1 = occupied, white = 0 = free)
    trinary: p > occupied_thresh -> 100, p < free_thresh -> 0, else -1 (unknown)
    scale:   the same, but between the thresholds 1 + 98 * (p - free) / (occupied - free)
    raw:     v itself (as map_server: stored in an int8, so 200 reads as -56)

The occupancy array's row 0 is the bottom row of the image (the map frame's y points up), as
in nav_msgs/OccupancyGrid: occupancy[j, i] is the cell in column i (x) and row j (y).
"""
import math
import re

import numpy as np

from mbot_common.strict_yaml import ConfigError, Reader, load_yaml

MODES = ("trinary", "scale", "raw")

OCCUPIED = 100
FREE = 0
UNKNOWN = -1


class MapData(object):
    """An occupancy map and the yaml fields it was made from."""

    def __init__(self, path, image_path, resolution, origin, occupied_thresh, free_thresh, negate, mode,
                 occupancy):
        self.path = path                        # the map yaml
        self.image_path = image_path            # the PGM (relative paths are relative to the yaml)
        self.resolution = resolution            # [m/cell]
        self.origin = tuple(origin)             # (x [m], y [m], yaw [rad]) of the lower-left corner of cell (0, 0)
        self.occupied_thresh = occupied_thresh  # occupancy probability above which a cell is occupied
        self.free_thresh = free_thresh          # occupancy probability below which a cell is free
        self.negate = negate                    # True: white is occupied, black free
        self.mode = mode                        # trinary, scale or raw
        self.occupancy = occupancy              # int8 [height, width], row 0 at the bottom
        self.height, self.width = occupancy.shape  # [cells]

    def world_to_cell(self, x, y):
        """The cell (i column, j row) that holds the map-frame point (x, y) [m]. It may lie outside
        the map: check with contains(i, j)."""
        ox, oy, yaw = self.origin
        dx, dy = x - ox, y - oy
        c, s = math.cos(yaw), math.sin(yaw)
        # the point in the grid's own frame (rotated by the origin's yaw)
        gx, gy = c * dx + s * dy, -s * dx + c * dy
        return int(math.floor(gx / self.resolution)), int(math.floor(gy / self.resolution))

    def cell_to_world(self, i, j):
        """The map-frame centre (x, y) [m] of cell (i column, j row)."""
        ox, oy, yaw = self.origin
        gx, gy = (i + 0.5) * self.resolution, (j + 0.5) * self.resolution
        c, s = math.cos(yaw), math.sin(yaw)
        return ox + c * gx - s * gy, oy + s * gx + c * gy

    def contains(self, i, j):
        """True if cell (i, j) is inside the map."""
        return 0 <= i < self.width and 0 <= j < self.height


def _directory_of(path):
    slash = path.rfind("/")
    return "." if slash < 0 else path[:slash]


class _PgmHeader(object):
    """The whitespace- and comment-separated header tokens of a PGM."""

    def __init__(self, data, path):
        self.data = data
        self.path = path
        self.pos = 0

    def token(self):
        data = self.data
        while self.pos < len(data):
            if data[self.pos:self.pos + 1] == b"#":
                end = data.find(b"\n", self.pos)
                self.pos = len(data) if end < 0 else end
            elif data[self.pos:self.pos + 1].isspace():
                self.pos += 1
            else:
                break
        start = self.pos
        while self.pos < len(data) and not data[self.pos:self.pos + 1].isspace() \
                and data[self.pos:self.pos + 1] != b"#":
            self.pos += 1
        return data[start:self.pos].decode("latin-1")

    def positive(self, what, max_value):
        t = self.token()
        if not t or not (t.isascii() and t.isdigit()) or len(t) > 9:
            raise ConfigError('%s: bad PGM header: expected %s (a positive integer), got "%s"' % (self.path, what, t))
        value = int(t)
        if value == 0 or value > max_value:
            raise ConfigError("%s: bad PGM header: %s must be in [1, %d], got %s" % (self.path, what, max_value, t))
        return value


def read_pgm(path, yaml_path=None):
    """A P5 (binary) or P2 (text) PGM as a uint8 array [height, width], top row first, grey
    values scaled to 0..255 for a maxval other than 255 (v * 255 // maxval, as map_server's
    SDL_image). ConfigError for a missing or broken file."""
    try:
        with open(path, "rb") as f:
            data = f.read()
    except (IOError, OSError):
        if yaml_path is not None:
            raise ConfigError('%s: image: cannot read "%s" (missing or unreadable)' % (yaml_path, path))
        raise ConfigError("%s: cannot read the file (missing or unreadable)" % path)
    header = _PgmHeader(data, path)
    magic = header.token()
    if magic not in ("P5", "P2"):
        raise ConfigError('%s: bad PGM header: expected magic P5 (binary) or P2 (text), got "%s"' % (path, magic[:8]))
    width = header.positive("width", 1 << 16)
    height = header.positive("height", 1 << 16)
    maxval = header.positive("maxval", 65535)
    count = width * height
    if magic == "P5":
        bytes_per_pixel = 1 if maxval < 256 else 2
        start = header.pos + 1  # one whitespace byte after maxval, then the pixels
        available = max(0, len(data) - start)
        if available < count * bytes_per_pixel:
            raise ConfigError("%s: truncated PGM: expected %d bytes of pixels for %dx%d, got %d"
                              % (path, count * bytes_per_pixel, width, height, available))
        dtype = np.uint8 if bytes_per_pixel == 1 else np.dtype(">u2")  # 16-bit PGM is big-endian
        values = np.frombuffer(data, dtype=dtype, count=count, offset=start).astype(np.int64)
    else:
        text = re.sub(rb"#[^\n]*", b" ", data[header.pos:])
        tokens = text.split()[:count]
        if len(tokens) < count:
            raise ConfigError("%s: truncated PGM: expected %d pixel values, got %d" % (path, count, len(tokens)))
        for k, t in enumerate(tokens):
            if not t.isdigit() or len(t) > 6:
                raise ConfigError('%s: bad PGM pixel %d: expected an integer, got "%s"'
                                  % (path, k, t.decode("latin-1")))
        values = np.array([int(t) for t in tokens], dtype=np.int64)
    values = np.minimum(values, maxval)
    if maxval != 255:
        values = values * 255 // maxval
    return values.astype(np.uint8).reshape(height, width)


def occupancy_from_image(image, occupied_thresh, free_thresh, negate, mode):
    """The int8 occupancy [height, width] (row 0 at the bottom) of a grey image [height, width]
    (top row first), exactly as map_server's image_loader computes it."""
    if mode not in MODES:
        raise ValueError("mode: expected one of %s, got %r" % (", ".join(MODES), mode))
    color = image.astype(np.float64)
    if negate:
        color = 255.0 - color
    if mode == "raw":
        values = color.astype(np.uint8).view(np.int8)  # map_server stores an unsigned char in int8
    else:
        occ = (255.0 - color) / 255.0
        values = np.full(image.shape, UNKNOWN, dtype=np.int8)
        if mode == "scale":
            between = (occ >= free_thresh) & (occ <= occupied_thresh)
            ratio = (occ - free_thresh) / max(occupied_thresh - free_thresh, 1e-300)
            # map_server truncates 1 + 98 * ratio into an unsigned char
            values[between] = (1.0 + 98.0 * ratio[between]).astype(np.uint8).astype(np.int8)
        values[occ > occupied_thresh] = OCCUPIED
        values[occ < free_thresh] = FREE
    return np.ascontiguousarray(values[::-1])  # image row 0 is the top, map row 0 the bottom


def load_map(yaml_path):
    """Read a map_server yaml strictly (every key, types and ranges) and its PGM image.
    ConfigError names the file, the key and the problem."""
    r = Reader(load_yaml(yaml_path), yaml_path)
    r.check_keys(["image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate", "mode"],
                 required=["image", "resolution", "origin", "occupied_thresh", "free_thresh", "negate"])
    resolution = r.required("resolution", float, what="a number > 0 [m/cell]", check=lambda v: v > 0.0)
    origin = r.number_list("origin", 3, what="a list of 3 numbers [x, y, yaw]")
    in_unit = "a number in [0, 1]"
    occupied_thresh = r.required("occupied_thresh", float, what=in_unit, check=lambda v: 0.0 <= v <= 1.0)
    free_thresh = r.required("free_thresh", float, what=in_unit, check=lambda v: 0.0 <= v <= 1.0)
    if free_thresh > occupied_thresh:
        r.expected("free_thresh", "a number <= occupied_thresh", r.data["free_thresh"])
    # map_server reads negate as an integer (0 or 1); true/false are accepted as well.
    negate = r.required("negate", object)
    if not (isinstance(negate, bool) or (isinstance(negate, int) and negate in (0, 1))):
        r.expected("negate", "0 or 1", negate)
    negate = bool(negate)
    mode = r.optional("mode", str, "trinary", what="trinary, scale or raw", check=lambda v: v in MODES)
    image = r.required("image", str, what="an image file name", check=lambda v: v != "")
    image_path = image if image.startswith("/") else _directory_of(yaml_path) + "/" + image
    pixels = read_pgm(image_path, yaml_path)
    occupancy = occupancy_from_image(pixels, occupied_thresh, free_thresh, negate, mode)
    return MapData(yaml_path, image_path, resolution, origin, occupied_thresh, free_thresh, negate, mode, occupancy)
