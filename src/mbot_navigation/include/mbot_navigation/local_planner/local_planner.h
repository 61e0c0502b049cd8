/**
 * @file local_planner.h
 * @brief The local planner interface (nav_core::BaseLocalPlanner, without ROS types): what the
 *        Navigator asks of a local planner. DwaPlanner (dwa_planner.h) is the one the nav node runs.
 */
#pragma once

#include <string>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/local_planner/trajectory.h"

namespace mbot_navigation
{
/// @brief What the local planner is doing in this cycle.
enum class LocalPlannerState
{
  FOLLOWING,  ///< driving along the plan (sampled trajectories)
  STOPPING,   ///< at the goal position, braking before the final rotation
  ROTATING,   ///< at the goal position, turning in place to the goal yaw
  ARRIVED,    ///< at the goal pose, braking to a standstill
};

/// @brief Outcome of one control cycle; `error` says why when `ok` is false.
struct LocalPlanResult
{
  bool ok = false;
  std::string error;  ///< e.g. "no valid trajectory: 60 samples, rejected by obstacle: 60"
  LocalPlannerState state = LocalPlannerState::FOLLOWING;
  Trajectory trajectory;  ///< the chosen trajectory (for the local_plan topic)
  int samples = 0;        ///< trajectories simulated this cycle
};

/// @brief Follows a global plan: one velocity command per control cycle.
class LocalPlanner
{
public:
  virtual ~LocalPlanner() = default;

  /// @brief For messages, e.g. "DWA".
  virtual std::string name() const = 0;

  /// @brief A new global plan, in the frame of the costmaps given to computeVelocityCommands.
  virtual void setPlan(const std::vector<Pose2D>& plan) = 0;
  /// @brief The plan still ahead of the robot (the planner may drop the poses it has passed).
  virtual const std::vector<Pose2D>& plan() const = 0;

  /**
   * @brief One control cycle.
   * @param robot_pose in the costmap's frame [m, m, rad]
   * @param robot_velocity the measured velocity, robot frame (odometry) [m/s, m/s, rad/s]
   * @param costmap the local costmap
   * @param[out] cmd the velocity to command; zero when the result is not ok
   * @return ok, or the reason why there is no command (the Navigator then replans or recovers)
   */
  virtual LocalPlanResult computeVelocityCommands(const Pose2D& robot_pose, const Twist2D& robot_velocity,
                                                  const Costmap2D& costmap, Twist2D& cmd) = 0;

  /// @brief True when the robot is at the plan's last pose and stopped.
  virtual bool isGoalReached(const Pose2D& robot_pose, const Twist2D& robot_velocity) const = 0;

  /// @brief The robot's footprint radius [m]: plan poses this close to the robot are under it.
  virtual double footprintRadius() const = 0;
};

}  // namespace mbot_navigation
