/**
 * @file dwa_planner.h
 * @brief The DWA local planner: a trajectory generator plus weighted critics,
 *        with nav_core's local planner interface, free of ROS types.
 *
 * Model: ros-planning/navigation dwa_local_planner/dwa_planner.h (sampling and scoring) and
 * base_local_planner/latched_stop_rotate_controller.h (what happens at the goal). Parameters:
 * DwaConfig in trajectory.h.
 *
 * One control cycle (computeVelocityCommands):
 *  1. prune the plan poses the robot has left behind;
 *  2. if the goal position is reached (within half the xy tolerance, or within it when no
 *     trajectory gets closer): brake, then rotate in place to the goal yaw, then stop;
 *  3. otherwise sample the dynamic window, simulate each sample for sim_time, let the critics
 *     score it (a negative score rejects it) and command the cheapest trajectory's velocity.
 */
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/local_planner/critics.h"
#include "mbot_navigation/local_planner/local_planner.h"
#include "mbot_navigation/local_planner/trajectory.h"
#include "mbot_navigation/local_planner/trajectory_generator.h"

namespace mbot_navigation
{
/// @brief The DWA local planner (setPlan / computeVelocityCommands / isGoalReached).
class DwaPlanner : public LocalPlanner
{
public:
  /// @throws std::invalid_argument when a parameter is out of range (DwaConfig::validate)
  explicit DwaPlanner(const DwaConfig& config);
  // The critic list points into this object: not copyable.
  DwaPlanner(const DwaPlanner&) = delete;
  DwaPlanner& operator=(const DwaPlanner&) = delete;

  /// @brief A new global plan, in the frame of the costmaps given to computeVelocityCommands.
  ///        Clears the oscillation flags; a plan to a new goal (another last pose) also clears
  ///        the goal latch and the rotation to the goal yaw, a new plan to the same goal keeps them.
  void setPlan(const std::vector<Pose2D>& plan) override;

  /**
   * @brief One control cycle.
   * @param robot_pose in the costmap's frame [m, m, rad]
   * @param robot_velocity the measured velocity, robot frame (odometry) [m/s, m/s, rad/s]
   * @param costmap the local costmap
   * @param[out] cmd the velocity to command; zero when the result is not ok
   * @return ok with the chosen trajectory, or the reason of the failure (no plan, plan outside
   *         the costmap, every sample rejected...); the caller then runs its recoveries
   */
  LocalPlanResult computeVelocityCommands(const Pose2D& robot_pose, const Twist2D& robot_velocity,
                                          const Costmap2D& costmap, Twist2D& cmd) override;

  /// @brief True when the robot is within both goal tolerances and stopped
  ///        (|v| <= trans_stopped_vel, |omega| <= theta_stopped_vel).
  bool isGoalReached(const Pose2D& robot_pose, const Twist2D& robot_velocity) const override;

  const DwaConfig& config() const { return config_; }
  /// @brief The plan, as pruned by the last cycle (the part the robot has not passed yet).
  const std::vector<Pose2D>& plan() const override { return plan_; }
  std::string name() const override { return "DWA"; }
  double footprintRadius() const override { return config_.footprint_radius; }

private:
  /// The two goal poses are the same (within 1 cm and 0.01 rad).
  static bool sameGoal(const Pose2D& a, const Pose2D& b);
  /// Of a measured and a commanded velocity on one axis, the one nearer zero; zero when their
  /// signs differ.
  static double slower(double measured, double commanded);
  /// computeVelocityCommands without remembering the command.
  LocalPlanResult controlCycle(const Pose2D& robot_pose, const Twist2D& robot_velocity, const Costmap2D& costmap,
                               Twist2D& cmd);
  /// Distance [m] from `pose` to the goal position.
  double goalDistance(const Pose2D& pose) const;
  /// Where braking for the goal starts: within half the xy_goal_tolerance of the goal; once
  /// stopping, within the tolerance (or latched there).
  bool positionReached(const Pose2D& robot_pose) const;
  /// Drop the plan poses before the first one within 1 m of the robot (base_local_planner's
  /// prunePlan); nothing when no pose is that close.
  void prunePlan(const Pose2D& robot_pose);
  /// Brake, rotate to the goal yaw, stop; the obstacle critic must be prepared.
  LocalPlanResult stopAndRotate(const Pose2D& robot_pose, const Twist2D& robot_velocity, Twist2D& cmd);
  /// Sample, simulate and score; the critics must be prepared.
  LocalPlanResult followPlan(const Pose2D& robot_pose, const Twist2D& robot_velocity, Twist2D& cmd);
  /// Whether a critic takes part this cycle (scale != 0; the obstacle critic always does).
  bool isActive(const TrajectoryCritic& critic) const;
  /// Cut a trajectory where it comes within half the xy goal tolerance of the goal: the robot
  /// brakes there (stopAndRotate), so what follows would never be driven. Without this, every
  /// sample near the goal overshoots it (a sample is held for sim_time at >= min_vel_trans) and
  /// the robot may turn in place short of the goal instead of driving the last centimetres.
  void truncateAtGoal(Trajectory& trajectory) const;
  /// Weighted sum of the critics' scores; negative (the critic's code) when one rejects.
  /// Stops early once the sum exceeds `best` (>= 0), as the result cannot win then.
  double scoreTrajectory(const Trajectory& trajectory, double best, int& rejected_by);

  DwaConfig config_;
  TrajectoryGenerator generator_;
  std::vector<Pose2D> plan_;  ///< the global plan, pruned behind the robot

  // Critics, owned here; `critics_` lists them in scoring order (cheap and decisive first).
  ObstacleCritic obstacle_critic_;
  OscillationCritic oscillation_critic_;
  PathDistCritic path_critic_;
  GoalDistCritic goal_critic_;
  PathAlignCritic path_align_critic_;
  GoalAlignCritic goal_align_critic_;
  TwirlingCritic twirling_critic_;
  std::vector<TrajectoryCritic*> critics_;

  /// braking or turning at the goal until pushed out of the tolerance (with
  /// latch_xy_goal_tolerance: until a new goal)
  bool stopping_at_goal_ = false;
  bool rotating_to_goal_ = false;  ///< stopped at the goal position, now turning
  Twist2D last_cmd_;               ///< the last cycle's command (zero after a failed cycle)

  // Reused per cycle (no allocation once sized).
  Trajectory candidate_;
  Trajectory best_;
};

}  // namespace mbot_navigation
