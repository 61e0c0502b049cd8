#include "mbot_coordination/grid.h"

#include <algorithm>
#include <cmath>
#include <deque>
#include <stdexcept>

namespace mbot_coordination
{
Grid::Grid(int width, int height, std::vector<uint8_t> free) : width_(width), height_(height), free_(std::move(free))
{
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("grid size must be positive, got " + std::to_string(width) + " x " +
                                std::to_string(height));
  if (free_.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
    throw std::invalid_argument("grid of " + std::to_string(width) + " x " + std::to_string(height) + " given " +
                                std::to_string(free_.size()) + " cells");
  adjacency_.resize(free_.size());
  static const int dx[4] = {1, -1, 0, 0};
  static const int dy[4] = {0, 0, 1, -1};
  for (int y = 0; y < height_; ++y)
    for (int x = 0; x < width_; ++x)
    {
      if (!free_[id(x, y)]) continue;
      for (int k = 0; k < 4; ++k)
        if (isFree(x + dx[k], y + dy[k])) adjacency_[id(x, y)].push_back(id(x + dx[k], y + dy[k]));
    }
}

Grid Grid::fromOccupancy(const std::vector<int8_t>& data, int width, int height, double resolution, double cell_size,
                         double robot_radius, int occupied_threshold)
{
  if (width <= 0 || height <= 0 || data.size() != static_cast<size_t>(width) * static_cast<size_t>(height))
    throw std::invalid_argument("occupancy grid: " + std::to_string(data.size()) + " cells for " +
                                std::to_string(width) + " x " + std::to_string(height));
  if (!(resolution > 0.0) || !(cell_size >= resolution) || !(robot_radius >= 0.0))
    throw std::invalid_argument("occupancy grid: need resolution > 0, cell_size >= resolution, robot_radius >= 0");
  const int cw = static_cast<int>(std::floor(width * resolution / cell_size));
  const int ch = static_cast<int>(std::floor(height * resolution / cell_size));
  if (cw <= 0 || ch <= 0) throw std::invalid_argument("occupancy grid: smaller than one coarse cell");
  const int pad = static_cast<int>(std::ceil(robot_radius / resolution));
  std::vector<uint8_t> free(static_cast<size_t>(cw) * ch, 1);
  for (int cy = 0; cy < ch; ++cy)
    for (int cx = 0; cx < cw; ++cx)
    {
      const int x0 = static_cast<int>(std::floor(cx * cell_size / resolution)) - pad;
      const int x1 = static_cast<int>(std::ceil((cx + 1) * cell_size / resolution)) - 1 + pad;
      const int y0 = static_cast<int>(std::floor(cy * cell_size / resolution)) - pad;
      const int y1 = static_cast<int>(std::ceil((cy + 1) * cell_size / resolution)) - 1 + pad;
      bool ok = true;
      for (int y = y0; y <= y1 && ok; ++y)
        for (int x = x0; x <= x1 && ok; ++x)
        {
          if (x < 0 || y < 0 || x >= width || y >= height)
          {
            ok = false;  // off the map: unknown
            break;
          }
          const int8_t c = data[static_cast<size_t>(y) * width + x];
          if (c < 0 || c >= occupied_threshold) ok = false;
        }
      free[static_cast<size_t>(cy) * cw + cx] = ok ? 1 : 0;
    }
  return Grid(cw, ch, std::move(free));
}

int Grid::freeCount() const { return static_cast<int>(std::count(free_.begin(), free_.end(), 1)); }

bool Grid::adjacent(int a, int b) const
{
  if (!isFree(a)) return false;
  const auto& n = adjacency_[a];
  return std::find(n.begin(), n.end(), b) != n.end();
}

std::vector<int> Grid::distancesTo(int target) const
{
  std::vector<int> dist(free_.size(), -1);
  if (!isFree(target)) return dist;
  std::deque<int> queue{target};
  dist[target] = 0;
  while (!queue.empty())
  {
    const int v = queue.front();
    queue.pop_front();
    for (int u : adjacency_[v])
      if (dist[u] < 0)
      {
        dist[u] = dist[v] + 1;
        queue.push_back(u);
      }
  }
  return dist;
}

}  // namespace mbot_coordination
