/**
 * @file costmap_2d.h
 * @brief A 2D grid of navigation costs, free of ROS types.
 *
 * Cell (mx, my) is stored at index my * size_x + mx; cell (0, 0) is the one whose lower-left
 * corner is the origin. Costs follow costmap_2d's cost_values.h.
 */
#pragma once

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <mbot_common/geometry.h>

namespace mbot_navigation
{
/// Cost values, as in costmap_2d/cost_values.h.
namespace cost
{
constexpr uint8_t FREE = 0;
constexpr uint8_t INSCRIBED = 253;  ///< robot centre here means a collision
constexpr uint8_t LETHAL = 254;     ///< an obstacle
constexpr uint8_t NO_INFORMATION = 255;
}  // namespace cost

/// @brief A planar pose {x [m], y [m], theta [rad]}: mbot_common's, shared by every package.
using mbot_common::Pose2D;

/// @brief A rectangular grid of costs with a resolution [m/cell] and an origin [m] in its frame.
class Costmap2D
{
public:
  Costmap2D() = default;
  Costmap2D(unsigned size_x, unsigned size_y, double resolution, double origin_x, double origin_y,
            uint8_t default_cost = cost::FREE)
      : size_x_(size_x),
        size_y_(size_y),
        resolution_(resolution),
        origin_x_(origin_x),
        origin_y_(origin_y),
        costs_(static_cast<size_t>(size_x) * size_y, default_cost)
  {}

  unsigned sizeX() const { return size_x_; }
  unsigned sizeY() const { return size_y_; }
  double resolution() const { return resolution_; }  ///< [m/cell]
  double originX() const { return origin_x_; }       ///< [m]
  double originY() const { return origin_y_; }       ///< [m]

  size_t index(unsigned mx, unsigned my) const { return static_cast<size_t>(my) * size_x_ + mx; }
  uint8_t cost(unsigned mx, unsigned my) const { return costs_[index(mx, my)]; }
  void setCost(unsigned mx, unsigned my, uint8_t c) { costs_[index(mx, my)] = c; }
  const uint8_t* data() const { return costs_.data(); }
  uint8_t* data() { return costs_.data(); }

  /// @brief World [m] to cell; false when outside the grid.
  bool worldToMap(double wx, double wy, unsigned& mx, unsigned& my) const
  {
    if (wx < origin_x_ || wy < origin_y_) return false;
    const double fx = (wx - origin_x_) / resolution_;
    const double fy = (wy - origin_y_) / resolution_;
    if (fx >= size_x_ || fy >= size_y_) return false;
    mx = static_cast<unsigned>(fx);
    my = static_cast<unsigned>(fy);
    return true;
  }

  /// @brief Centre of a cell, in world coordinates [m].
  void mapToWorld(unsigned mx, unsigned my, double& wx, double& wy) const
  {
    wx = origin_x_ + (mx + 0.5) * resolution_;
    wy = origin_y_ + (my + 0.5) * resolution_;
  }

  /// @brief Move the origin (rolling window); costs are not shifted here.
  void setOrigin(double ox, double oy)
  {
    origin_x_ = ox;
    origin_y_ = oy;
  }

  void fill(uint8_t c) { std::fill(costs_.begin(), costs_.end(), c); }

  /// @brief True when (mx, my) is a cell of the grid (signed, for coordinates computed by offsets).
  bool inBounds(int mx, int my) const
  {
    return mx >= 0 && my >= 0 && mx < static_cast<int>(size_x_) && my < static_cast<int>(size_y_);
  }

  /// @brief Set every cell of the window [x0, xn) x [y0, yn) to `c` (the window is clipped).
  void resetWindow(int x0, int y0, int xn, int yn, uint8_t c)
  {
    x0 = std::max(x0, 0);
    y0 = std::max(y0, 0);
    xn = std::min(xn, static_cast<int>(size_x_));
    yn = std::min(yn, static_cast<int>(size_y_));
    for (int y = y0; y < yn; ++y)
      std::fill(costs_.begin() + index(x0, y), costs_.begin() + index(x0, y) + std::max(xn - x0, 0), c);
  }

  /**
   * @brief Move the origin to (new_origin_x, new_origin_y) [m] snapped to whole cells, keeping the
   *        costs of the cells that stay inside the grid (rolling window, as costmap_2d's
   *        Costmap2D::updateOrigin); cells that enter the grid get `fill_cost`.
   */
  void updateOrigin(double new_origin_x, double new_origin_y, uint8_t fill_cost)
  {
    // Whole-cell shift, so that kept cells keep their exact world position.
    // (The 1e-6 cell guards against 0.15 / 0.05 = 2.9999999999999996.)
    const int dx = static_cast<int>(std::floor((new_origin_x - origin_x_) / resolution_ + 1e-6));
    const int dy = static_cast<int>(std::floor((new_origin_y - origin_y_) / resolution_ + 1e-6));
    if (dx == 0 && dy == 0) return;
    std::vector<uint8_t> shifted(costs_.size(), fill_cost);
    const int sx = static_cast<int>(size_x_);
    const int sy = static_cast<int>(size_y_);
    // New cell (x, y) was old cell (x + dx, y + dy).
    const int x_lo = std::max(0, -dx), x_hi = std::min(sx, sx - dx);
    for (int y = std::max(0, -dy); y < std::min(sy, sy - dy); ++y)
    {
      if (x_lo >= x_hi) break;
      std::copy(costs_.begin() + index(x_lo + dx, y + dy), costs_.begin() + index(x_hi + dx, y + dy),
                shifted.begin() + index(x_lo, y));
    }
    costs_.swap(shifted);
    origin_x_ += dx * resolution_;
    origin_y_ += dy * resolution_;
  }

private:
  unsigned size_x_ = 0;
  unsigned size_y_ = 0;
  double resolution_ = 0.05;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  std::vector<uint8_t> costs_;
};

}  // namespace mbot_navigation
