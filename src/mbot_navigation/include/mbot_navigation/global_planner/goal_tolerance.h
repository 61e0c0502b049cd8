/**
 * @file goal_tolerance.h
 * @brief move_base's make_plan `tolerance`: when the requested goal cannot be planned to, try
 *        free goals around it, nearest first. No ROS types (the nav node's make_plan service
 *        calls planWithTolerance).
 */
#pragma once

#include <functional>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/global_planner/global_planner.h"

namespace mbot_navigation
{
/// @brief A goal cell the search may pick: on the map and below INSCRIBED (unknown is not free).
bool isFreeGoal(const Costmap2D& costmap, const Pose2D& goal);

/**
 * @brief The free goals around `goal` within `tolerance` [m], nearest first: rings of radius
 *        resolution, 2 x resolution, ... up to `tolerance`, 16 directions on each ring (the
 *        goal's yaw is kept). Empty when tolerance < one cell or nothing around is free.
 */
std::vector<Pose2D> goalsAround(const Costmap2D& costmap, const Pose2D& goal, double tolerance);

/**
 * @brief The nearest free goal within `tolerance` [m]: `goal` itself when it is free, else the
 *        first of goalsAround(). @return false when nothing within `tolerance` is free
 */
bool nearestFreeGoal(const Costmap2D& costmap, const Pose2D& goal, double tolerance, Pose2D& out);

/**
 * @brief Plan to `goal` with `plan`; when that fails and tolerance > 0, plan to goalsAround() in
 *        order until one succeeds. @return the successful plan, or the last attempt's failure
 */
PlanResult planWithTolerance(const Costmap2D& costmap, const Pose2D& goal, double tolerance,
                             const std::function<PlanResult(const Pose2D& goal)>& plan);

}  // namespace mbot_navigation
