/**
 * @file goal_checks.h
 * @brief Why a navigation goal cannot be accepted, free of ROS types.
 *
 * The nav node rejects a bad goal at once, with a status text that says why, instead of letting
 * the planner fail for planner_patience seconds:
 *  - checkGoalValues(): a NaN or infinite coordinate, an orientation that is not a unit
 *    quaternion (norm off by more than 1e-3) or not a rotation about the z axis;
 *  - StaticGoalChecker: a position outside the map, in an obstacle of the static map (a wall, or
 *    closer to one than the robot's radius), or in a part of the map that the robot cannot reach
 *    from where it stands.
 *
 * Only the static map decides "in an obstacle" and "unreachable" here: obstacles seen by the laser
 * and teammates come and go, so a goal blocked by them is retried (planner_patience, recoveries).
 * Every text starts with the words the move_base-compatible interface promises, e.g.
 * "goal is in an obstacle", "no path from start to goal".
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"

namespace mbot_navigation
{
/// @brief A goal as it arrives in a message: position [m] and orientation quaternion.
struct GoalValues
{
  double x = 0.0, y = 0.0, z = 0.0;               ///< [m]
  double qx = 0.0, qy = 0.0, qz = 0.0, qw = 1.0;  ///< orientation quaternion
};

/**
 * @brief Check the numbers of a goal.
 * @param norm_tolerance how far the quaternion's norm may be from 1
 * @return "" when the goal is fine, else "goal has a NaN coordinate", "goal has an infinite
 *         coordinate", "goal orientation is not a unit quaternion (norm 0.50)" or "goal
 *         orientation is not a rotation about the z axis (...)"
 */
std::string checkGoalValues(const GoalValues& goal, double norm_tolerance = 1e-3);

/// @brief "(12.00, 3.00)": a point [m] as the status texts print it.
std::string formatPoint(double x, double y);

/**
 * @brief Checks goals against the static costmap (the map inflated by the robot's radius): outside
 *        the map, in an obstacle, or not in the free region the robot stands in.
 *
 * setCostmap() labels the connected regions of passable cells (cost < INSCRIBED, 8-connected as
 * the A* planner moves; NO_INFORMATION counts as passable when allow_unknown), so that each check
 * is O(1) and agrees with what the global planner can do on the static map.
 */
class StaticGoalChecker
{
public:
  /// @param allow_unknown NO_INFORMATION cells are passable (as the global planner's allow_unknown)
  /// @param escape_radius a robot standing in an impassable cell (pushed against a wall, say)
  ///        counts as being in the nearest passable cell within this distance [m]
  explicit StaticGoalChecker(bool allow_unknown = true, double escape_radius = 0.5)
      : allow_unknown_(allow_unknown), escape_radius_(escape_radius)
  {}

  /// @brief Take a new static costmap (copied) and label its regions.
  void setCostmap(const Costmap2D& costmap);
  /// @brief True once a costmap was given.
  bool ready() const { return !label_.empty(); }
  const Costmap2D& costmap() const { return costmap_; }

  /**
   * @brief Check a goal (costmap frame [m]). "": fine. Otherwise one of
   *        "goal (12.00, 3.00) is outside the map [-10, 10] x [-10, 10]",
   *        "goal is in an obstacle: ...", "no path from start to goal: ...".
   * @param start the robot's position, or nullptr when unknown (then reachability is not checked;
   *        nor is it when the robot stands further than escape_radius inside an obstacle)
   */
  std::string check(const Pose2D* start, const Pose2D& goal) const;

  /// @brief The region label of the passable cell nearest to (x, y) [m] within `radius` [m]
  ///        (the cell itself when passable); -1 when there is none or (x, y) is off the map.
  int32_t regionNear(double x, double y, double radius) const;

private:
  bool passable(uint8_t c) const { return c < cost::INSCRIBED || (allow_unknown_ && c == cost::NO_INFORMATION); }

  bool allow_unknown_;
  double escape_radius_;  ///< [m]
  Costmap2D costmap_;
  std::vector<int32_t> label_;  ///< per cell: region number, or -1 for an impassable cell
};

}  // namespace mbot_navigation
