#include "mbot_navigation/local_planner/trajectory.h"

#include <sstream>
#include <stdexcept>
#include <string>

namespace mbot_navigation
{
namespace
{
void require(bool ok, const std::string& key, double value, const std::string& expected)
{
  if (ok) return;
  std::ostringstream msg;
  msg << "DWA parameter " << key << " = " << value << ": expected " << expected;
  throw std::invalid_argument(msg.str());
}
}  // namespace

void DwaConfig::validate() const
{
  require(max_vel_trans > 0.0, "max_vel_trans", max_vel_trans, "> 0");
  require(min_vel_trans >= 0.0, "min_vel_trans", min_vel_trans, ">= 0");
  require(max_vel_x >= min_vel_x, "max_vel_x", max_vel_x, ">= min_vel_x");
  require(max_vel_y >= min_vel_y, "max_vel_y", max_vel_y, ">= min_vel_y");
  require(max_vel_theta > 0.0, "max_vel_theta", max_vel_theta, "> 0");
  require(min_vel_theta >= 0.0 && min_vel_theta <= max_vel_theta, "min_vel_theta", min_vel_theta,
          "in [0, max_vel_theta]");
  require(acc_lim_x > 0.0, "acc_lim_x", acc_lim_x, "> 0");
  require(acc_lim_y > 0.0 || max_vel_y == min_vel_y, "acc_lim_y", acc_lim_y, "> 0 when v_y is sampled");
  require(acc_lim_theta > 0.0, "acc_lim_theta", acc_lim_theta, "> 0");
  require(trans_stopped_vel >= 0.0, "trans_stopped_vel", trans_stopped_vel, ">= 0");
  require(theta_stopped_vel >= 0.0, "theta_stopped_vel", theta_stopped_vel, ">= 0");
  require(xy_goal_tolerance > 0.0, "xy_goal_tolerance", xy_goal_tolerance, "> 0");
  require(yaw_goal_tolerance > 0.0, "yaw_goal_tolerance", yaw_goal_tolerance, "> 0");
  require(controller_frequency > 0.0, "controller_frequency", controller_frequency, "> 0 [Hz]");
  require(sim_time > 0.0, "sim_time", sim_time, "> 0 [s]");
  require(sim_granularity > 0.0, "sim_granularity", sim_granularity, "> 0 [m]");
  require(angular_sim_granularity > 0.0, "angular_sim_granularity", angular_sim_granularity, "> 0 [rad]");
  require(vx_samples >= 1, "vx_samples", vx_samples, ">= 1");
  require(vy_samples >= 1, "vy_samples", vy_samples, ">= 1");
  require(vth_samples >= 1, "vth_samples", vth_samples, ">= 1");
  require(path_distance_bias >= 0.0, "path_distance_bias", path_distance_bias, ">= 0");
  require(goal_distance_bias >= 0.0, "goal_distance_bias", goal_distance_bias, ">= 0");
  require(occdist_scale >= 0.0, "occdist_scale", occdist_scale, ">= 0");
  require(twirling_scale >= 0.0, "twirling_scale", twirling_scale, ">= 0");
  require(forward_point_distance >= 0.0, "forward_point_distance", forward_point_distance, ">= 0");
  require(oscillation_reset_dist >= 0.0, "oscillation_reset_dist", oscillation_reset_dist, ">= 0");
  require(oscillation_reset_angle >= 0.0, "oscillation_reset_angle", oscillation_reset_angle, ">= 0");
  require(footprint_radius > 0.0, "footprint_radius", footprint_radius,
          "> 0 [m] (the URDF's footprint radius, mbot_description RobotModel::footprint_radius)");
}

}  // namespace mbot_navigation
