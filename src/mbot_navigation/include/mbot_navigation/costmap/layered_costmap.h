/**
 * @file layered_costmap.h
 * @brief A master cost grid built from a stack of layers (costmap_2d's LayeredCostmap, no ROS).
 *
 * Global costmap: a static size (usually the static layer's map size). Local costmap: a rolling
 * window of `width` x `height` metres kept centred on the robot; recentering shifts the kept
 * cells (Costmap2D::updateOrigin) instead of clearing them.
 */
#pragma once

#include <memory>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/costmap/layer.h"

namespace mbot_navigation
{
/// @brief Costmap-wide settings, with move_base's costmap_2d parameter names.
struct LayeredCostmapConfig
{
  bool rolling_window = false;       ///< keep the window centred on the robot (local costmap)
  double width = 10.0;               ///< window width [m] (rolling window; a static map sets its own)
  double height = 10.0;              ///< window height [m]
  double resolution = 0.05;          ///< [m/cell]
  double origin_x = 0.0;             ///< lower-left corner of cell (0, 0) [m] (not rolling)
  double origin_y = 0.0;             ///< [m]
  bool track_unknown_space = false;  ///< master default NO_INFORMATION (true) or FREE (false)
  /// Robot footprint radius [m] (move_base `robot_radius`; the nav node takes it from the URDF).
  double robot_radius = 0.2;
};

/// @brief The master grid plus its layers; updateMap() runs the two-pass layer update.
class LayeredCostmap
{
public:
  explicit LayeredCostmap(const LayeredCostmapConfig& config);

  /// @brief Append a layer (updated after the ones added before it) and size it to the master.
  /// @return the layer, still owned by this costmap
  Layer& addLayer(std::unique_ptr<Layer> layer);

  /// @brief Resize the master (and every layer) to size_x x size_y cells [-, -, m/cell, m, m].
  void resizeMap(unsigned size_x, unsigned size_y, double resolution, double origin_x, double origin_y);

  /// @brief Set the footprint radius [m]; layers that depend on it (inflation) are told.
  void setRobotRadius(double robot_radius);

  /**
   * @brief Update the master grid for the robot at `robot` [m, m, rad] (costmap frame): recenter
   *        a rolling window, collect the layers' dirty windows, reset that window of the master
   *        to its default value and let every layer write its costs into it.
   */
  void updateMap(const Pose2D& robot);

  /// @brief Reset every layer and rewrite the whole master at the next update.
  void reset();
  /// @brief Rewrite the whole master at the next update (a layer's settings changed).
  void requestFullUpdate() { full_update_ = true; }

  const Costmap2D& costmap() const { return costmap_; }
  const LayeredCostmapConfig& config() const { return config_; }
  bool isRolling() const { return config_.rolling_window; }
  double robotRadius() const { return config_.robot_radius; }
  /// @brief NO_INFORMATION when tracking unknown space, else FREE.
  uint8_t defaultValue() const { return config_.track_unknown_space ? cost::NO_INFORMATION : cost::FREE; }
  /// @brief The window [cells] written by the last updateMap() (empty when nothing changed).
  const CellWindow& lastWindow() const { return last_window_; }
  /// @brief Number of layers.
  size_t size() const { return layers_.size(); }
  Layer& layer(size_t i) { return *layers_[i]; }

private:
  /// @brief Convert a window in metres to clipped cells, as costmap_2d does ([x0, xn) x [y0, yn)).
  CellWindow toCells(const Bounds& b) const;

  LayeredCostmapConfig config_;
  Costmap2D costmap_;
  std::vector<std::unique_ptr<Layer>> layers_;
  CellWindow last_window_;
  bool full_update_ = true;  ///< rewrite the whole grid at the next update (resize, reset, move)
};

}  // namespace mbot_navigation
