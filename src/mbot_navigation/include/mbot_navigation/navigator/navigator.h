/**
 * @file navigator.h
 * @brief move_base's state machine (plan, control, recover), free of ROS types.
 *
 * The nav node feeds it one control cycle at a time (the robot's pose and velocity and the two
 * updated costmaps) and publishes what it returns; everything else of move_base's behaviour is
 * here, so that it can be tested without a master:
 *
 *  - PLANNING: plan from the robot to the goal on the global costmap. On success: CONTROLLING.
 *    On failure: stand still and try again next cycle, until planner_patience has passed since the
 *    plan became necessary; then recover.
 *  - CONTROLLING: every cycle, check the plan ahead of the robot against the updated global costmap
 *    and replan when one of its poses became impassable (>= INSCRIBED: an obstacle or a teammate
 *    moved onto it), and also every 1 / planner_frequency seconds when planner_frequency > 0. Then
 *    the goal is reached (SUCCEEDED), or the local planner gives the velocity; when it cannot, stand
 *    still and replan, until controller_patience has passed since its last valid command; then
 *    recover. With oscillation_timeout > 0, moving less than oscillation_distance in that time also
 *    starts a recovery.
 *  - RECOVERING: run the next recovery behaviour (in order: clear costmaps, rotate, back up), then
 *    plan again with fresh patience. Moving oscillation_distance afterwards counts as progress and
 *    starts the list over. When the list is used up, the goal is ABORTED with a text naming what
 *    failed and which recoveries were tried.
 */
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/global_planner/global_planner.h"
#include "mbot_navigation/local_planner/local_planner.h"
#include "mbot_navigation/navigator/recovery.h"

namespace mbot_navigation
{
/// @brief The state machine's settings, with move_base's parameter names.
struct NavigatorConfig
{
  double planner_patience = 5.0;      ///< how long to try to plan before recovering [s]
  double controller_patience = 15.0;  ///< how long without a valid command before recovering [s]
  double planner_frequency = 0.0;     ///< periodic replanning [Hz]; 0: only when needed
  double oscillation_timeout = 0.0;   ///< [s] recover when not moving oscillation_distance in it; 0: off
  double oscillation_distance = 0.5;  ///< [m] this much motion counts as progress
  bool recovery_behavior_enabled = true;
  /// NO_INFORMATION cells are passable (the global planner's allow_unknown): the blocked-plan test
  /// must agree with the planner, or it would replan forever.
  bool allow_unknown = true;
  /// A robot whose centre is in an impassable cell (a teammate or a wall came too close) plans
  /// from the nearest passable cell within this radius [m] (the plan then starts at the robot).
  double start_escape_radius = 0.5;
};

/// @brief Where the state machine is.
enum class NavState
{
  IDLE,         ///< no goal
  PLANNING,     ///< looking for a global plan
  CONTROLLING,  ///< following the plan with the local planner
  RECOVERING,   ///< running a recovery behaviour
};

/// @brief "IDLE", "PLANNING", ...
const char* toString(NavState state);

/// @brief What happened to the goal in this cycle.
enum class NavOutcome
{
  NONE,       ///< no goal (idle)
  ACTIVE,     ///< still working on it
  SUCCEEDED,  ///< reached (the navigator is idle again)
  ABORTED,    ///< given up; see NavCycleResult::text (the navigator is idle again)
};

/// @brief One control cycle's output.
struct NavCycleResult
{
  NavOutcome outcome = NavOutcome::NONE;
  Twist2D cmd;                ///< velocity to command (zero unless driving or recovering)
  std::string text;           ///< why, when ABORTED
  bool plan_updated = false;  ///< globalPlan() changed in this cycle (publish it)
};

/// @brief move_base's plan / control / recover loop; see the file comment.
class Navigator
{
public:
  /**
   * @param local_planner follows the plan (the nav node gives a DwaPlanner)
   * @param planner the global planner (planner_factory.h)
   * @param recoveries tried in this order
   * @throws std::invalid_argument for a setting out of range or a missing planner
   */
  Navigator(const NavigatorConfig& config, std::unique_ptr<LocalPlanner> local_planner,
            std::unique_ptr<GlobalPlanner> planner, std::vector<std::unique_ptr<RecoveryBehavior>> recoveries);

