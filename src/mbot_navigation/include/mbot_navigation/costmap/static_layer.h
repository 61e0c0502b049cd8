/**
 * @file static_layer.h
 * @brief The static map as a costmap layer (costmap_2d's StaticLayer, without ROS types).
 */
#pragma once

#include <cstdint>
#include <string>

#include "mbot_navigation/costmap/layer.h"

namespace mbot_navigation
{
/// @brief StaticLayer settings, with costmap_2d's parameter names.
struct StaticLayerConfig
{
  bool track_unknown_space = false;  ///< unknown (-1) -> NO_INFORMATION (true) or FREE (false)
  int lethal_cost_threshold = 100;   ///< occupancy >= this -> LETHAL [0..100]
  int unknown_cost_value = -1;       ///< the occupancy value that means unknown
  bool trinary_costmap = true;       ///< values between free and lethal -> FREE (true) or scaled
};

/**
 * @brief Copies an occupancy grid (map_server values: 100 occupied, 0 free, -1 unknown) into the
 *        costmap. In a static costmap the map sets the master's size, resolution and origin; in a
 *        rolling window the layer copies the part of the map under the window.
 */
class StaticLayer : public Layer
{
public:
  explicit StaticLayer(const StaticLayerConfig& config = StaticLayerConfig()) : config_(config) {}

  std::string name() const override { return "static_layer"; }

  /**
   * @brief Take a new map. Arguments are plain fields so that nav_msgs/OccupancyGrid and
   *        mbot_common::OccupancyMap both pass without a copy into another struct. Add the layer to
   *        its LayeredCostmap first: a static costmap then takes the map's size and origin.
   * @param width, height [cells]; @param resolution [m/cell]; @param origin_x, origin_y lower-left
   *        corner of cell (0, 0) [m] (rotation is ignored, as costmap_2d does)
   * @param data width * height occupancy values, row-major, row 0 at origin_y
   */
  void setMap(unsigned width, unsigned height, double resolution, double origin_x, double origin_y, const int8_t* data);

  /// @brief The cost that an occupancy value becomes (costmap_2d's StaticLayer::interpretValue).
  uint8_t interpretValue(int8_t value) const;

  void updateBounds(const Pose2D& robot, Bounds& bounds) override;
  void updateCosts(Costmap2D& master, const CellWindow& window) override;
  void reset() override { has_updated_data_ = true; }

  /// @brief The map as costs, in the map's own geometry.
  const Costmap2D& grid() const { return map_; }

private:
  StaticLayerConfig config_;
  Costmap2D map_;  ///< the map as costs
  bool has_map_ = false;
  bool has_updated_data_ = false;  ///< a new map arrived since the last update
};

}  // namespace mbot_navigation
