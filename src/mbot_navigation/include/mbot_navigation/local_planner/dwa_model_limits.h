/**
 * @file
 * @brief The robot model's velocity and acceleration limits as DWA settings: what the nav node
 *        and dwa_bench start from before the DWAPlannerROS keys.
 */
#pragma once

#include <algorithm>

#include <mbot_description/robot_model.h>

#include "mbot_navigation/local_planner/trajectory.h"

namespace mbot_navigation
{
/// @brief Overwrite the speed and acceleration limits of `c` with the model's.
inline void applyModelLimits(const mbot_description::Limits& lim, DwaConfig& c)
{
  c.max_vel_x = lim.max_vel_x;
  c.min_vel_x = lim.min_vel_x;
  c.max_vel_y = lim.max_vel_y;
  c.min_vel_y = -lim.max_vel_y;
  c.max_vel_trans = std::max(lim.max_vel_x, lim.max_vel_y);
  c.max_vel_theta = lim.max_vel_theta;
  c.min_vel_theta = std::min(c.min_vel_theta, lim.max_vel_theta);
  c.acc_lim_x = lim.acc_lim_x;
  c.acc_lim_y = lim.acc_lim_y;
  c.acc_lim_theta = lim.acc_lim_theta;
}
}  // namespace mbot_navigation
