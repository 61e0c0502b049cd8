#include "mbot_navigation/global_planner/goal_tolerance.h"

#include <cmath>

namespace mbot_navigation
{
bool isFreeGoal(const Costmap2D& costmap, const Pose2D& goal)
{
  unsigned mx, my;
  return costmap.worldToMap(goal.x, goal.y, mx, my) && costmap.cost(mx, my) < cost::INSCRIBED;
}

std::vector<Pose2D> goalsAround(const Costmap2D& costmap, const Pose2D& goal, double tolerance)
{
  std::vector<Pose2D> out;
  const double step = costmap.resolution();
  // 1e-9: a tolerance of exactly k cells includes ring k despite rounding in the sum
  for (double r = step; r <= tolerance + 1e-9; r += step)
    for (int k = 0; k < 16; ++k)
    {
      Pose2D g = goal;
      g.x += r * std::cos(k * M_PI / 8.0);
      g.y += r * std::sin(k * M_PI / 8.0);
      if (isFreeGoal(costmap, g)) out.push_back(g);
    }
  return out;
}

bool nearestFreeGoal(const Costmap2D& costmap, const Pose2D& goal, double tolerance, Pose2D& out)
{
  if (isFreeGoal(costmap, goal))
  {
    out = goal;
    return true;
  }
  const std::vector<Pose2D> around = goalsAround(costmap, goal, tolerance);
  if (around.empty()) return false;
  out = around.front();
  return true;
}

PlanResult planWithTolerance(const Costmap2D& costmap, const Pose2D& goal, double tolerance,
                             const std::function<PlanResult(const Pose2D& goal)>& plan)
{
  PlanResult result = plan(goal);
  if (result.ok || !(tolerance > 0.0)) return result;
  for (const Pose2D& g : goalsAround(costmap, goal, tolerance))
  {
    result = plan(g);
    if (result.ok) break;
  }
  return result;
}

}  // namespace mbot_navigation
