/**
 * @file obstacle_layer.h
 * @brief Obstacles seen by a laser: marking and ray-trace clearing (costmap_2d's ObstacleLayer,
 *        without ROS types).
 *
 * Every update first clears the cells that the beams passed through, then marks the cells they
 * hit, so that a hit of this scan is never cleared by another beam of the same scan. Ranges follow
 * REP-117: -Inf means "too close to measure" and NaN means "invalid" (both ignored); +Inf means
 * "no return within range_max", which costmap_2d ignores too unless `inf_is_valid` is set: then
 * the beam counts as a reading at range_max (it clears up to there, and a range_max within
 * obstacle_range is even marked, as in costmap_2d).
 */
#pragma once

#include <limits>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/layer.h"

namespace mbot_navigation
{
/// @brief ObstacleLayer settings, with move_base's (costmap_2d's) parameter names.
struct ObstacleLayerConfig
{
  double obstacle_range = 2.5;             ///< mark hits no further than this from the sensor [m]
  double raytrace_range = 3.0;             ///< clear free space no further than this [m]
  bool track_unknown_space = false;        ///< never-seen cells: NO_INFORMATION (true) or FREE (false)
  bool footprint_clearing_enabled = true;  ///< clear the cells under the robot (robot_radius)
  bool marking = true;                     ///< hits mark their cells (the source's `marking`)
  bool clearing = true;                    ///< beams clear the cells they cross (the source's `clearing`)
  bool inf_is_valid = false;               ///< +Inf is a reading at range_max (costmap_2d's default: ignored)
};

/// @brief One beam: a direction and a range, REP-117 semantics for the range.
struct ScanBeam
{
  double angle = 0.0;  ///< beam direction in the costmap frame [rad]
  double range = 0.0;  ///< [m]; +Inf no return, -Inf too close, NaN invalid
};

/// @brief A laser scan already transformed into the costmap frame.
struct ScanObservation
{
  double origin_x = 0.0;                                       ///< sensor position in the costmap frame [m]
  double origin_y = 0.0;                                       ///< [m]
  double range_min = 0.0;                                      ///< [m] (LaserScan.range_min)
  double range_max = std::numeric_limits<double>::infinity();  ///< [m] (LaserScan.range_max)
  double stamp = 0.0;                                          ///< when it was taken [s] (moving obstacles)
  std::vector<ScanBeam> beams;

  /// @brief Add a beam that hit the point (x, y) [m] of the costmap frame (set the origin first).
  void addEndpoint(double x, double y);
  /// @brief Add a beam with no return (+Inf) in direction `angle` [rad].
  void addNoReturn(double angle);
};

/// @brief Marks laser hits as LETHAL in its own grid and clears the cells the beams crossed.
class ObstacleLayer : public Layer
{
public:
  explicit ObstacleLayer(const ObstacleLayerConfig& config = ObstacleLayerConfig());

  std::string name() const override { return "obstacle_layer"; }

  /// @brief Queue a scan; it is applied at the next updateMap() (as costmap_2d's buffers).
  void addObservation(const ScanObservation& scan) { pending_.push_back(scan); }

  void matchSize(const Costmap2D& master) override;
  void updateOrigin(double new_origin_x, double new_origin_y) override;
  void onFootprintChanged(double robot_radius) override { robot_radius_ = robot_radius; }
  void updateBounds(const Pose2D& robot, Bounds& bounds) override;
  void updateCosts(Costmap2D& master, const CellWindow& window) override;
  void reset() override;

  /// @brief What this layer has seen so far, in the master's geometry.
  const Costmap2D& grid() const { return grid_; }

private:
  /// @brief Set the cells of the segment (x0, y0) -> (x1, y1) [m], clipped to the grid, to FREE;
  ///        the end cell is kept when `keep_end` (it holds the hit).
  void raytrace(double x0, double y0, double x1, double y1, bool keep_end, Bounds& bounds);
  /// The range to use for a beam: NaN for a beam to skip, +Inf for a no-return beam with
  /// inf_is_valid and an infinite range_max, else a finite range.
  double usableRange(double range, const ScanObservation& scan) const;
  uint8_t unknownValue() const { return config_.track_unknown_space ? cost::NO_INFORMATION : cost::FREE; }

  ObstacleLayerConfig config_;
  Costmap2D grid_;
  std::vector<ScanObservation> pending_;
  double robot_radius_ = 0.0;
};

}  // namespace mbot_navigation
