/**
 * @file trajectory_generator.h
 * @brief Samples the dynamic window and simulates each sample forward (free of ROS types).
 *
 * Model: base_local_planner/simple_trajectory_generator.h with use_dwa = true: the window is
 * every velocity reachable from the current one within one control period (sim_period) under
 * the acceleration limits; each sample is then held constant for sim_time.
 */
#pragma once

#include <vector>

#include "mbot_navigation/local_planner/trajectory.h"

namespace mbot_navigation
{
/// @brief Dynamic-window sampler and forward simulator for diff-drive and omni robots.
class TrajectoryGenerator
{
public:
  explicit TrajectoryGenerator(const DwaConfig& config);

  /**
   * @brief Compute the velocity samples of the dynamic window around the `measured` velocity.
   *
   * The measured velocity is first clipped to the velocity limits (odometry noise can read above
   * them). Then v_x, v_y and omega are each sampled evenly over [v - acc_lim * sim_period,
   * v + acc_lim * sim_period], clipped to the velocity limits (omega to +-max_vel_theta).
   */
  void initialise(const Twist2D& measured);

  /// @brief The samples computed by the last initialise().
  const std::vector<Twist2D>& samples() const { return samples_; }

  /**
   * @brief False for samples that are too slow to move (below both min_vel_trans and
   *        min_vel_theta) or too fast (above max_vel_trans), as dwa_local_planner does; except
   *        that the minimums are lowered to the fastest speeds of the current window, so that
   *        a robot with low acceleration limits can start from rest.
   */
  bool isAdmissible(const Twist2D& sample) const;

  /**
   * @brief Simulate `sample` held for sim_time from `pose`, one pose per sim_granularity [m] or
   *        angular_sim_granularity [rad], whichever gives more poses.
   * @return false (and an empty trajectory) when the sample is not admissible
   */
  bool generate(const Pose2D& pose, const Twist2D& sample, Trajectory& trajectory) const;

  /**
   * @brief Simulate `command` held for one sim_period, then braking at the acceleration limits
   *        to a stop: where the robot goes if we send `command` now and stop after it.
   *        Used to check the slow-down and rotate-in-place commands near the goal.
   */
  void generateBraking(const Pose2D& pose, const Twist2D& command, Trajectory& trajectory) const;

  /**
   * @brief Evenly spaced samples of [min, max], both included (base_local_planner's
   *        VelocityIterator): one sample if min == max, else at least two; 0 is added when the
   *        range crosses it so that the robot can always command "no motion" on that axis.
   */
  static std::vector<double> sampleRange(double min, double max, int num_samples);

private:
  DwaConfig config_;
  std::vector<Twist2D> samples_;
  double min_vel_trans_;  ///< admissible minimum |(v_x, v_y)| in the current window [m/s]
  double min_vel_theta_;  ///< admissible minimum |omega| in the current window [rad/s]
};

/// @brief One Euler step of the robot's kinematics: `velocity` (robot frame) for `dt` [s].
Pose2D integratePose(const Pose2D& pose, const Twist2D& velocity, double dt);

/// @brief `v` moved towards `target` by at most `max_step` (one period of limited acceleration).
double stepTowards(double v, double target, double max_step);

}  // namespace mbot_navigation
