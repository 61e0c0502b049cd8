/**
 * @file global_planner.h
 * @brief The global planner interface (nav_core::BaseGlobalPlanner, without ROS types).
 */
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"

namespace mbot_navigation
{
/// @brief Outcome of one planning request; `error` says why when `ok` is false.
struct PlanResult
{
  bool ok = false;
  std::vector<Pose2D> path;  ///< start to goal, in the costmap's frame [m, m, rad]
  std::string error;         ///< e.g. "goal (3.20, 1.00) is in an obstacle (cost 254)"
};

/// @brief Plans a path over a costmap. Implementations are chosen by name (see makeGlobalPlanner).
class GlobalPlanner
{
public:
  virtual ~GlobalPlanner() = default;
  /// @brief Plan from start to goal over `costmap`. Cells with cost >= INSCRIBED are impassable.
  virtual PlanResult makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal) = 0;
  virtual std::string name() const = 0;
};

}  // namespace mbot_navigation
