/**
 * @file layer.h
 * @brief One layer of a layered costmap (costmap_2d's Layer, without ROS types).
 *
 * An update of the LayeredCostmap runs in two passes over its layers, in the order they were
 * added: updateBounds() lets every layer grow the dirty window (world coordinates [m]) by the
 * area it changed since the last update; updateCosts() then lets every layer write its costs into
 * that window of the master grid. Layers combine by maximum (see updateWithMax()).
 */
#pragma once

#include <algorithm>
#include <cstdint>
#include <limits>
#include <string>

#include "mbot_navigation/costmap/costmap_2d.h"

namespace mbot_navigation
{
class LayeredCostmap;

/// @brief An axis-aligned window in the costmap frame [m]; empty until something is added.
struct Bounds
{
  double min_x = std::numeric_limits<double>::infinity();
  double min_y = std::numeric_limits<double>::infinity();
  double max_x = -std::numeric_limits<double>::infinity();
  double max_y = -std::numeric_limits<double>::infinity();

  bool empty() const { return min_x > max_x || min_y > max_y; }
  /// @brief Grow to include the point (x, y) [m].
  void include(double x, double y)
  {
    min_x = std::min(min_x, x);
    min_y = std::min(min_y, y);
    max_x = std::max(max_x, x);
    max_y = std::max(max_y, y);
  }
  /// @brief Grow to include another window.
  void include(const Bounds& b)
  {
    if (b.empty()) return;
    include(b.min_x, b.min_y);
    include(b.max_x, b.max_y);
  }
};

/// @brief A dirty window in cells: [x0, xn) x [y0, yn).
struct CellWindow
{
  int x0 = 0;
  int y0 = 0;
  int xn = 0;
  int yn = 0;
  bool empty() const { return xn <= x0 || yn <= y0; }
};

/**
 * @brief Combine one cell by maximum, as costmap_2d's CostmapLayer::updateWithMax: a layer's
 *        NO_INFORMATION never overwrites; anything overwrites the master's NO_INFORMATION.
 */
inline void updateWithMax(uint8_t& master, uint8_t layer)
{
  if (layer == cost::NO_INFORMATION) return;
  if (master == cost::NO_INFORMATION || master < layer) master = layer;
}

/// @brief Base class of the costmap layers (static, obstacle, other robots, inflation).
class Layer
{
public:
  virtual ~Layer() = default;

  /// @brief A short name for messages, e.g. "obstacle_layer".
  virtual std::string name() const = 0;

  /// @brief Called when the layer is added and whenever the master grid changes size.
  virtual void matchSize(const Costmap2D& /*master*/) {}

  /// @brief Rolling window: the master's origin moved to (new_origin_x, new_origin_y) [m].
  virtual void updateOrigin(double /*new_origin_x*/, double /*new_origin_y*/) {}

  /// @brief The robot's footprint radius [m] changed (LayeredCostmap::setRobotRadius).
  virtual void onFootprintChanged(double /*robot_radius*/) {}

  /**
   * @brief Grow `bounds` [m] by the area this layer changed since its last update.
   * @param robot the robot's pose in the costmap frame [m, m, rad]
   */
  virtual void updateBounds(const Pose2D& robot, Bounds& bounds) = 0;

  /// @brief Write this layer's costs into `window` of `master` (combined by maximum).
  virtual void updateCosts(Costmap2D& master, const CellWindow& window) = 0;

  /// @brief Forget everything sensed (clear_costmaps); the next update rewrites the whole layer.
  virtual void reset() {}

protected:
  friend class LayeredCostmap;
  /// The costmap this layer belongs to (non-owning; set by LayeredCostmap::addLayer).
  LayeredCostmap* layered_costmap_ = nullptr;
};

}  // namespace mbot_navigation
