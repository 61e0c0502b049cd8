#include "mbot_navigation/navigator/goal_checks.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <deque>

namespace mbot_navigation
{
std::string formatPoint(double x, double y)
{
  char buf[64];
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f)", x, y);
  return buf;
}

std::string checkGoalValues(const GoalValues& g, double norm_tolerance)
{
  const double values[7] = {g.x, g.y, g.z, g.qx, g.qy, g.qz, g.qw};
  for (double v : values)
    if (std::isnan(v)) return "goal has a NaN coordinate";
  for (double v : values)
    if (std::isinf(v)) return "goal has an infinite coordinate";

  char buf[160];
  const double norm = std::sqrt(g.qx * g.qx + g.qy * g.qy + g.qz * g.qz + g.qw * g.qw);
  if (std::fabs(norm - 1.0) > norm_tolerance)
  {
    std::snprintf(buf, sizeof(buf), "goal orientation is not a unit quaternion (norm %.2f)", norm);
    return buf;
  }
  // A planar robot can only take a yaw: the rotation axis must be z (qx = qy = 0), as move_base
  // requires. The z axis rotated by q has the z component 1 - 2 (qx^2 + qy^2).
  const double tilt = std::acos(std::max(-1.0, std::min(1.0, 1.0 - 2.0 * (g.qx * g.qx + g.qy * g.qy))));
  if (tilt > 1e-3)
  {
    std::snprintf(buf, sizeof(buf), "goal orientation is not a rotation about the z axis (tilted %.3f rad)", tilt);
    return buf;
  }
  return "";
}

void StaticGoalChecker::setCostmap(const Costmap2D& costmap)
{
  costmap_ = costmap;
  const int sx = static_cast<int>(costmap.sizeX()), sy = static_cast<int>(costmap.sizeY());
  label_.assign(static_cast<size_t>(sx) * sy, -1);
  // Flood fill, 8-connected (the planner's moves). Unvisited passable cells have label -2.
  for (size_t i = 0; i < label_.size(); ++i)
    if (passable(costmap.data()[i])) label_[i] = -2;
  int32_t next = 0;
  std::vector<size_t> stack;
  for (size_t seed = 0; seed < label_.size(); ++seed)
  {
    if (label_[seed] != -2) continue;
    label_[seed] = next;
    stack.push_back(seed);
    while (!stack.empty())
    {
      const size_t i = stack.back();
      stack.pop_back();
      const int x = static_cast<int>(i % sx), y = static_cast<int>(i / sx);
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx)
        {
          if (!costmap.inBounds(x + dx, y + dy)) continue;
          const size_t j = costmap.index(x + dx, y + dy);
          if (label_[j] != -2) continue;
          label_[j] = next;
          stack.push_back(j);
        }
    }
    ++next;
  }
}

int32_t StaticGoalChecker::regionNear(double x, double y, double radius) const
{
  unsigned mx, my;
  if (!ready() || !costmap_.worldToMap(x, y, mx, my)) return -1;
  const int32_t here = label_[costmap_.index(mx, my)];
  if (here >= 0) return here;
  // Breadth-first over the cells within `radius`: the nearest passable one (in steps) wins.
  const int r = static_cast<int>(std::ceil(radius / costmap_.resolution()));
  std::deque<std::pair<int, int>> queue{{static_cast<int>(mx), static_cast<int>(my)}};
  std::vector<uint8_t> seen(static_cast<size_t>(2 * r + 1) * (2 * r + 1), 0);
  auto seen_at = [&](int x_, int y_) -> uint8_t& {
    return seen[static_cast<size_t>(y_ - static_cast<int>(my) + r) * (2 * r + 1) + (x_ - static_cast<int>(mx) + r)];
  };
  seen_at(mx, my) = 1;
  while (!queue.empty())
  {
    const auto [cx, cy] = queue.front();
    queue.pop_front();
    const int32_t l = label_[costmap_.index(cx, cy)];
    if (l >= 0) return l;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
      {
        const int nx = cx + dx, ny = cy + dy;
        if (std::abs(nx - static_cast<int>(mx)) > r || std::abs(ny - static_cast<int>(my)) > r) continue;
        if (!costmap_.inBounds(nx, ny) || seen_at(nx, ny)) continue;
        seen_at(nx, ny) = 1;
        queue.emplace_back(nx, ny);
      }
  }
  return -1;
}

std::string StaticGoalChecker::check(const Pose2D* start, const Pose2D& goal) const
{
  if (!ready()) return "";
  const double res = costmap_.resolution();
  const double x0 = costmap_.originX(), y0 = costmap_.originY();
  const double x1 = x0 + costmap_.sizeX() * res, y1 = y0 + costmap_.sizeY() * res;
  unsigned mx, my;
  if (!costmap_.worldToMap(goal.x, goal.y, mx, my))
  {
    char buf[200];
    std::snprintf(buf, sizeof(buf), "goal %s is outside the map [%g, %g] x [%g, %g]",
                  formatPoint(goal.x, goal.y).c_str(), x0, x1, y0, y1);
    return buf;
  }
  const uint8_t c = costmap_.cost(mx, my);
  if (!passable(c))
  {
    const char* what = c == cost::LETHAL      ? "a wall of the map"
                       : c == cost::INSCRIBED ? "closer to a wall than the robot's radius"
                                              : "unknown space";
    return "goal is in an obstacle: " + formatPoint(goal.x, goal.y) + " is " + what + " (cost " +
           std::to_string(static_cast<int>(c)) + ")";
  }
  if (start == nullptr) return "";
  const int32_t from = regionNear(start->x, start->y, escape_radius_);
  if (from < 0) return "";  // the robot itself is stuck: let the planner and the recoveries try
  if (label_[costmap_.index(mx, my)] != from)
    return "no path from start to goal: " + formatPoint(goal.x, goal.y) + " is not connected to the robot's position " +
           formatPoint(start->x, start->y) + " on the map";
  return "";
}

}  // namespace mbot_navigation
