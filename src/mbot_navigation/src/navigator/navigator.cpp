#include "mbot_navigation/navigator/navigator.h"

#include <cmath>
#include <cstdio>
#include <stdexcept>

namespace mbot_navigation
{
namespace
{
std::string join(const std::vector<std::string>& items)
{
  std::string out;
  for (const std::string& s : items) out += (out.empty() ? "" : ", ") + s;
  return out;
}

double pathLength(const std::vector<Pose2D>& path)
{
  double length = 0.0;
  for (size_t i = 1; i < path.size(); ++i) length += std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  return length;
}
}  // namespace

const char* toString(NavState state)
{
  switch (state)
  {
    case NavState::IDLE: return "IDLE";
    case NavState::PLANNING: return "PLANNING";
    case NavState::CONTROLLING: return "CONTROLLING";
    case NavState::RECOVERING: return "RECOVERING";
  }
  return "?";
}

Navigator::Navigator(const NavigatorConfig& config, std::unique_ptr<LocalPlanner> local_planner,
                     std::unique_ptr<GlobalPlanner> planner, std::vector<std::unique_ptr<RecoveryBehavior>> recoveries)
    : config_(config),
      planner_(std::move(planner)),
      local_planner_(std::move(local_planner)),
      recoveries_(std::move(recoveries))
{
  if (!planner_) throw std::invalid_argument("Navigator: no global planner");
  if (!local_planner_) throw std::invalid_argument("Navigator: no local planner");
  if (!(config.planner_patience >= 0.0) || !(config.controller_patience >= 0.0) || !(config.planner_frequency >= 0.0) ||
      !(config.oscillation_timeout >= 0.0))
    throw std::invalid_argument(
        "Navigator: planner_patience, controller_patience, planner_frequency and oscillation_timeout must be >= 0");
}

void Navigator::setLocalPlanner(std::unique_ptr<LocalPlanner> local_planner)
{
  if (!local_planner) throw std::invalid_argument("Navigator: no local planner");
  if (!plan_.empty()) local_planner->setPlan(plan_);
  local_planner_ = std::move(local_planner);
}

void Navigator::setGoal(const Pose2D& goal, double now)
{
  goal_ = goal;
  state_ = NavState::PLANNING;
  plan_.clear();
  local_plan_.poses.clear();
  plan_needed_since_ = now;
  last_valid_control_ = now;
  last_progress_time_ = now;
  progress_pose_set_ = false;
  recovery_index_ = 0;
  tried_.clear();
  last_error_.clear();
}

void Navigator::cancel()
{
  state_ = NavState::IDLE;
  plan_.clear();
  local_plan_.poses.clear();
}

long Navigator::firstBlockedPose(const Costmap2D& costmap, const std::vector<Pose2D>& plan, size_t from,
                                 bool allow_unknown)
{
  for (size_t i = from; i < plan.size(); ++i)
  {
    unsigned mx, my;
    if (!costmap.worldToMap(plan[i].x, plan[i].y, mx, my)) continue;
    const uint8_t c = costmap.cost(mx, my);
    if (c >= cost::INSCRIBED && !(allow_unknown && c == cost::NO_INFORMATION)) return static_cast<long>(i);
  }
  return -1;
}

PlanResult Navigator::makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal)
{
  unsigned sx, sy;
  if (!costmap.worldToMap(start.x, start.y, sx, sy) || passable(costmap.cost(sx, sy)))
    return planner_->makePlan(costmap, start, goal);

  // The robot stands in an impassable cell: plan from the nearest passable cell instead.
  const int r = static_cast<int>(std::ceil(config_.start_escape_radius / costmap.resolution()));
  double best = config_.start_escape_radius;
  bool found = false;
  Pose2D escape = start;
  for (int dy = -r; dy <= r; ++dy)
    for (int dx = -r; dx <= r; ++dx)
    {
      const int mx = static_cast<int>(sx) + dx, my = static_cast<int>(sy) + dy;
      if (!costmap.inBounds(mx, my) || !passable(costmap.cost(mx, my))) continue;
      double wx, wy;
      costmap.mapToWorld(mx, my, wx, wy);
      const double d = std::hypot(wx - start.x, wy - start.y);
      if (d > best) continue;
      best = d;
      escape.x = wx;
      escape.y = wy;
      found = true;
    }
  if (!found) return planner_->makePlan(costmap, start, goal);  // let the planner say why
  PlanResult result = planner_->makePlan(costmap, escape, goal);
  if (result.ok) result.path.insert(result.path.begin(), start);
  return result;
}

bool Navigator::replan(const Costmap2D& global_costmap, const Pose2D& pose, double now, std::string& error)
{
  PlanResult result = makePlan(global_costmap, pose, goal_);
  if (!result.ok || result.path.empty())
  {
    error = result.ok ? "the planner returned an empty path" : result.error;
    last_error_ = "global planner: " + error;
    return false;
  }
  plan_ = std::move(result.path);
  local_planner_->setPlan(plan_);
  last_plan_time_ = now;
  return true;
}

NavCycleResult Navigator::finish(NavOutcome outcome, const std::string& text)
{
  state_ = NavState::IDLE;
  plan_.clear();
  NavCycleResult result;
  result.outcome = outcome;
  result.text = text;
  result.plan_updated = true;  // the plan is gone
  return result;
}

NavCycleResult Navigator::recover(const std::string& reason, const RecoveryInput& input)
{
  if (config_.recovery_behavior_enabled && recovery_index_ < recoveries_.size())
  {
    state_ = NavState::RECOVERING;
    recoveries_[recovery_index_]->start(input);
    NavCycleResult result;
    result.outcome = NavOutcome::ACTIVE;
    return result;
  }
  std::string text = reason;
  if (!tried_.empty())
    text += "; recoveries tried: " + join(tried_);
  else if (!config_.recovery_behavior_enabled)
    text += " (recovery behaviours are disabled)";
  return finish(NavOutcome::ABORTED, text);
}

