/**
 * @file trajectory.h
 * @brief The vocabulary of the DWA local planner: a velocity, a simulated trajectory and the
 *        planner's parameters (DwaConfig). Free of ROS types.
 *
 * Model: ros-planning/navigation base_local_planner/trajectory.h and
 * dwa_local_planner/cfg/DWAPlanner.cfg (parameter names and defaults are theirs).
 */
#pragma once

#include <vector>

#include <mbot_common/geometry.h>

#include "mbot_navigation/costmap/costmap_2d.h"

namespace mbot_navigation
{
/// @brief A planar velocity in the robot's frame: mbot_common's {vx [m/s] forward, vy [m/s] to
///        the left (omni robots only), wz [rad/s] counter-clockwise} (geometry_msgs/Twist's
///        linear.x, linear.y and angular.z).
using mbot_common::Twist2D;

/// @brief One velocity sample held for `sim_time`, and the poses the robot would pass through.
struct Trajectory
{
  Twist2D velocity;           ///< the sampled command [m/s, m/s, rad/s]
  double time_delta = 0.0;    ///< time between consecutive poses [s]
  std::vector<Pose2D> poses;  ///< from the robot's pose (first) to the pose after sim_time (last)
  double cost = -1.0;         ///< weighted sum of the critics' scores; negative = rejected
};

/**
 * @brief Parameters of the DWA local planner, named and defaulted as dwa_local_planner's.
 *
 * The defaults are dwa_local_planner's, which were tuned for an omni-directional base: for a
 * differential-drive robot set max_vel_y = min_vel_y = 0 (v_y is then never sampled). Robot
 * limits come from mbot_description's model file (RobotModel::limits), the footprint radius
 * from the URDF (RobotModel::footprint_radius).
 */
struct DwaConfig
{
  // Robot limits (base_local_planner's LocalPlannerLimits).
  double max_vel_trans = 0.55;     ///< largest |(v_x, v_y)| [m/s]
  double min_vel_trans = 0.1;      ///< smallest |(v_x, v_y)| of a sample that does not rotate [m/s]
  double max_vel_x = 0.55;         ///< [m/s]
  double min_vel_x = 0.0;          ///< negative lets the robot back up [m/s]
  double max_vel_y = 0.1;          ///< [m/s] (0 for a differential drive)
  double min_vel_y = -0.1;         ///< [m/s] (0 for a differential drive)
  double max_vel_theta = 1.0;      ///< largest |omega| [rad/s]
  double min_vel_theta = 0.4;      ///< smallest |omega| of a sample that does not translate [rad/s]
  double acc_lim_x = 2.5;          ///< [m/s^2]
  double acc_lim_y = 2.5;          ///< [m/s^2]
  double acc_lim_theta = 3.2;      ///< [rad/s^2]
  double trans_stopped_vel = 0.1;  ///< below this |v_x| and |v_y| the robot counts as stopped [m/s]
  double theta_stopped_vel = 0.1;  ///< below this |omega| the robot counts as stopped [rad/s]

  // Goal tolerances.
  double xy_goal_tolerance = 0.1;        ///< [m]
  double yaw_goal_tolerance = 0.1;       ///< [rad]
  bool latch_xy_goal_tolerance = false;  ///< once within xy tolerance, only rotate (even if pushed out)

  // Forward simulation.
  double controller_frequency = 20.0;    ///< [Hz]; sim_period = 1 / controller_frequency
  double sim_time = 1.7;                 ///< each sample is simulated this long [s]
  double sim_granularity = 0.025;        ///< step between poses along a trajectory [m]
  double angular_sim_granularity = 0.1;  ///< step between poses of a rotation [rad]
  int vx_samples = 3;                    ///< samples of v_x in the dynamic window
  int vy_samples = 10;                   ///< samples of v_y (1 sample when max_vel_y == min_vel_y)
  int vth_samples = 20;                  ///< samples of omega

  // Critics' weights.
  double path_distance_bias = 32.0;       ///< weight of staying on the plan [1/m of distance]
  double goal_distance_bias = 24.0;       ///< weight of reaching the local goal [1/m of distance]
  double occdist_scale = 0.01;            ///< weight of the largest cell cost along a trajectory
  double twirling_scale = 0.0;            ///< weight of |omega| (0 disables the twirling critic)
  double forward_point_distance = 0.325;  ///< the robot's "nose", ahead of its centre [m]
  double oscillation_reset_dist = 0.05;   ///< travel that clears the oscillation flags [m]
  double oscillation_reset_angle = 0.2;   ///< rotation that clears the oscillation flags [rad]
  bool prune_plan = true;                 ///< drop plan poses the robot has left behind (> 1 m back)

  // Robot geometry (from the URDF: mbot_description RobotModel::footprint_radius).
  double footprint_radius = 0.0;  ///< radius of the circular footprint [m]; must be set (> 0)

  /// @brief Control period [s], the time over which one cycle's acceleration applies.
  double simPeriod() const { return 1.0 / controller_frequency; }

  /// @brief Throws std::invalid_argument naming the first parameter that is out of range.
  void validate() const;
};

}  // namespace mbot_navigation
