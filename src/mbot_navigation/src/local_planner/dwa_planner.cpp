#include "mbot_navigation/local_planner/dwa_planner.h"

#include <algorithm>
#include <cmath>
#include <sstream>

namespace mbot_navigation
{
namespace
{
constexpr double kPruneDistance = 1.0;  // [m] see prunePlan()
constexpr double kMinApproach = 0.005;  // [m] a trajectory closer to the goal by less makes no progress

/// The config, after checking it (so that no member is built from a bad one).
const DwaConfig& validated(const DwaConfig& config)
{
  config.validate();
  return config;
}
}  // namespace

DwaPlanner::DwaPlanner(const DwaConfig& config)
    : config_(validated(config)),
      generator_(config),
      obstacle_critic_(config.occdist_scale, config.footprint_radius),
      oscillation_critic_(config.oscillation_reset_dist, config.oscillation_reset_angle),
      path_critic_(config.path_distance_bias),
      goal_critic_(config.goal_distance_bias),
      path_align_critic_(config.path_distance_bias, config.forward_point_distance),
      goal_align_critic_(config.goal_distance_bias, config.forward_point_distance),
      twirling_critic_(config.twirling_scale)
{
  // Scoring order: the cheap critics that reject most come first, so that the early exit in
  // scoreTrajectory() saves the most work.
  critics_ = {&oscillation_critic_, &obstacle_critic_,   &path_critic_,    &goal_critic_,
              &path_align_critic_,  &goal_align_critic_, &twirling_critic_};
}

void DwaPlanner::setPlan(const std::vector<Pose2D>& plan)
{
  // The nav node replans periodically (planner_frequency): a new plan to the same goal must not
  // interrupt the final approach (the latch, the rotation in place), only a new goal does.
  const bool same_goal = !plan_.empty() && !plan.empty() && sameGoal(plan_.back(), plan.back());
  plan_ = plan;
  oscillation_critic_.reset();  // as dwa_local_planner: the new plan may lead the other way
  if (same_goal) return;
  stopping_at_goal_ = false;
  rotating_to_goal_ = false;
}

bool DwaPlanner::sameGoal(const Pose2D& a, const Pose2D& b)
{
  constexpr double kSamePosition = 0.01;  // [m]
  constexpr double kSameYaw = 0.01;       // [rad]
  return std::hypot(a.x - b.x, a.y - b.y) <= kSamePosition &&
         std::fabs(mbot_common::angleDiff(a.theta, b.theta)) <= kSameYaw;
}

void DwaPlanner::prunePlan(const Pose2D& robot_pose)
{
  const auto near = std::find_if(plan_.begin(), plan_.end(), [&](const Pose2D& p) {
    return std::hypot(p.x - robot_pose.x, p.y - robot_pose.y) < kPruneDistance;
  });
  if (near != plan_.end()) plan_.erase(plan_.begin(), near);
}

double DwaPlanner::goalDistance(const Pose2D& pose) const
{
  const Pose2D& goal = plan_.back();
  return std::hypot(goal.x - pose.x, goal.y - pose.y);
}

bool DwaPlanner::positionReached(const Pose2D& robot_pose) const
{
  if (config_.latch_xy_goal_tolerance && stopping_at_goal_) return true;  // latched at the goal position
  // Braking starts within half the tolerance (where the trajectories aim, truncateAtGoal), and
  // the stop holds while the robot stays within the tolerance. Braking at the edge of the
  // tolerance would leave the robot there, where its localization error alone (a few cm)
  // decides whether it truly is within the tolerance.
  const double radius = stopping_at_goal_ ? config_.xy_goal_tolerance : 0.5 * config_.xy_goal_tolerance;
  return goalDistance(robot_pose) <= radius;
}

bool DwaPlanner::isGoalReached(const Pose2D& robot_pose, const Twist2D& robot_velocity) const
{
  if (plan_.empty() || !positionReached(robot_pose)) return false;
  const double yaw_error = mbot_common::angleDiff(plan_.back().theta, robot_pose.theta);
  const bool stopped = std::fabs(robot_velocity.vx) <= config_.trans_stopped_vel &&
                       std::fabs(robot_velocity.vy) <= config_.trans_stopped_vel &&
                       std::fabs(robot_velocity.wz) <= config_.theta_stopped_vel;
  return std::fabs(yaw_error) <= config_.yaw_goal_tolerance && stopped;
}

LocalPlanResult DwaPlanner::computeVelocityCommands(const Pose2D& robot_pose, const Twist2D& robot_velocity,
                                                    const Costmap2D& costmap, Twist2D& cmd)
{
  cmd = Twist2D{};
  const LocalPlanResult result = controlCycle(robot_pose, robot_velocity, costmap, cmd);
  last_cmd_ = cmd;  // zero when the cycle failed: the nav node then commands zero
  return result;
}

LocalPlanResult DwaPlanner::controlCycle(const Pose2D& robot_pose, const Twist2D& robot_velocity,
                                         const Costmap2D& costmap, Twist2D& cmd)
{
  if (plan_.empty())
  {
    LocalPlanResult result;
    result.error = "no global plan (setPlan was not called, or with an empty plan)";
    return result;
  }
  if (config_.prune_plan) prunePlan(robot_pose);

  const CriticContext context{costmap, plan_, robot_pose, robot_velocity};
  std::string error;
  if (positionReached(robot_pose))
  {
    stopping_at_goal_ = true;
    obstacle_critic_.prepare(context, error);  // only the collision check is needed here
    return stopAndRotate(robot_pose, robot_velocity, cmd);
  }
  stopping_at_goal_ = false;  // (pushed) out of the goal area: drive again
  rotating_to_goal_ = false;

  for (TrajectoryCritic* critic : critics_)
  {
    if (!isActive(*critic)) continue;
    if (!critic->prepare(context, error))
    {
      LocalPlanResult result;
      result.error = critic->name() + " critic: " + error;
      return result;
    }
  }
  LocalPlanResult result = followPlan(robot_pose, robot_velocity, cmd);
  // Within the tolerance but not within half of it: stop here after all when the best
  // trajectory would not bring the robot closer (an obstacle, or the goal in the inflation).
  const double distance = goalDistance(robot_pose);
  if (result.ok && distance <= config_.xy_goal_tolerance && !result.trajectory.poses.empty() &&
      goalDistance(result.trajectory.poses.back()) >= distance - kMinApproach)
  {
    stopping_at_goal_ = true;
    return stopAndRotate(robot_pose, robot_velocity, cmd);
  }
  return result;
}

bool DwaPlanner::isActive(const TrajectoryCritic& critic) const
{
  // A critic with scale 0 is skipped (as dwa_local_planner does), except the obstacle critic:
  // occdist_scale 0 only means "do not prefer clearance", never "drive through walls".
  return critic.scale() != 0.0 || &critic == &obstacle_critic_;
}

void DwaPlanner::truncateAtGoal(Trajectory& trajectory) const
{
  if (trajectory.poses.empty()) return;
  const Pose2D& goal = plan_.back();
  const double tolerance = 0.5 * config_.xy_goal_tolerance;
  // Most trajectories end far from the goal: skip them without looking at every pose.
  const Pose2D& start = trajectory.poses.front();
  const double reach = std::hypot(trajectory.velocity.vx, trajectory.velocity.vy) * config_.sim_time;
  if (std::hypot(goal.x - start.x, goal.y - start.y) > reach + tolerance) return;
  for (size_t i = 0; i < trajectory.poses.size(); ++i)
  {
    const double dx = trajectory.poses[i].x - goal.x;
    const double dy = trajectory.poses[i].y - goal.y;
    if (dx * dx + dy * dy <= tolerance * tolerance)
    {
      trajectory.poses.resize(i + 1);
      return;
    }
  }
}

double DwaPlanner::scoreTrajectory(const Trajectory& trajectory, double best, int& rejected_by)
{
  double total = 0.0;
  for (size_t i = 0; i < critics_.size(); ++i)
  {
    TrajectoryCritic& critic = *critics_[i];
    if (!isActive(critic)) continue;
    const double score = critic.score(trajectory);
    if (score < 0.0)
    {
      rejected_by = static_cast<int>(i);
      return score;
    }
    total += score * critic.scale();
    if (best >= 0.0 && total > best) break;  // cannot beat the best one any more
  }
  return total;
}

LocalPlanResult DwaPlanner::followPlan(const Pose2D& robot_pose, const Twist2D& robot_velocity, Twist2D& cmd)
{
  LocalPlanResult result;
  result.state = LocalPlannerState::FOLLOWING;
  generator_.initialise(robot_velocity);

  std::vector<int> rejections(critics_.size(), 0);
  best_.cost = -1.0;
  best_.poses.clear();
  for (const Twist2D& sample : generator_.samples())
  {
    if (!generator_.generate(robot_pose, sample, candidate_)) continue;  // too slow or too fast
    truncateAtGoal(candidate_);
    ++result.samples;
    int rejected_by = -1;
    const double cost = scoreTrajectory(candidate_, best_.cost, rejected_by);
    if (cost < 0.0)
    {
      ++rejections[rejected_by];
      continue;
    }
    if (best_.cost < 0.0 || cost < best_.cost)
    {
      candidate_.cost = cost;
      std::swap(best_, candidate_);  // keeps both buffers' capacity
    }
  }

  oscillation_critic_.update(robot_pose, best_, config_.min_vel_trans);
  result.trajectory = best_;
  if (best_.cost < 0.0 && result.samples == 0)
  {
    result.error = "no valid trajectory: no admissible velocity in the dynamic window";
    return result;  // cmd stays zero
  }
  if (best_.cost < 0.0)
  {
    std::ostringstream msg;
    msg << "no valid trajectory: " << result.samples << " samples, rejected by";
    const char* sep = " ";
    for (size_t i = 0; i < critics_.size(); ++i)
    {
      if (rejections[i] == 0) continue;
      msg << sep << critics_[i]->name() << ": " << rejections[i];
      sep = ", ";
    }
    result.error = msg.str();
    return result;  // cmd stays zero
  }
  cmd = best_.velocity;
  result.ok = true;
  return result;
}

double DwaPlanner::slower(double measured, double commanded)
{
  if (measured * commanded <= 0.0) return 0.0;  // standing, or one of them says the other way
  return std::fabs(measured) < std::fabs(commanded) ? measured : commanded;
}

LocalPlanResult DwaPlanner::stopAndRotate(const Pose2D& robot_pose, const Twist2D& robot_velocity, Twist2D& cmd)
{
  LocalPlanResult result;
  const double dt = config_.simPeriod();
  const double yaw_error = mbot_common::angleDiff(plan_.back().theta, robot_pose.theta);

  // The gentlest stop the acceleration limits allow; translation always ends with it here. It
  // starts from the slower of the measured velocity and the last command: from the measured one
  // alone, noisy odometry steers the "brake" (with mbot_sim's noise a robot in the goal area sped
  // up from 0.08 to 0.44 m/s and left it). So the braking commands never grow.
  Twist2D brake;
  brake.vx = stepTowards(slower(robot_velocity.vx, last_cmd_.vx), 0.0, config_.acc_lim_x * dt);
  brake.vy = stepTowards(slower(robot_velocity.vy, last_cmd_.vy), 0.0, config_.acc_lim_y * dt);
  brake.wz = stepTowards(slower(robot_velocity.wz, last_cmd_.wz), 0.0, config_.acc_lim_theta * dt);
  const bool stopped = std::fabs(robot_velocity.vx) <= config_.trans_stopped_vel &&
                       std::fabs(robot_velocity.vy) <= config_.trans_stopped_vel &&
                       std::fabs(robot_velocity.wz) <= config_.theta_stopped_vel;

  Twist2D command = brake;
  if (std::fabs(yaw_error) <= config_.yaw_goal_tolerance)
  {
    result.state = LocalPlannerState::ARRIVED;
    rotating_to_goal_ = false;
  }
  else if (!rotating_to_goal_ && !stopped)
  {
    result.state = LocalPlannerState::STOPPING;
  }
  else
  {
    result.state = LocalPlannerState::ROTATING;
    rotating_to_goal_ = true;
    // Turn as fast as allowed, but no faster than lets us stop at the goal yaw
    // (v^2 = 2 a d), and not so slowly that the base stalls (min_vel_theta).
    double speed = std::min(config_.max_vel_theta, std::sqrt(2.0 * config_.acc_lim_theta * std::fabs(yaw_error)));
    speed = std::max(speed, config_.min_vel_theta);
    command.wz = stepTowards(robot_velocity.wz, std::copysign(speed, yaw_error), config_.acc_lim_theta * dt);
  }

  // The command must leave the robot clear of obstacles until it has braked to a stop.
  generator_.generateBraking(robot_pose, command, result.trajectory);
  const double clearance = obstacle_critic_.score(result.trajectory);
  result.trajectory.cost = clearance;
  if (clearance < 0.0)
  {
    result.error = "at the goal position, but stopping or turning there would collide";
    return result;  // cmd stays zero
  }
  cmd = command;
  result.ok = true;
  return result;
}

}  // namespace mbot_navigation
