/**
 * @file ompl_planner.h
 * @brief A sampling-based global planner on OMPL (RRT*, PRM* or RRT-Connect in the plane),
 *        behind the GlobalPlanner interface. Free of ROS types.
 *
 * The state space is the xy plane bounded by the costmap (the footprint is a circle, so the yaw
 * does not matter; the poses' yaw is set afterwards). A state is valid when the cell under it is
 * in the map and costs less than INSCRIBED (the costmap is inflated by the robot's radius, so the
 * centre alone decides). A motion is valid when every cell its straight segment crosses is valid:
 * an exact cell walk, which is stricter than checking samples every half cell (those can skip the
 * clipped corner of a cell).
 *
 * Validity alone makes paths that graze door jambs and corners, where the local planner (DWA)
 * stalls. So the planner minimises a cost-aware objective, the integral along the path of
 *
 *     1 + cost_weight * c / 252      per metre, c = the inflated costmap's cost under the path,
 *
 * i.e. the path length plus a penalty for every metre driven close to obstacles (the inflation
 * layer's cost falls off with the distance from them). RRT* and PRM* optimise it within
 * `time_limit`; RRT-Connect stops at its first path. Then every planner's path is improved with
 * OMPL's cost-aware PathSimplifier steps only (shortcutPath: a shortcut is taken only when it costs
 * less than the part of the path it replaces, so it does not cut back onto a jamb; perturbPath:
 * moves path points where that lowers the cost, e.g. towards the middle of a door), for at most
 * `simplify_time_limit`. Last, the path is interpolated to one pose per `path_resolution`
 * (default: the costmap's resolution), so that the local planner gets a dense path; the poses'
 * yaw is the direction of travel, except the first and the last, which are the start and the
 * goal as given.
 */
#pragma once

#include <string>

#include "mbot_navigation/global_planner/global_planner.h"

namespace mbot_navigation
{
/**
 * @brief OmplPlanner parameters (the nav node reads them from ~OmplPlanner/<name>).
 *
 * The time limits are wall time; the nav node plans in its control loop, so the robot waits for
 * up to time_limit + simplify_time_limit (for a new goal, or when the plan is blocked).
 */
struct OmplConfig
{
  std::string planner = "rrtconnect";  ///< "rrtconnect" (fast, repeatable), "rrtstar" or "prmstar"
  double time_limit = 0.5;             ///< planning time [s]; RRT* and PRM* use all of it to
                                       ///< improve the path, RRT-Connect stops at its first path
  double simplify_time_limit = 0.2;    ///< at most this long [s] for the cost-aware simplification
                                       ///< (it usually converges much sooner)
  double cost_weight = 4.0;            ///< a metre through a cell of cost c counts as
                                       ///< 1 + cost_weight * c / 252 m; 0: only the length matters.
                                       ///< 4 is A*'s default (neutral_cost 50, cost_factor 0.8)
  unsigned seed = 42;                  ///< OMPL's random seed (> 0), set before every plan
  double path_resolution = 0.0;        ///< spacing of the returned poses [m]; 0: the costmap's
                                       ///< resolution
  bool simplify = true;                ///< improve the planner's path (shortcuts and perturbations)
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
   * same path with "rrtconnect" (unless the simplification runs into its time limit); RRT* and
   * PRM* refine until the time limit, so their result also depends on how many iterations fit in
   * it.
   */
  PlanResult makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal) override;

  /// @brief "ompl", the name makeGlobalPlanner() knows it by; config().planner says which one.
  std::string name() const override { return "ompl"; }

  const OmplConfig& config() const { return config_; }

private:
  OmplConfig config_;
};

}  // namespace mbot_navigation
