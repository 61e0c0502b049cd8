"""Shortest paths and free space on an occupancy grid, with numpy/scipy and without ROS: what the
navigation tests and the trial benchmark measure the nav node against.

A grid here is a ``Grid`` (row-major occupancy values as in nav_msgs/OccupancyGrid: 100 occupied,
0 free, -1 unknown; row 0 at ``origin_y``). The robot's centre may go where the clearance (the
distance from the cell's centre to the nearest occupied cell's centre) is at least the robot's
radius: the configuration space that the nav node's costmap also forbids (cost >= INSCRIBED).
"""
from collections import namedtuple

import numpy as np
from scipy import ndimage
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import dijkstra

#: occupancy: 2-D int array [rows = y, cols = x]; resolution [m/cell]; origin [m] of cell (0, 0)'s corner
Grid = namedtuple("Grid", "occupancy resolution origin_x origin_y")


def grid_from_msg(msg):
    """A Grid from a nav_msgs/OccupancyGrid."""
    occupancy = np.asarray(msg.data, dtype=np.int16).reshape(msg.info.height, msg.info.width)
    return Grid(occupancy, float(msg.info.resolution), msg.info.origin.position.x, msg.info.origin.position.y)


def occupied_mask(grid, occupied_threshold=65, unknown_is_occupied=True):
    """True where a cell is an obstacle (occupancy >= threshold, or unknown when so chosen)."""
    occupied = grid.occupancy >= occupied_threshold
    if unknown_is_occupied:
        occupied |= grid.occupancy < 0
    return occupied


def clearance(grid):
    """Distance [m] from every cell's centre to the nearest occupied cell's centre."""
    return ndimage.distance_transform_edt(~occupied_mask(grid)) * grid.resolution


def world_to_cell(grid, x, y):
    """(row, col) of the cell holding (x, y) [m], or None off the grid."""
    col = int(np.floor((x - grid.origin_x) / grid.resolution))
    row = int(np.floor((y - grid.origin_y) / grid.resolution))
    rows, cols = grid.occupancy.shape
    if 0 <= row < rows and 0 <= col < cols:
        return row, col
    return None


def cell_to_world(grid, row, col):
    """Centre (x, y) [m] of a cell."""
    return grid.origin_x + (col + 0.5) * grid.resolution, grid.origin_y + (row + 0.5) * grid.resolution


def region_of(free, cell):
    """Boolean mask of the free cells 8-connected to ``cell`` (empty when ``cell`` is not free)."""
    labels, _ = ndimage.label(free, structure=np.ones((3, 3), dtype=bool))
    label = labels[cell]
    return labels == label if label > 0 else np.zeros_like(free)


def path_lengths_from(free, resolution, start_cell):
    """Length [m] of the shortest 8-connected path through ``free`` cells from ``start_cell`` to
    every cell (inf where unreachable): the A* optimum on that grid. A diagonal step needs both
    cells beside it free, so that a path never cuts an obstacle's corner."""
    rows, cols = free.shape
    index = -np.ones(free.shape, dtype=np.int64)
    index[free] = np.arange(int(free.sum()))
    src, dst, weight = [], [], []
    # Steps right, up, and the two diagonals up: each edge once; the graph is undirected.
    for dr, dc, length in ((0, 1, 1.0), (1, 0, 1.0), (1, 1, np.sqrt(2.0)), (1, -1, np.sqrt(2.0))):
        r0, r1 = max(0, -dr), rows - max(0, dr)
        c0, c1 = max(0, -dc), cols - max(0, dc)
        a = free[r0:r1, c0:c1]
        b = free[r0 + dr:r1 + dr, c0 + dc:c1 + dc]
        ok = a & b
        if dr and dc:  # no corner cutting
            ok &= free[r0 + dr:r1 + dr, c0:c1] & free[r0:r1, c0 + dc:c1 + dc]
        src.append(index[r0:r1, c0:c1][ok])
        dst.append(index[r0 + dr:r1 + dr, c0 + dc:c1 + dc][ok])
        weight.append(np.full(int(ok.sum()), length * resolution))
    n = int(free.sum())
    graph = coo_matrix((np.concatenate(weight), (np.concatenate(src), np.concatenate(dst))), shape=(n, n)).tocsr()
    lengths = np.full(free.shape, np.inf)
    if not free[start_cell]:
        return lengths
    lengths[free] = dijkstra(graph, directed=False, indices=int(index[start_cell]))
    return lengths


def shortest_path_length(grid, robot_radius, start, goal):
    """The A* optimum [m] from ``start`` to ``goal`` (x, y) [m] for a robot of ``robot_radius`` [m]
    on ``grid`` (inf when unreachable). Start and goal are snapped to their cells' centres."""
    free = clearance(grid) >= robot_radius
    s, g = world_to_cell(grid, *start), world_to_cell(grid, *goal)
    if s is None or g is None:
        return float("inf")
    return float(path_lengths_from(free, grid.resolution, s)[g])


def polyline_length(points):
    """Length [m] of a list of (x, y) points."""
    p = np.asarray(points, dtype=float).reshape(-1, 2)
    return float(np.hypot(*np.diff(p, axis=0).T).sum()) if len(p) > 1 else 0.0
