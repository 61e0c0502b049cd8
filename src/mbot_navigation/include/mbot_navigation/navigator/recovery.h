/**
 * @file recovery.h
 * @brief Recovery behaviours of the nav node (move_base's clear_costmap_recovery,
 *        rotate_recovery and a back-up), free of ROS types.
 *
 * move_base runs a recovery as one blocking call that publishes velocities itself. Here a
 * recovery is stepped by the control loop instead, one cycle at a time, so that the node keeps
 * serving preemptions, costmap updates and feedback while it runs: start() once, then step()
 * every control cycle until it reports DONE or FAILED.
 */
#pragma once

#include <functional>
#include <string>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/local_planner/trajectory.h"

namespace mbot_navigation
{
/// @brief What a recovery sees in one control cycle (costmap frame).
struct RecoveryInput
{
  double now = 0.0;                          ///< [s]
  Pose2D pose;                               ///< the robot [m, m, rad]
  Twist2D velocity;                          ///< measured, robot frame [m/s, m/s, rad/s]
  const Costmap2D* local_costmap = nullptr;  ///< the local costmap, updated this cycle
};

enum class RecoveryStatus
{
  RUNNING,  ///< command `cmd` and step again next cycle
  DONE,     ///< finished as intended
  FAILED,   ///< could not do its job; message() says why
};

/// @brief A recovery behaviour (nav_core::RecoveryBehavior, stepped instead of blocking).
class RecoveryBehavior
{
public:
  virtual ~RecoveryBehavior() = default;
  /// @brief Name used in status texts, e.g. "rotate_recovery".
  virtual std::string name() const = 0;
  /// @brief Begin a run from the robot's current state.
  virtual void start(const RecoveryInput& input) = 0;
  /// @brief One control cycle: the velocity to command now (zero unless RUNNING).
  virtual RecoveryStatus step(const RecoveryInput& input, Twist2D& cmd) = 0;
  /// @brief Why the last run FAILED ("" otherwise).
  const std::string& message() const { return message_; }

protected:
  std::string message_;
};

/// @brief Forget what the sensors marked in both costmaps (the callback does it), in one cycle.
class ClearCostmapsRecovery : public RecoveryBehavior
{
public:
  explicit ClearCostmapsRecovery(std::function<void()> clear_costmaps) : clear_(std::move(clear_costmaps)) {}
  std::string name() const override { return "clear_costmaps"; }
  void start(const RecoveryInput&) override { message_.clear(); }
  RecoveryStatus step(const RecoveryInput& input, Twist2D& cmd) override;

private:
  std::function<void()> clear_;
};

/// @brief RotateRecovery settings.
struct RotateRecoveryConfig
{
  double max_vel_theta = 1.0;    ///< [rad/s]
  double acc_lim_theta = 3.2;    ///< [rad/s^2]
  double min_vel_theta = 0.4;    ///< slowest turn that still moves the robot [rad/s]
  double control_period = 0.05;  ///< [s] 1 / controller_frequency
  double tolerance = 0.1;        ///< stop this short of a full turn [rad]
  double timeout = 20.0;         ///< give up after this long [s]
};

/**
 * @brief Turn once in place (counter-clockwise), so that the laser sweeps the costmaps clear
 *        (rotate_recovery). The footprint is a circle around the turning centre, so turning cannot
 *        hit anything the robot does not already touch; no collision check is needed.
 */
class RotateRecovery : public RecoveryBehavior
{
public:
  explicit RotateRecovery(const RotateRecoveryConfig& config) : config_(config) {}
  std::string name() const override { return "rotate_recovery"; }
  void start(const RecoveryInput& input) override;
  RecoveryStatus step(const RecoveryInput& input, Twist2D& cmd) override;

private:
  RotateRecoveryConfig config_;
  double start_time_ = 0.0;  ///< [s]
  double last_yaw_ = 0.0;    ///< [rad]
  double turned_ = 0.0;      ///< so far [rad]
  double last_cmd_ = 0.0;    ///< last commanded yaw rate [rad/s]
};

/// @brief BackUpRecovery settings.
struct BackUpRecoveryConfig
{
  double distance = 0.3;           ///< how far to back up [m]
  double speed = 0.1;              ///< backwards speed [m/s] (> 0)
  double footprint_radius = 0.15;  ///< the robot's circle [m]
  double timeout = 10.0;           ///< give up after this long [s]
};

/**
 * @brief Drive straight backwards `distance`, as far as the local costmap shows no LETHAL cell
 *        under the footprint along the way (a robot pushed against an obstacle, or inside the
 *        inflated zone where the local planner rejects every trajectory, gets out this way).
 */
class BackUpRecovery : public RecoveryBehavior
{
public:
  explicit BackUpRecovery(const BackUpRecoveryConfig& config) : config_(config) {}
  std::string name() const override { return "back_up"; }
  void start(const RecoveryInput& input) override;
  RecoveryStatus step(const RecoveryInput& input, Twist2D& cmd) override;

  /// @brief How far [m] the robot at `pose` can back up (at most `distance`) before a LETHAL cell
  ///        of `costmap` behind its starting position comes under its footprint (cells beside or
  ///        ahead of it, which it may already touch, do not count); checked every half cell.
  static double freeDistanceBehind(const Costmap2D& costmap, const Pose2D& pose, double distance,
                                   double footprint_radius);

private:
  BackUpRecoveryConfig config_;
  Pose2D start_pose_;
  double start_time_ = 0.0;  ///< [s]
  double target_ = 0.0;      ///< distance to back up in this run [m]
};

}  // namespace mbot_navigation
