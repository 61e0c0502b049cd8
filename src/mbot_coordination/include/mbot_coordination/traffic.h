// The live traffic planner's core, without ROS: a planning grid from an occupancy map, goal sets
// (a strict YAML reader and their checks), timed waypoints from a solution, the poses an executor
// holds its robot at, and re-planning some robots around the others' fixed paths.
#pragma once

#include <string>
#include <vector>

#include "mbot_common/geometry.h"
#include "mbot_common/map_io.h"
#include "mbot_coordination/instance.h"
#include "mbot_coordination/planner.h"

namespace mbot_coordination
{
// A Grid over a map: cell (cx, cy) is the square [origin + c * cell_size, origin + (c + 1) * cell_size).
struct PlanningGrid
{
  Grid grid;
  double origin_x = 0.0;   // [m] the map's origin (lower-left corner)
  double origin_y = 0.0;   // [m]
  double cell_size = 0.0;  // [m]
  double map_width = 0.0;  // [m]
  double map_height = 0.0;

  bool insideMap(double x, double y) const;
  // The cell holding (x, y) [m], -1 outside the grid.
  int cellAt(double x, double y) const;
  // The free cell whose centre is nearest (x, y), -1 when none is free (a robot beside a wall
  // stands in a blocked cell: it plans from the nearest free one).
  int nearestFreeCell(double x, double y) const;
  mbot_common::Point2D centre(int cell) const;
};

// Coarse cells of cell_size >= the robot's diameter, a cell blocked when any map cell within
// robot_radius of it is occupied or unknown (Grid::fromOccupancy). std::invalid_argument when the
// cell is smaller than the robot, or the map is rotated (origin yaw != 0).
PlanningGrid makePlanningGrid(const mbot_common::OccupancyMap& map, double cell_size, double robot_radius);

// One pose of a timed plan: a cell centre in the map frame and when to be there.
struct TimedPose
{
  double x = 0.0, y = 0.0, yaw = 0.0;  // [m, m, rad]
  double t = 0.0;                      // [s] planned arrival
  int cell = -1;
};

// path[k] -> pose k at t0 + k * cell_size / speed (so a wait is a repeated pose with a later time).
// yaw: towards the next different cell; the last pose (and waits at the end) take final_yaw.
std::vector<TimedPose> timedWaypoints(const PlanningGrid& grid, const std::vector<int>& path, double t0, double speed,
                                      double final_yaw);

// The poses an executor sends as goals (increasing indices into path): 0, the first pose of every
// wait, every corner, every pose before a cell marked in hold_before (cells another robot visits
// too: the robot is held there until its time and its turn), and the last.
std::vector<size_t> markedPoses(const std::vector<int>& path, const std::vector<bool>& hold_before);
// The last index of the wait that begins at k (k itself when the robot moves on at once).
size_t waitEnd(const std::vector<int>& path, size_t k);

// One robot's goal in a goal set.
struct FleetGoal
{
  std::string robot;
  double x = 0.0, y = 0.0, yaw = 0.0;  // [m, m, rad] map frame
};

// A goals file: `goals: {robot_0: [x, y, yaw], ...}`. Strict (mbot_common::ConfigError naming
// the file and key): unknown keys, a robot twice, a pose that is not 3 finite numbers, no goals.
std::vector<FleetGoal> readGoalsFile(const std::string& path);

// The goal cells of `goals`, or std::invalid_argument naming the first problem: no goals, an
// unknown robot, a robot twice, a pose not finite, outside the map, in (or too near) a wall, two
// robots with one goal cell.
std::vector<int> checkGoals(const std::vector<FleetGoal>& goals, const std::vector<std::string>& known_robots,
                            const PlanningGrid& grid);

// Re-plans `starts` -> `goals` (prioritized, SIPP) around `fixed` paths (time 0 = now; each fixed
// robot stays at its last cell afterwards), within options.time_limit_s and with
// options.following. Empty when no order found paths for all; *why then says which robot failed.
Paths planAround(const Grid& grid, const Paths& fixed, const std::vector<int>& starts, const std::vector<int>& goals,
                 const PlannerOptions& options, std::string* why = nullptr);

}  // namespace mbot_coordination
