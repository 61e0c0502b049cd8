#include "mbot_navigation/navigator/recovery.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

namespace mbot_navigation
{
namespace
{
constexpr double kTwoPi = 6.283185307179586;
}  // namespace

// ---------------------------------------------------------------------------------------------

RecoveryStatus ClearCostmapsRecovery::step(const RecoveryInput&, Twist2D& cmd)
{
  cmd = Twist2D{};
  if (clear_) clear_();
  return RecoveryStatus::DONE;
}

// ---------------------------------------------------------------------------------------------

void RotateRecovery::start(const RecoveryInput& input)
{
  message_.clear();
  start_time_ = input.now;
  last_yaw_ = input.pose.theta;
  turned_ = 0.0;
  last_cmd_ = input.velocity.wz;
}

RecoveryStatus RotateRecovery::step(const RecoveryInput& input, Twist2D& cmd)
{
  cmd = Twist2D{};
  // Count the turn from the measured yaw (what the robot really did, not what we asked).
  turned_ += mbot_common::angleDiff(input.pose.theta, last_yaw_);
  last_yaw_ = input.pose.theta;
  const double remaining = kTwoPi - config_.tolerance - turned_;
  if (remaining <= 0.0) return RecoveryStatus::DONE;
  if (input.now - start_time_ > config_.timeout)
  {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "turned only %.2f of %.2f rad in %.1f s", turned_, kTwoPi, config_.timeout);
    message_ = buf;
    return RecoveryStatus::FAILED;
  }
  // Trapezoidal profile: no faster than the limit, than we can still brake from over the
  // remaining angle, or than one period of acceleration from the last command.
  double w = std::min(config_.max_vel_theta, std::sqrt(2.0 * config_.acc_lim_theta * remaining));
  w = std::min(w, std::max(last_cmd_, 0.0) + config_.acc_lim_theta * config_.control_period);
  w = std::max(w, config_.min_vel_theta);
  last_cmd_ = w;
  cmd.wz = w;
  return RecoveryStatus::RUNNING;
}

// ---------------------------------------------------------------------------------------------

double BackUpRecovery::freeDistanceBehind(const Costmap2D& costmap, const Pose2D& pose, double distance,
                                          double footprint_radius)
{
  const double step = 0.5 * costmap.resolution();
  const double cx = std::cos(pose.theta), sy = std::sin(pose.theta);
  // The robot may already touch something in front of it or at its side: only cells behind the
  // line through its centre, across its heading, can be met while backing up.
  const double res = costmap.resolution();
  const int r = static_cast<int>(std::ceil(footprint_radius / res));
  double free = 0.0;
  for (int i = 1;; ++i)
  {
    const double d = std::min(i * step, distance);
    const double x = pose.x - d * cx, y = pose.y - d * sy;
    unsigned mx0, my0;
    if (!costmap.worldToMap(x, y, mx0, my0)) return free;
    bool hit = false;
    for (int dy = -r; dy <= r && !hit; ++dy)
      for (int dx = -r; dx <= r && !hit; ++dx)
      {
        const int mx = static_cast<int>(mx0) + dx, my = static_cast<int>(my0) + dy;
        if (!costmap.inBounds(mx, my) || costmap.cost(mx, my) != cost::LETHAL) continue;
        double wx, wy;
        costmap.mapToWorld(mx, my, wx, wy);
        const bool under = std::hypot(wx - x, wy - y) <= footprint_radius;
        const bool behind_start = (wx - pose.x) * cx + (wy - pose.y) * sy < 0.0;
        hit = under && behind_start;
      }
    if (hit) return free;
    free = d;
    if (d >= distance) return free;
  }
}

void BackUpRecovery::start(const RecoveryInput& input)
{
  message_.clear();
  start_pose_ = input.pose;
  start_time_ = input.now;
  target_ = input.local_costmap
                ? freeDistanceBehind(*input.local_costmap, input.pose, config_.distance, config_.footprint_radius)
                : 0.0;
}

RecoveryStatus BackUpRecovery::step(const RecoveryInput& input, Twist2D& cmd)
{
  cmd = Twist2D{};
  char buf[128];
  if (target_ < 0.05)
  {
    std::snprintf(buf, sizeof(buf), "no room to back up (%.2f m free behind the robot)", target_);
    message_ = buf;
    return RecoveryStatus::FAILED;
  }
  const double moved = std::hypot(input.pose.x - start_pose_.x, input.pose.y - start_pose_.y);
  if (moved >= target_) return RecoveryStatus::DONE;
  if (input.now - start_time_ > config_.timeout)
  {
    std::snprintf(buf, sizeof(buf), "backed up only %.2f of %.2f m in %.1f s", moved, target_, config_.timeout);
    message_ = buf;
    return RecoveryStatus::FAILED;
  }
  // Re-check the way behind on the updated costmap (something may have moved in).
  if (input.local_costmap && freeDistanceBehind(*input.local_costmap, input.pose, std::min(0.1, target_ - moved),
                                                config_.footprint_radius) < std::min(0.1, target_ - moved) - 1e-9)
  {
    std::snprintf(buf, sizeof(buf), "an obstacle appeared behind the robot after %.2f m", moved);
    message_ = buf;
    return RecoveryStatus::FAILED;
  }
  cmd.vx = -config_.speed;
  return RecoveryStatus::RUNNING;
}

}  // namespace mbot_navigation