NavCycleResult Navigator::cycle(double now, const Pose2D& pose, const Twist2D& velocity,
                                const Costmap2D& global_costmap, const Costmap2D& local_costmap)
{
  NavCycleResult result;
  local_plan_.poses.clear();
  if (state_ == NavState::IDLE) return result;
  result.outcome = NavOutcome::ACTIVE;
  const RecoveryInput input{now, pose, velocity, &local_costmap};

  // Progress: moving oscillation_distance restarts the oscillation clock and the recovery list.
  if (!progress_pose_set_)
  {
    progress_pose_ = pose;
    progress_pose_set_ = true;
    last_progress_time_ = now;
  }
  else if (std::hypot(pose.x - progress_pose_.x, pose.y - progress_pose_.y) >= config_.oscillation_distance)
  {
    progress_pose_ = pose;
    last_progress_time_ = now;
    if (state_ != NavState::RECOVERING)
    {
      recovery_index_ = 0;
      tried_.clear();
    }
  }

  if (state_ == NavState::RECOVERING)
  {
    RecoveryBehavior& behaviour = *recoveries_[recovery_index_];
    const RecoveryStatus status = behaviour.step(input, result.cmd);
    if (status == RecoveryStatus::RUNNING) return result;
    tried_.push_back(status == RecoveryStatus::DONE ? behaviour.name()
                                                    : behaviour.name() + " (failed: " + behaviour.message() + ")");
    ++recovery_index_;
    // Plan and drive again, with fresh patience.
    state_ = NavState::PLANNING;
    plan_needed_since_ = now;
    last_valid_control_ = now;
    last_progress_time_ = now;
    progress_pose_ = pose;
    result.cmd = Twist2D{};
  }

  if (state_ == NavState::PLANNING)
  {
    std::string error;
    if (!replan(global_costmap, pose, now, error))
    {
      if (now - plan_needed_since_ > config_.planner_patience)
      {
        char buf[96];
        std::snprintf(buf, sizeof(buf),
                      "the global planner (%s) found no valid plan for %.1f s: ", planner_->name().c_str(),
                      config_.planner_patience);
        return recover(buf + error, input);
      }
      return result;  // stand still, try again next cycle
    }
    result.plan_updated = true;
    state_ = NavState::CONTROLLING;
  }
  return control(now, pose, velocity, global_costmap, local_costmap, result);
}

NavCycleResult Navigator::control(double now, const Pose2D& pose, const Twist2D& velocity,
                                  const Costmap2D& global_costmap, const Costmap2D& local_costmap,
                                  NavCycleResult result)
{
  const RecoveryInput input{now, pose, velocity, &local_costmap};

  // 1. Replan when the plan ahead became impassable, or periodically. Poses under the robot's own
  //    footprint do not count: the robot may stand close to something that it is leaving.
  const std::vector<Pose2D>& ahead = local_planner_->plan();
  size_t from = 0;
  const double own = local_planner_->footprintRadius();
  while (from < ahead.size() && std::hypot(ahead[from].x - pose.x, ahead[from].y - pose.y) <= own) ++from;
  const bool blocked = firstBlockedPose(global_costmap, ahead, from, config_.allow_unknown) >= 0;
  const bool periodic = !blocked && config_.planner_frequency > 0.0 &&
                        now - last_plan_time_ >= 1.0 / config_.planner_frequency &&
                        pathLength(ahead) > 1.0;  // near the goal a new plan would only disturb the approach
  if (blocked || periodic)
  {
    std::string error;
    if (replan(global_costmap, pose, now, error))
      result.plan_updated = true;
    else if (blocked)
    {
      // The way ahead is closed and there is no other (yet): stand still and keep trying.
      state_ = NavState::PLANNING;
      plan_needed_since_ = now;
      result.cmd = Twist2D{};
      return result;
    }
    else
      last_plan_time_ = now;  // periodic replanning failed: keep the old (still free) plan
  }

  // 2. Arrived?
  if (local_planner_->isGoalReached(pose, velocity)) return finish(NavOutcome::SUCCEEDED, "");

  // 3. Oscillation: not moving for too long.
  if (config_.oscillation_timeout > 0.0 && now - last_progress_time_ > config_.oscillation_timeout)
  {
    char buf[128];
    std::snprintf(buf, sizeof(buf), "the robot moved less than %.2f m in %.1f s (oscillating)",
                  config_.oscillation_distance, config_.oscillation_timeout);
    return recover(buf, input);
  }

  // 4. The local planner.
  Twist2D cmd;
  const LocalPlanResult local = local_planner_->computeVelocityCommands(pose, velocity, local_costmap, cmd);
  if (local.ok)
  {
    last_valid_control_ = now;
    local_plan_ = local.trajectory;
    result.cmd = cmd;
    return result;
  }
  result.cmd = Twist2D{};
  last_error_ = "local planner: " + local.error;
  if (now - last_valid_control_ > config_.controller_patience)
  {
    char buf[128];
    std::snprintf(buf, sizeof(buf),
                  "the local planner (%s) found no valid velocity command for %.1f s: ", local_planner_->name().c_str(),
                  config_.controller_patience);
    return recover(buf + local.error, input);
  }
  // As move_base: stand still and plan again (the plan may be what the local planner cannot follow).
  state_ = NavState::PLANNING;
  plan_needed_since_ = now;
  return result;
}

}  // namespace mbot_navigation
