"""Where in the map a robot fits: to tell whether a formation slot falls into a wall.

The occupancy grid is the nav_msgs/OccupancyGrid layout: an int8 array [height, width], row 0 =
the bottom row of the map (y grows with the row), values 100 occupied, 0 free, -1 unknown (the
0..100 values in between are occupied from OCCUPIED = 50 up). A cell is blocked when its centre
is within `clearance` [m] of the centre of an occupied cell: give the robot's radius plus a
margin. Unknown cells are not free either (nobody should be sent where the map knows nothing),
but they do not block their neighbours. The map's origin has no rotation (map_server maps here
have yaw 0). Pure numpy/scipy, no ROS.
"""
import math

import numpy as np
from scipy.ndimage import distance_transform_edt

OCCUPIED = 50      # grid values >= this are obstacles (nav_msgs/OccupancyGrid: 0..100)


def _is_number(value):
    return (isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
            and math.isfinite(value))


class FreeSpace(object):
    """Free-space test on an occupancy grid grown by `clearance`."""

    def __init__(self, occupancy, resolution, origin_xy, clearance):
        grid = np.asarray(occupancy)
        if grid.ndim != 2 or grid.size == 0:
            raise ValueError("FreeSpace: occupancy must be a non-empty 2-D array [height, width], "
                             "got shape %s" % (grid.shape,))
        if not np.issubdtype(grid.dtype, np.integer):
            raise ValueError("FreeSpace: occupancy must hold integers (100/0/-1), got %s" % grid.dtype)
        if not _is_number(resolution) or resolution <= 0:
            raise ValueError("FreeSpace: resolution must be a finite number > 0 [m/cell], got %r"
                             % (resolution,))
        if not _is_number(clearance) or clearance < 0:
            raise ValueError("FreeSpace: clearance must be a finite number >= 0 [m], got %r"
                             % (clearance,))
        if len(origin_xy) != 2 or not all(math.isfinite(v) for v in origin_xy):
            raise ValueError("FreeSpace: origin_xy must be two finite numbers (x, y) [m], got %r"
                             % (origin_xy,))
        self.resolution = float(resolution)             # [m/cell]
        self.origin_xy = (float(origin_xy[0]), float(origin_xy[1]))  # map corner of cell (0, 0) [m]
        self.clearance = float(clearance)               # [m]
        self.height, self.width = grid.shape

        occupied = grid >= OCCUPIED
        if occupied.any():
            # distance [cells] from every cell centre to the nearest occupied cell centre
            distance = distance_transform_edt(~occupied)
            # compared in cells, with a little slack: 3 cells of 0.1 m are 0.30000000000000004 m
            blocked = distance <= self.clearance / self.resolution + 1e-9
        else:
            blocked = np.zeros(grid.shape, dtype=bool)
        self.free = ~blocked & (grid >= 0)    # [row, column]: True where a robot may be

    @classmethod
    def from_grid_msg(cls, msg, clearance):
        """The free space of a nav_msgs/OccupancyGrid message (anything with its fields)."""
        grid = np.array(msg.data, dtype=np.int8).reshape(msg.info.height, msg.info.width)
        origin = (msg.info.origin.position.x, msg.info.origin.position.y)
        return cls(grid, msg.info.resolution, origin, clearance)

    def cell(self, x, y):
        """(row, column) of the cell holding world point (x, y), or None outside the map."""
        col = int(math.floor((x - self.origin_xy[0]) / self.resolution))
        row = int(math.floor((y - self.origin_xy[1]) / self.resolution))
        if 0 <= row < self.height and 0 <= col < self.width:
            return row, col
        return None

    def is_free(self, x, y):
        """True if a robot centred at (x, y) [m] keeps `clearance` to every obstacle."""
        if not (math.isfinite(x) and math.isfinite(y)):
            return False
        rc = self.cell(x, y)
        return rc is not None and bool(self.free[rc])

    def segment_free(self, x0, y0, x1, y1):
        """True if every point of the straight segment (x0, y0) -> (x1, y1) is free.

        Checked at both ends and every quarter cell in between.
        """
        length = math.hypot(x1 - x0, y1 - y0)
        if not math.isfinite(length):
            return False
        samples = int(math.ceil(length / (0.25 * self.resolution)))
        for k in range(samples + 1):
            f = k / samples if samples else 0.0
            if not self.is_free(x0 + f * (x1 - x0), y0 + f * (y1 - y0)):
                return False
        return True
