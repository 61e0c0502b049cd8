/**
 * @file ompl_planner.h
 * @brief A sampling-based global planner on OMPL (RRT*, PRM* or RRT-Connect over SE(2)),
 *        behind the GlobalPlanner interface. Free of ROS types.
 *
 * The state space is SE(2) bounded by the costmap. A state is valid when the cell under it is in
 * the map and costs less than INSCRIBED (the costmap is inflated by the robot's radius, so the
 * centre alone decides; the footprint is a circle, so the yaw does not matter). A motion is valid
 * when every cell its straight xy segment crosses is valid: an exact cell walk, which is stricter
 * than checking samples every half cell (those can skip the clipped corner of a cell).
 *
 * The solution is simplified (ompl::geometric::PathSimplifier) and then interpolated to about one
 * pose per `path_resolution`; the poses' yaw is the direction of travel, except the first and the
 * last, which are the start and the goal as given.
 */
#pragma once

#include <string>

#include "mbot_navigation/global_planner.h"

namespace mbot_navigation
{
/// @brief OmplPlanner parameters.
struct OmplConfig
{
  std::string planner = "rrtstar";  ///< "rrtstar", "prmstar" or "rrtconnect"
  double time_limit = 1.0;          ///< planning time [s]; RRT* and PRM* use all of it to
                                    ///< shorten the path, RRT-Connect stops at its first path
  unsigned seed = 42;               ///< OMPL's random seed (> 0), set before every plan
  double path_resolution = 0.05;    ///< spacing of the returned poses [m]
  bool simplify = true;             ///< shorten and smooth the solution (PathSimplifier)
};

/// @brief GlobalPlanner on OMPL; see the file comment.
class OmplPlanner : public GlobalPlanner
{
public:
  /// @throws std::invalid_argument for an unknown planner name or a parameter out of range
  explicit OmplPlanner(const OmplConfig& config);

  /**
   * @brief Plan from start to goal; start and goal must lie on cells with cost < INSCRIBED.
   *
   * The random seed is reset to `config.seed` before each request, so a request always gives the
   * same path with "rrtconnect"; RRT* and PRM* refine until the time limit, so their result also
   * depends on how many iterations fit in it.
   */
  PlanResult makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal) override;

  /// @brief "ompl", the name makeGlobalPlanner() knows it by; config().planner says which one.
  std::string name() const override { return "ompl"; }

  const OmplConfig& config() const { return config_; }

private:
  OmplConfig config_;
};

}  // namespace mbot_navigation
