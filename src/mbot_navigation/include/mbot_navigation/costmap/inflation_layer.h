/**
 * @file inflation_layer.h
 * @brief Inflation around lethal cells (costmap_2d's InflationLayer cost formula, without ROS).
 *
 * The cost of a cell at Euclidean distance d [m] from the nearest LETHAL cell is
 *   d == 0                  -> LETHAL (254)
 *   d <= inscribed_radius   -> INSCRIBED (253)  (the robot's centre here means a collision)
 *   d <= inflation_radius   -> floor(252 * exp(-cost_scaling_factor * (d - inscribed_radius)))
 *   beyond                  -> FREE (0)
 * with d measured between cell centres, exactly as costmap_2d computes it (d = cells * resolution,
 * compared as doubles). The distance is the exact Euclidean distance transform (Felzenszwalb and
 * Huttenlocher, two linear passes) over the dirty window grown by the inflation radius.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/layer.h"

namespace mbot_navigation
{
/// @brief InflationLayer settings, with move_base's (costmap_2d's) parameter names.
struct InflationLayerConfig
{
  double inflation_radius = 0.55;     ///< inflate out to this distance from obstacles [m]
  double cost_scaling_factor = 10.0;  ///< exponential decay rate of the cost [1/m]
  bool inflate_unknown = false;       ///< let inflation overwrite NO_INFORMATION cells
};

/// @brief Writes the inflated cost of every cell near a LETHAL cell of the master grid.
class InflationLayer : public Layer
{
public:
  explicit InflationLayer(const InflationLayerConfig& config = InflationLayerConfig());

  std::string name() const override { return "inflation_layer"; }

  /// @brief The inscribed radius is the robot's footprint radius [m].
  void onFootprintChanged(double robot_radius) override;
  void matchSize(const Costmap2D& master) override;
  void updateBounds(const Pose2D& robot, Bounds& bounds) override;
  void updateCosts(Costmap2D& master, const CellWindow& window) override;

  /// @brief The cost at `distance_cells` [cells] from the nearest LETHAL cell (formula above).
  uint8_t computeCost(double distance_cells) const;

  /**
   * @brief Inflate a whole grid in place, as updateCosts() does on a master grid; for tools and
   *        tests that start from a grid of LETHAL cells.
   */
  void inflate(Costmap2D& grid);

  /// @brief New settings (dynamic_reconfigure); the caller rewrites the master grid.
  /// @throws std::invalid_argument for a negative radius or factor
  void setConfig(const InflationLayerConfig& config);
  const InflationLayerConfig& config() const { return config_; }

  double inscribedRadius() const { return inscribed_radius_; }  ///< [m]

private:
  /// @brief Recompute the cost-by-squared-distance table after a parameter change.
  void computeCaches();

  InflationLayerConfig config_;
  double inscribed_radius_ = 0.0;    ///< [m]
  double resolution_ = 0.0;          ///< [m/cell] of the grid the caches were built for
  int cell_radius_ = 0;              ///< inflation radius in whole cells
  std::vector<uint8_t> cost_by_d2_;  ///< cost for squared distance d2 [cells^2], d2 <= cell_radius_^2
  // Reused buffers of the distance transform (no allocation per update once sized).
  std::vector<int> col_dist_;  ///< pass 1: vertical distance to the nearest lethal cell [cells]
  std::vector<int> d2_;        ///< pass 2: squared distance [cells^2]
  std::vector<int> env_v_;     ///< lower envelope: parabola positions
  std::vector<double> env_z_;  ///< lower envelope: boundaries
  std::vector<int> row_f_;     ///< one row of squared column distances
};

}  // namespace mbot_navigation
