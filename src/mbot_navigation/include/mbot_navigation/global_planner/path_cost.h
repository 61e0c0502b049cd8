/**
 * @file path_cost.h
 * @brief The path cost of the planner benchmark (bench/inputs/README.md): the sum of the map's
 *        costs over the cells a path's polyline passes through. Header-only, no ROS types; used by
 *        plan_bench and test_astar.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <cstdlib>
#include <limits>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"

namespace mbot_navigation
{
/**
 * Sum of the map's costs over the cells that the polyline through `path` passes through, each
 * cell once (bench/inputs/README.md). Grid traversal in continuous cell coordinates (Amanatides & Woo);
 * a segment through a cell corner steps diagonally. `mark` (one entry per cell) and `stamp` tell
 * the cells already counted.
 */
inline double pathCellCost(const Costmap2D& map, const std::vector<Pose2D>& path, std::vector<uint32_t>& mark,
                           uint32_t stamp)
{
  const double res = map.resolution();
  const unsigned W = map.sizeX();
  double sum = 0.0;
  auto count = [&](long x, long y) {
    if (x < 0 || y < 0 || x >= static_cast<long>(W) || y >= static_cast<long>(map.sizeY())) return;
    const size_t i = static_cast<size_t>(y) * W + static_cast<size_t>(x);
    if (mark[i] == stamp) return;
    mark[i] = stamp;
    sum += map.data()[i];
  };
  for (size_t k = 0; k < path.size(); ++k)
  {
    const double x1 = (path[k].x - map.originX()) / res, y1 = (path[k].y - map.originY()) / res;
    if (k == 0)
    {
      count(static_cast<long>(std::floor(x1)), static_cast<long>(std::floor(y1)));
      continue;
    }
    const double x0 = (path[k - 1].x - map.originX()) / res, y0 = (path[k - 1].y - map.originY()) / res;
    long x = static_cast<long>(std::floor(x0)), y = static_cast<long>(std::floor(y0));
    const long ex = static_cast<long>(std::floor(x1)), ey = static_cast<long>(std::floor(y1));
    const double dx = x1 - x0, dy = y1 - y0;
    const int sx = dx > 0 ? 1 : -1, sy = dy > 0 ? 1 : -1;
    // t (0..1 along the segment) at the next vertical / horizontal cell boundary, and per cell.
    const double inf = std::numeric_limits<double>::infinity();
    const double ddx = dx != 0.0 ? 1.0 / std::fabs(dx) : inf, ddy = dy != 0.0 ? 1.0 / std::fabs(dy) : inf;
    double tx = dx != 0.0 ? ((sx > 0 ? x + 1 - x0 : x0 - x) * ddx) : inf;
    double ty = dy != 0.0 ? ((sy > 0 ? y + 1 - y0 : y0 - y) * ddy) : inf;
    for (long steps = std::labs(ex - x) + std::labs(ey - y); steps > 0 && (x != ex || y != ey); --steps)
    {
      if (std::fabs(tx - ty) < 1e-9)  // through a corner: the diagonal cell
      {
        x += sx;
        y += sy;
        tx += ddx;
        ty += ddy;
        --steps;
      }
      else if (tx < ty)
      {
        x += sx;
        tx += ddx;
      }
      else
      {
        y += sy;
        ty += ddy;
      }
      count(x, y);
    }
  }
  return sum;
}

/// @brief pathCellCost() with its own marks (allocated per call).
inline double pathCellCost(const Costmap2D& map, const std::vector<Pose2D>& path)
{
  std::vector<uint32_t> mark(static_cast<size_t>(map.sizeX()) * map.sizeY(), 0);
  return pathCellCost(map, path, mark, 1);
}

}  // namespace mbot_navigation