  /// @brief Start navigating to `goal` (costmap frame [m, m, rad]); replaces any current goal.
  void setGoal(const Pose2D& goal, double now);
  /// @brief Drop the current goal (preempted); the next cycle commands zero.
  void cancel();
  /// @brief Replace the local planner (e.g. one with new settings, from dynamic_reconfigure), in
  ///        force from the next cycle; it is given the current plan.
  ///        @throws std::invalid_argument for a null planner
  void setLocalPlanner(std::unique_ptr<LocalPlanner> local_planner);
  NavState state() const { return state_; }
  const Pose2D& goal() const { return goal_; }

  /**
   * @brief One control cycle (see the file comment).
   * @param now [s]; @param pose the robot in the costmaps' frame; @param velocity measured, robot frame
   */
  NavCycleResult cycle(double now, const Pose2D& pose, const Twist2D& velocity, const Costmap2D& global_costmap,
                       const Costmap2D& local_costmap);

  /**
   * @brief Plan on `costmap` with the global planner; a start in an impassable cell is moved to the
   *        nearest passable cell (start_escape_radius) and the plan then begins at the real start.
   */
  PlanResult makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal);

  /// @brief The current global plan (empty when idle).
  const std::vector<Pose2D>& globalPlan() const { return plan_; }
  /// @brief The trajectory the local planner chose in the last cycle (empty poses if none).
  const Trajectory& localPlan() const { return local_plan_; }
  const GlobalPlanner& globalPlanner() const { return *planner_; }
  const LocalPlanner& localPlanner() const { return *local_planner_; }
  /// @brief The last planner or local planner failure ("" if none since the goal was set), for logs.
  const std::string& lastError() const { return last_error_; }
  /// @brief Names of the recoveries run since the robot last made progress, with their outcome.
  const std::vector<std::string>& recoveriesTried() const { return tried_; }

  /**
   * @brief The first pose of `plan` (from index `from`) whose cell is impassable in `costmap`
   *        (cost >= INSCRIBED; NO_INFORMATION only when !allow_unknown), or -1 when none is.
   *        Poses off the costmap do not count.
   */
  static long firstBlockedPose(const Costmap2D& costmap, const std::vector<Pose2D>& plan, size_t from,
                               bool allow_unknown);

private:
  /// Plan and hand the plan to the local planner; false (and `error`) on failure.
  bool replan(const Costmap2D& global_costmap, const Pose2D& pose, double now, std::string& error);
  /// Start the next recovery, or abort when none is left. Returns the cycle's result.
  NavCycleResult recover(const std::string& reason, const RecoveryInput& input);
  NavCycleResult finish(NavOutcome outcome, const std::string& text);
  NavCycleResult control(double now, const Pose2D& pose, const Twist2D& velocity, const Costmap2D& global_costmap,
                         const Costmap2D& local_costmap, NavCycleResult result);
  bool passable(uint8_t c) const { return c < cost::INSCRIBED || (config_.allow_unknown && c == cost::NO_INFORMATION); }

  NavigatorConfig config_;
  std::unique_ptr<GlobalPlanner> planner_;
  std::unique_ptr<LocalPlanner> local_planner_;
  std::vector<std::unique_ptr<RecoveryBehavior>> recoveries_;

  NavState state_ = NavState::IDLE;
  Pose2D goal_;
  std::vector<Pose2D> plan_;
  Trajectory local_plan_;
  double plan_needed_since_ = 0.0;   ///< [s] PLANNING since (planner_patience counts from here)
  double last_plan_time_ = 0.0;      ///< [s] last successful plan
  double last_valid_control_ = 0.0;  ///< [s]
  double last_progress_time_ = 0.0;  ///< [s] the robot last moved oscillation_distance
  Pose2D progress_pose_;             ///< where it was then
  bool progress_pose_set_ = false;
  size_t recovery_index_ = 0;       ///< next recovery to run
  std::vector<std::string> tried_;  ///< recoveries run since the last progress
  std::string last_error_;
};

}  // namespace mbot_navigation
