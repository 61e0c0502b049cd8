/**
 * @file planner_factory.h
 * @brief Choose a global planner by name, as move_base's `base_global_planner` parameter does.
 */
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot_navigation/global_planner/astar_planner.h"
#include "mbot_navigation/global_planner/global_planner.h"
#include "mbot_navigation/global_planner/ompl_planner.h"

namespace mbot_navigation
{
/// @brief The settings of every global planner; the factory passes the chosen one's part on.
///        Parameters are read at the edge (the nav node) into these structs.
struct GlobalPlannerParams
{
  AStarConfig astar;  ///< for "astar" (AStarPlanner)
  OmplConfig ompl;    ///< for "ompl" (OmplPlanner)
  // A new planner: its config here, its name in globalPlannerNames(), a branch in makeGlobalPlanner().
};

/// @brief The names makeGlobalPlanner() accepts: {"astar", "ompl"}.
std::vector<std::string> globalPlannerNames();

/**
 * @brief Make the global planner called `name` ("astar" or "ompl").
 * @throws std::invalid_argument for an unknown name (listing the known ones) or, from the
 *         planner's constructor, for a parameter out of range
 */
std::unique_ptr<GlobalPlanner> makeGlobalPlanner(const std::string& name, const GlobalPlannerParams& params);

}  // namespace mbot_navigation
