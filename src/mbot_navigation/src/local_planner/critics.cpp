#include "mbot_navigation/local_planner/critics.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>

namespace mbot_navigation
{
namespace
{
// Rejection codes (negative scores), as base_local_planner's critics return them.
constexpr double kOffMap = -4.0;
constexpr double kThroughObstacle = -3.0;  // also: footprint over a lethal cell
constexpr double kUnreachable = -2.0;
constexpr double kReversal = -5.0;
}  // namespace

// ---------------------------------------------------------------------------------------------
// ObstacleCritic

ObstacleCritic::ObstacleCritic(double scale, double footprint_radius)
    : TrajectoryCritic(scale), footprint_radius_(footprint_radius)
{}

bool ObstacleCritic::prepare(const CriticContext& context, std::string& /*error*/)
{
  costmap_ = &context.costmap;
  const double res = costmap_->resolution();
  if (res != offsets_resolution_)
  {
    // The footprint is on a cell when the disc overlaps the cell's square (an obstacle may be
    // anywhere in it). For a robot centred anywhere in cell (0, 0), that is possible for the
    // cells (dx, dy) whose square lies closer than the radius to cell (0, 0)'s square, i.e.
    // |(max(0, |dx| - 1), max(0, |dy| - 1))| * resolution < radius: never optimistic.
    const double reach = footprint_radius_ / res;  // [cells]
    const int r = static_cast<int>(std::ceil(reach)) + 1;
    disc_offsets_.clear();
    for (int dy = -r; dy <= r; ++dy)
      for (int dx = -r; dx <= r; ++dx)
      {
        const double gx = std::max(0, std::abs(dx) - 1);
        const double gy = std::max(0, std::abs(dy) - 1);
        if (gx * gx + gy * gy < reach * reach) disc_offsets_.emplace_back(dx, dy);
      }
    offsets_resolution_ = res;
  }
  lethal_memo_.assign(static_cast<size_t>(costmap_->sizeX()) * costmap_->sizeY(), 0);
  return true;
}

bool ObstacleCritic::footprintHitsLethal(unsigned mx, unsigned my)
{
  uint8_t& memo = lethal_memo_[costmap_->index(mx, my)];
  if (memo != 0) return memo == 2;
  const int sx = static_cast<int>(costmap_->sizeX());
  const int sy = static_cast<int>(costmap_->sizeY());
  bool hit = false;
  for (const auto& d : disc_offsets_)
  {
    const int x = static_cast<int>(mx) + d.first;
    const int y = static_cast<int>(my) + d.second;
    // Cells beyond the map's edge are unknown to us; the centre check keeps the robot inside.
    if (x < 0 || y < 0 || x >= sx || y >= sy) continue;
    if (costmap_->cost(x, y) == cost::LETHAL)
    {
      hit = true;
      break;
    }
  }
  memo = hit ? 2 : 1;
  return hit;
}

double ObstacleCritic::poseCost(double x, double y)
{
  unsigned mx, my;
  if (!costmap_->worldToMap(x, y, mx, my)) return kOffMap;
  const uint8_t c = costmap_->cost(mx, my);
  if (c >= cost::INSCRIBED) return kThroughObstacle;
  if (footprintHitsLethal(mx, my)) return kThroughObstacle;
  return c;
}

double ObstacleCritic::score(const Trajectory& trajectory)
{
  double worst = 0.0;
  for (const Pose2D& p : trajectory.poses)
  {
    const double c = poseCost(p.x, p.y);
    if (c < 0.0) return c;
    worst = std::max(worst, c);
  }
  return worst;
}

// ---------------------------------------------------------------------------------------------
// MapGridCritic

MapGridCritic::MapGridCritic(double scale, Target target, double forward_shift, bool stop_on_failure)
    : TrajectoryCritic(scale), target_(target), forward_shift_(forward_shift), stop_on_failure_(stop_on_failure)
{}

bool MapGridCritic::computeMap(const Costmap2D& costmap, const std::vector<Pose2D>& targets, std::string& error)
{
  costmap_ = &costmap;
  size_x_ = costmap.sizeX();
  const size_t n = static_cast<size_t>(costmap.sizeX()) * costmap.sizeY();
  obstacle_ = static_cast<uint32_t>(n);
  unreachable_ = obstacle_ + 1;
  dist_.assign(n, unreachable_);
  queue_.clear();

  // Walk the plan in steps of half a cell so that no cell along it is skipped, and take the
  // first stretch that lies in the costmap (the part behind the robot was pruned; the part
  // after the plan leaves the local costmap does not matter here). Unlike MapGrid, plan cells
  // on an obstacle (one that appeared after planning) are not targets: a local goal inside a
  // wall would make every cell unreachable, and the robot could not even drive up to the wall.
  const double step = 0.5 * costmap.resolution();
  bool started = false;
  bool left = false;
  bool found = false;
  size_t local_goal = 0;
  auto visit = [&](double x, double y) {
    unsigned mx, my;
    if (costmap.worldToMap(x, y, mx, my) && costmap.cost(mx, my) != cost::NO_INFORMATION)
    {
      started = true;
      if (costmap.cost(mx, my) >= cost::INSCRIBED) return;
      const size_t i = costmap.index(mx, my);
      found = true;
      local_goal = i;
      if (target_ == Target::PATH && dist_[i] != 0)
      {
        dist_[i] = 0;
        queue_.push_back(static_cast<uint32_t>(i));
      }
    }
    else if (started)
    {
      left = true;
    }
  };
  for (size_t k = 0; k < targets.size() && !left; ++k)
  {
    const Pose2D& a = targets[k];
    if (k + 1 == targets.size())
    {
      visit(a.x, a.y);
      break;
    }
    const Pose2D& b = targets[k + 1];
    const double len = std::hypot(b.x - a.x, b.y - a.y);
    const int steps = std::max(1, static_cast<int>(std::ceil(len / step)));
    for (int j = 0; j < steps && !left; ++j)
    {
      const double t = static_cast<double>(j) / steps;
      visit(a.x + t * (b.x - a.x), a.y + t * (b.y - a.y));
    }
  }
  if (!found)
  {
    error = started ? "every pose of the global plan in the local costmap is in an obstacle"
                    : "no pose of the global plan lies in the local costmap";
    return false;
  }
  if (target_ == Target::LOCAL_GOAL)
  {
    dist_[local_goal] = 0;
    queue_.push_back(static_cast<uint32_t>(local_goal));
  }

  // Breadth-first wavefront, 4-connected: each step adds one cell to the distance.
  const unsigned sx = costmap.sizeX();
  const unsigned sy = costmap.sizeY();
  const uint8_t* costs = costmap.data();
  for (size_t head = 0; head < queue_.size(); ++head)
  {
    const uint32_t i = queue_[head];
    const unsigned x = i % sx;
    const unsigned y = i / sx;
    const uint32_t next_dist = dist_[i] + 1;
    auto relax = [&](uint32_t j) {
      if (dist_[j] != unreachable_) return;  // already reached (breadth first: not shorter)
      if (costs[j] >= cost::INSCRIBED)
      {
        dist_[j] = obstacle_;
        return;
      }
      dist_[j] = next_dist;
      queue_.push_back(j);
    };
    if (x > 0) relax(i - 1);
    if (x + 1 < sx) relax(i + 1);
    if (y > 0) relax(i - sx);
    if (y + 1 < sy) relax(i + sx);
  }
  return true;
}

double MapGridCritic::score(const Trajectory& trajectory)
{
  if (trajectory.poses.empty()) return kOffMap;
  // The score is read at the last point. Only with stop_on_failure can an earlier point
  // matter (an obstacle or unreachable cell rejects), so only then are all points looked at.
  // (MapGridCostFunction also rejects a trajectory whose shifted point leaves the map midway;
  // a nose that pokes out of the local costmap for a moment is harmless, and skipping it saves
  // a sine and a cosine per pose.)
  const size_t first = stop_on_failure_ ? 0 : trajectory.poses.size() - 1;
  uint32_t last = 0;
  for (size_t i = first; i < trajectory.poses.size(); ++i)
  {
    const Pose2D& p = trajectory.poses[i];
    double px = p.x;
    double py = p.y;
    if (forward_shift_ != 0.0)
    {
      px += forward_shift_ * std::cos(p.theta);
      py += forward_shift_ * std::sin(p.theta);
    }
    unsigned mx, my;
    if (!costmap_->worldToMap(px, py, mx, my)) return kOffMap;
    last = distance(mx, my);
    if (stop_on_failure_)
    {
      if (last == obstacle_) return kThroughObstacle;
      if (last == unreachable_) return kUnreachable;
    }
  }
  return last * costmap_->resolution();
}

bool PathDistCritic::prepare(const CriticContext& context, std::string& error)
{
  return computeMap(context.costmap, context.plan, error);
}

bool GoalDistCritic::prepare(const CriticContext& context, std::string& error)
{
  return computeMap(context.costmap, context.plan, error);
}

bool PathAlignCritic::prepare(const CriticContext& context, std::string& error)
{
  const Pose2D& goal = context.plan.back();
  const double dx = goal.x - context.robot_pose.x;
  const double dy = goal.y - context.robot_pose.y;
  active_ = dx * dx + dy * dy > forward_point_distance_ * forward_point_distance_;
  if (!active_) return true;
  return computeMap(context.costmap, context.plan, error);
}

double PathAlignCritic::score(const Trajectory& trajectory) { return active_ ? MapGridCritic::score(trajectory) : 0.0; }

bool GoalAlignCritic::prepare(const CriticContext& context, std::string& error)
{
  front_plan_ = context.plan;
  Pose2D& goal = front_plan_.back();
  const double angle = std::atan2(goal.y - context.robot_pose.y, goal.x - context.robot_pose.x);
  goal.x += forward_point_distance_ * std::cos(angle);
  goal.y += forward_point_distance_ * std::sin(angle);
  return computeMap(context.costmap, front_plan_, error);
}

// ---------------------------------------------------------------------------------------------
// OscillationCritic

double OscillationCritic::score(const Trajectory& trajectory)
{
  const Twist2D& v = trajectory.velocity;
  if ((forward_pos_only_ && v.vx < 0.0) || (forward_neg_only_ && v.vx > 0.0) || (strafe_pos_only_ && v.vy < 0.0) ||
      (strafe_neg_only_ && v.vy > 0.0) || (rot_pos_only_ && v.wz < 0.0) || (rot_neg_only_ && v.wz > 0.0))
    return kReversal;
  return 0.0;
}

void OscillationCritic::reset()
{
  forward_pos_ = forward_neg_ = strafe_pos_ = strafe_neg_ = rot_pos_ = rot_neg_ = false;
  forward_pos_only_ = forward_neg_only_ = false;
  strafe_pos_only_ = strafe_neg_only_ = false;
  rot_pos_only_ = rot_neg_only_ = false;
}

bool OscillationCritic::setFlags(const Trajectory& chosen, double min_vel_trans)
{
  // A reversal on an axis (e.g. forward after backward) restricts that axis to the new direction.
  auto track = [](double v, bool& pos, bool& neg, bool& pos_only, bool& neg_only) {
    bool set = false;
    if (v < 0.0)
    {
      if (pos)  // was going the other way: a reversal
      {
        neg_only = true;
        set = true;
      }
      pos = false;
      neg = true;
    }
    if (v > 0.0)
    {
      if (neg)
      {
        pos_only = true;
        set = true;
      }
      neg = false;
      pos = true;
    }
    return set;
  };
  const Twist2D& v = chosen.velocity;
  bool set = track(v.vx, forward_pos_, forward_neg_, forward_pos_only_, forward_neg_only_);
  // Strafing and turning only count while the robot is not driving forward or backward.
  if (std::fabs(v.vx) <= min_vel_trans)
  {
    set = track(v.vy, strafe_pos_, strafe_neg_, strafe_pos_only_, strafe_neg_only_) || set;
    set = track(v.wz, rot_pos_, rot_neg_, rot_pos_only_, rot_neg_only_) || set;
  }
  return set;
}

void OscillationCritic::update(const Pose2D& robot_pose, const Trajectory& chosen, double min_vel_trans)
{
  if (chosen.cost < 0.0) return;
  if (setFlags(chosen, min_vel_trans)) flag_pose_ = robot_pose;
  const bool restricted =
      forward_pos_only_ || forward_neg_only_ || strafe_pos_only_ || strafe_neg_only_ || rot_pos_only_ || rot_neg_only_;
  if (!restricted) return;
  const double dx = robot_pose.x - flag_pose_.x;
  const double dy = robot_pose.y - flag_pose_.y;
  const double dth = mbot_common::angleDiff(robot_pose.theta, flag_pose_.theta);
  if (dx * dx + dy * dy > reset_dist_ * reset_dist_ || std::fabs(dth) > reset_angle_) reset();
}

// ---------------------------------------------------------------------------------------------
// TwirlingCritic

double TwirlingCritic::score(const Trajectory& trajectory) { return std::fabs(trajectory.velocity.wz); }

}  // namespace mbot_navigation
