// The grid MAPF plans on: 4-connected moves plus wait, unit cost per step (the MovingAI MAPF
// benchmark's convention). No ROS types: the live planner builds one from an OccupancyGrid's data.
#pragma once

#include <cstdint>
#include <string>
#include <vector>

namespace mbot_coordination
{
// A cell is a vertex id y * width + x (x = column, y = row from the top left, as in MovingAI).
class Grid
{
public:
  Grid() = default;
  // free[y * width + x] true when the cell is passable; throws std::invalid_argument on a size mismatch.
  Grid(int width, int height, std::vector<uint8_t> free);

  // The live planner's grid: a coarser grid over an occupancy grid (nav_msgs/OccupancyGrid's data,
  // row 0 at the origin). A coarse cell of `cell_size` m is blocked when any fine cell within
  // `robot_radius` of its square is occupied (>= occupied_threshold) or unknown (-1), so a robot
  // centred anywhere in a free cell touches nothing. Row 0 of the result is the occupancy grid's row 0.
  static Grid fromOccupancy(const std::vector<int8_t>& data, int width, int height, double resolution, double cell_size,
                            double robot_radius, int occupied_threshold = 50);

  int width() const { return width_; }
  int height() const { return height_; }
  int size() const { return width_ * height_; }
  int id(int x, int y) const { return y * width_ + x; }
  int x(int v) const { return v % width_; }
  int y(int v) const { return v / width_; }
  bool inside(int x, int y) const { return x >= 0 && y >= 0 && x < width_ && y < height_; }
  bool isFree(int v) const { return v >= 0 && v < size() && free_[v] != 0; }
  bool isFree(int x, int y) const { return inside(x, y) && free_[id(x, y)] != 0; }
  int freeCount() const;

  // Free 4-neighbours of v (up to 4), in a fixed order.
  const std::vector<int>& neighbours(int v) const { return adjacency_[v]; }
  bool adjacent(int a, int b) const;

  // Steps from every cell to `target` (breadth-first; -1 when unreachable or blocked).
  std::vector<int> distancesTo(int target) const;

private:
  int width_ = 0;
  int height_ = 0;
  std::vector<uint8_t> free_;
  std::vector<std::vector<int>> adjacency_;
};

}  // namespace mbot_coordination
