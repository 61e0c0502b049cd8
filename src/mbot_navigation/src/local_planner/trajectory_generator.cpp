#include "mbot_navigation/local_planner/trajectory_generator.h"

#include <algorithm>
#include <cmath>

namespace mbot_navigation
{
namespace
{
constexpr double kEps = 1e-4;  // tolerance of the velocity limit checks, as base_local_planner's
}  // namespace

double stepTowards(double v, double target, double max_step)
{
  return v < target ? std::min(target, v + max_step) : std::max(target, v - max_step);
}

Pose2D integratePose(const Pose2D& pose, const Twist2D& velocity, double dt)
{
  const double c = std::cos(pose.theta);
  const double s = std::sin(pose.theta);
  Pose2D next;
  next.x = pose.x + (velocity.vx * c - velocity.vy * s) * dt;
  next.y = pose.y + (velocity.vx * s + velocity.vy * c) * dt;
  next.theta = pose.theta + velocity.wz * dt;
  return next;
}

TrajectoryGenerator::TrajectoryGenerator(const DwaConfig& config)
    : config_(config), min_vel_trans_(config.min_vel_trans), min_vel_theta_(config.min_vel_theta)
{}

std::vector<double> TrajectoryGenerator::sampleRange(double min, double max, int num_samples)
{
  std::vector<double> samples;
  if (min >= max)
  {
    samples.push_back(min);
    return samples;
  }
  num_samples = std::max(2, num_samples);
  const double step = (max - min) / (num_samples - 1);
  for (int i = 0; i < num_samples - 1; ++i)
  {
    const double current = min + i * step;
    const double next = current + step;
    samples.push_back(current);
    if (current < 0.0 && next > 0.0) samples.push_back(0.0);
  }
  samples.push_back(max);  // exactly max, free of rounding
  return samples;
}

void TrajectoryGenerator::initialise(const Twist2D& measured)
{
  const double dt = config_.simPeriod();
  // Noisy odometry can read a little above a limit (0.58 m/s at 0.5 m/s); the window is built
  // from the fastest speed the limits allow, else no sample stays within them and the robot
  // would get a zero command for that cycle.
  Twist2D velocity = measured;
  velocity.vx = std::min(std::max(velocity.vx, config_.min_vel_x), config_.max_vel_x);
  velocity.vy = std::min(std::max(velocity.vy, config_.min_vel_y), config_.max_vel_y);
  velocity.wz = std::min(std::max(velocity.wz, -config_.max_vel_theta), config_.max_vel_theta);
  // The dynamic window: what one control period of acceleration can reach, within the limits.
  const double max_vx = std::min(config_.max_vel_x, velocity.vx + config_.acc_lim_x * dt);
  const double min_vx = std::max(config_.min_vel_x, velocity.vx - config_.acc_lim_x * dt);
  double max_vy = config_.max_vel_y;
  double min_vy = config_.min_vel_y;
  if (max_vy > min_vy)  // an omni robot; a diff-drive robot keeps its single v_y sample
  {
    max_vy = std::min(max_vy, velocity.vy + config_.acc_lim_y * dt);
    min_vy = std::max(min_vy, velocity.vy - config_.acc_lim_y * dt);
  }
  const double max_vth = std::min(config_.max_vel_theta, velocity.wz + config_.acc_lim_theta * dt);
  const double min_vth = std::max(-config_.max_vel_theta, velocity.wz - config_.acc_lim_theta * dt);

  const auto xs = sampleRange(min_vx, max_vx, config_.vx_samples);
  const auto ys = sampleRange(min_vy, max_vy, config_.vy_samples);
  const auto ths = sampleRange(min_vth, max_vth, config_.vth_samples);

  samples_.clear();
  samples_.reserve(xs.size() * ys.size() * ths.size());
  double fastest_trans = 0.0;
  double fastest_theta = 0.0;
  for (double vx : xs)
    for (double vy : ys)
      for (double vth : ths)
      {
        samples_.push_back(Twist2D{vx, vy, vth});
        fastest_trans = std::max(fastest_trans, std::hypot(vx, vy));
        fastest_theta = std::max(fastest_theta, std::fabs(vth));
      }
  // dwa_local_planner rejects every sample slower than both minimum speeds. A robot whose
  // acceleration cannot reach them within one period (mbot from rest: 0.05 m/s, 0.15 rad/s)
  // would then never start, so the minimums are lowered to what the window can reach.
  min_vel_trans_ = std::min(config_.min_vel_trans, fastest_trans);
  min_vel_theta_ = std::min(config_.min_vel_theta, fastest_theta);
}

bool TrajectoryGenerator::isAdmissible(const Twist2D& sample) const
{
  const double vmag = std::hypot(sample.vx, sample.vy);
  // Too slow both ways: such a sample would hardly move the robot (a real base stalls).
  if (vmag + kEps < min_vel_trans_ && std::fabs(sample.wz) + kEps < min_vel_theta_) return false;
  return vmag - kEps <= config_.max_vel_trans;
}

bool TrajectoryGenerator::generate(const Pose2D& pose, const Twist2D& sample, Trajectory& trajectory) const
{
  trajectory.velocity = sample;
  trajectory.cost = -1.0;
  trajectory.poses.clear();
  if (!isAdmissible(sample)) return false;

  // Enough steps that no step moves more than sim_granularity or turns more than
  // angular_sim_granularity, so that no obstacle cell is stepped over.
  const double distance = std::hypot(sample.vx, sample.vy) * config_.sim_time;
  const double angle = std::fabs(sample.wz) * config_.sim_time;
  const int steps = std::max(1, static_cast<int>(std::ceil(std::max(distance / config_.sim_granularity,
                                                                    angle / config_.angular_sim_granularity))));
  const double dt = config_.sim_time / steps;
  trajectory.time_delta = dt;

  // Euler steps, as integratePose() but without a sine and cosine per step: the heading turns
  // by the same angle every step, so its unit vector (c, s) is rotated by that angle instead.
  const double dth = sample.wz * dt;
  const double cd = std::cos(dth);
  const double sd = std::sin(dth);
  double c = std::cos(pose.theta);
  double s = std::sin(pose.theta);
  Pose2D p = pose;
  trajectory.poses.reserve(steps + 1);
  trajectory.poses.push_back(p);
  for (int i = 0; i < steps; ++i)
  {
    p.x += (sample.vx * c - sample.vy * s) * dt;
    p.y += (sample.vx * s + sample.vy * c) * dt;
    p.theta += dth;
    const double c_next = c * cd - s * sd;
    s = s * cd + c * sd;
    c = c_next;
    trajectory.poses.push_back(p);
  }
  return true;
}

void TrajectoryGenerator::generateBraking(const Pose2D& pose, const Twist2D& command, Trajectory& trajectory) const
{
  trajectory.velocity = command;
  trajectory.cost = -1.0;
  trajectory.poses.clear();

  // Small time steps so that a step stays below sim_granularity even at full speed.
  const double top_speed = std::max(config_.max_vel_trans, std::hypot(command.vx, command.vy));
  const double dt = std::min(config_.simPeriod(), config_.sim_granularity / top_speed);
  trajectory.time_delta = dt;

  Pose2D p = pose;
  trajectory.poses.push_back(p);
  Twist2D v = command;
  double t = 0.0;
  const double max_time = config_.simPeriod() + config_.sim_time;  // bounds the loop
  while (t < max_time)
  {
    if (t >= config_.simPeriod())  // after the first period: brake
    {
      v.vx = stepTowards(v.vx, 0.0, config_.acc_lim_x * dt);
      v.vy = stepTowards(v.vy, 0.0, config_.acc_lim_y * dt);
      v.wz = stepTowards(v.wz, 0.0, config_.acc_lim_theta * dt);
      if (v.vx == 0.0 && v.vy == 0.0 && v.wz == 0.0) break;
    }
    p = integratePose(p, v, dt);
    trajectory.poses.push_back(p);
    t += dt;
  }
}

}  // namespace mbot_navigation
