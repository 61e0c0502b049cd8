#include "mbot_navigation/ompl_planner.h"

#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/objectives/PathLengthOptimizationObjective.h>
#include <ompl/base/spaces/SE2StateSpace.h>
#include <ompl/geometric/SimpleSetup.h>
#include <ompl/geometric/planners/prm/PRMstar.h>
#include <ompl/geometric/planners/rrt/RRTConnect.h>
#include <ompl/geometric/planners/rrt/RRTstar.h>
#include <ompl/util/Console.h>
#include <ompl/util/RandomNumbers.h>

namespace ob = ompl::base;
namespace og = ompl::geometric;

namespace mbot_navigation
{
namespace
{
/// "(1.20, 3.40)"
std::string formatXY(const Pose2D& p)
{
  char buf[64];
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f)", p.x, p.y);
  return buf;
}

/// True when the robot's centre may be in cell (mx, my): inside the map and not (near) an obstacle.
bool cellFree(const Costmap2D& map, int mx, int my)
{
  if (mx < 0 || my < 0 || mx >= static_cast<int>(map.sizeX()) || my >= static_cast<int>(map.sizeY()))
    return false;
  return map.cost(mx, my) < cost::INSCRIBED;
}

bool pointFree(const Costmap2D& map, double x, double y)
{
  unsigned mx, my;
  return map.worldToMap(x, y, mx, my) && map.cost(mx, my) < cost::INSCRIBED;
}

/**
 * Walk every cell that the segment a -> b [m] touches (Amanatides and Woo's grid traversal) and
 * return the segment parameter t in [0, 1] where it first enters a blocked cell, or -1 when all
 * are free. Where the segment passes exactly through a cell corner, both side cells count.
 */
double firstBlocked(const Costmap2D& map, double ax, double ay, double bx, double by)
{
  const double res = map.resolution();
  const double gx0 = (ax - map.originX()) / res;  // grid coordinates [cells]
  const double gy0 = (ay - map.originY()) / res;
  const double gx1 = (bx - map.originX()) / res;
  const double gy1 = (by - map.originY()) / res;
  int cx = static_cast<int>(std::floor(gx0));
  int cy = static_cast<int>(std::floor(gy0));
  const int ex = static_cast<int>(std::floor(gx1));
  const int ey = static_cast<int>(std::floor(gy1));
  const double dx = gx1 - gx0;
  const double dy = gy1 - gy0;
  const int step_x = (dx > 0.0) - (dx < 0.0);
  const int step_y = (dy > 0.0) - (dy < 0.0);
  const double inf = std::numeric_limits<double>::infinity();
  // t at which the segment crosses the next vertical / horizontal cell border, and t per cell.
  double t_max_x = step_x > 0 ? (cx + 1 - gx0) / dx : (step_x < 0 ? (gx0 - cx) / -dx : inf);
  double t_max_y = step_y > 0 ? (cy + 1 - gy0) / dy : (step_y < 0 ? (gy0 - cy) / -dy : inf);
  const double t_delta_x = step_x != 0 ? 1.0 / std::fabs(dx) : inf;
  const double t_delta_y = step_y != 0 ? 1.0 / std::fabs(dy) : inf;

  double t = 0.0;
  const int max_cells = std::abs(ex - cx) + std::abs(ey - cy) + 1;  // guards against rounding
  for (int n = 0; n <= max_cells; ++n)
  {
    if (!cellFree(map, cx, cy)) return t;
    if (cx == ex && cy == ey) return -1.0;
    if (t_max_x < t_max_y)
    {
      t = t_max_x;
      cx += step_x;
      t_max_x += t_delta_x;
    }
    else if (t_max_y < t_max_x)
    {
      t = t_max_y;
      cy += step_y;
      t_max_y += t_delta_y;
    }
    else  // exactly through a corner
    {
      t = t_max_x;
      if (t <= 1.0 && (!cellFree(map, cx + step_x, cy) || !cellFree(map, cx, cy + step_y))) return t;
      cx += step_x;
      cy += step_y;
      t_max_x += t_delta_x;
      t_max_y += t_delta_y;
    }
    if (t > 1.0) return -1.0;  // stepped past the end (rounding at a cell border)
  }
  return -1.0;
}

/// Checks the straight xy segment between two SE(2) states cell by cell (see firstBlocked).
class GridMotionValidator : public ob::MotionValidator
{
public:
  GridMotionValidator(const ob::SpaceInformationPtr& si, const Costmap2D& map)
    : ob::MotionValidator(si), map_(map)
  {
  }

  bool checkMotion(const ob::State* s1, const ob::State* s2) const override
  {
    if (blockedAt(s1, s2) < 0.0)
    {
      ++valid_;
      return true;
    }
    ++invalid_;
    return false;
  }

  bool checkMotion(const ob::State* s1, const ob::State* s2,
                   std::pair<ob::State*, double>& last_valid) const override
  {
    const double t = blockedAt(s1, s2);
    if (t < 0.0)
    {
      ++valid_;
      return true;
    }
    // The last valid state lies just before the first blocked cell.
    last_valid.second = std::max(0.0, t - 1e-6);
    if (last_valid.first != nullptr)
      si_->getStateSpace()->interpolate(s1, s2, last_valid.second, last_valid.first);
    ++invalid_;
    return false;
  }

private:
  double blockedAt(const ob::State* s1, const ob::State* s2) const
  {
    const auto* a = s1->as<ob::SE2StateSpace::StateType>();
    const auto* b = s2->as<ob::SE2StateSpace::StateType>();
    return firstBlocked(map_, a->getX(), a->getY(), b->getX(), b->getY());
  }

  const Costmap2D& map_;
};

/// Empty when the pose may be a start or goal, else why not.
std::string checkEndpoint(const char* what, const Costmap2D& map, const Pose2D& p)
{
  unsigned mx, my;
  if (!map.worldToMap(p.x, p.y, mx, my)) return std::string(what) + " " + formatXY(p) + " is outside the costmap";
  const unsigned c = map.cost(mx, my);
  if (c >= cost::INSCRIBED)
    return std::string(what) + " " + formatXY(p) + " is in an obstacle (cost " + std::to_string(c) + ")";
  return "";
}

/**
 * OMPL gives every random generator it creates a seed drawn from one process-wide generator;
 * resetting that one before we build the planner makes every request reproducible. OMPL logs an
 * error when it is reset after its first use, because RNGs created earlier are not affected;
 * ours are all created after it, so the message does not apply and is silenced.
 */
void reseedOmpl(unsigned seed)
{
  const ompl::msg::LogLevel level = ompl::msg::getLogLevel();
  ompl::msg::setLogLevel(ompl::msg::LOG_NONE);
  ompl::RNG::setSeed(seed);
  ompl::msg::setLogLevel(level);
}
}  // namespace

OmplPlanner::OmplPlanner(const OmplConfig& config) : config_(config)
{
  if (config_.planner != "rrtstar" && config_.planner != "prmstar" && config_.planner != "rrtconnect")
    throw std::invalid_argument("OMPL planner '" + config_.planner +
                                "' is unknown: expected rrtstar, prmstar or rrtconnect");
  if (!(config_.time_limit > 0.0))
    throw std::invalid_argument("OMPL time_limit = " + std::to_string(config_.time_limit) +
                                ": expected > 0 [s]");
  if (!(config_.path_resolution > 0.0))
    throw std::invalid_argument("OMPL path_resolution = " + std::to_string(config_.path_resolution) +
                                ": expected > 0 [m]");
  if (config_.seed == 0) throw std::invalid_argument("OMPL seed = 0: expected > 0");
  // OMPL reports progress at INFO level on every request; keep warnings and errors only.
  if (ompl::msg::getLogLevel() < ompl::msg::LOG_WARN) ompl::msg::setLogLevel(ompl::msg::LOG_WARN);
}

PlanResult OmplPlanner::makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal)
{
  PlanResult result;
  result.error = checkEndpoint("start", costmap, start);
  if (result.error.empty()) result.error = checkEndpoint("goal", costmap, goal);
  if (!result.error.empty()) return result;

  reseedOmpl(config_.seed);  // before any OMPL object that draws random numbers is built

  // SE(2) bounded by the costmap.
  auto space = std::make_shared<ob::SE2StateSpace>();
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, costmap.originX());
  bounds.setHigh(0, costmap.originX() + costmap.sizeX() * costmap.resolution());
  bounds.setLow(1, costmap.originY());
  bounds.setHigh(1, costmap.originY() + costmap.sizeY() * costmap.resolution());
  space->setBounds(bounds);

  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&costmap](const ob::State* state) {
    const auto* s = state->as<ob::SE2StateSpace::StateType>();
    return pointFree(costmap, s->getX(), s->getY());
  });
  si->setMotionValidator(std::make_shared<GridMotionValidator>(si, costmap));
  si->setup();

  og::SimpleSetup setup(si);
  ob::ScopedState<ob::SE2StateSpace> s(space), g(space);
  s->setXY(start.x, start.y);
  s->setYaw(start.theta);
  g->setXY(goal.x, goal.y);
  g->setYaw(goal.theta);
  s.enforceBounds();  // yaw into SO(2)'s range (pi itself is out of it)
  g.enforceBounds();
  setup.setStartAndGoalStates(s, g);
  setup.setOptimizationObjective(std::make_shared<ob::PathLengthOptimizationObjective>(si));
  if (config_.planner == "rrtstar")
    setup.setPlanner(std::make_shared<og::RRTstar>(si));
  else if (config_.planner == "prmstar")
    setup.setPlanner(std::make_shared<og::PRMstar>(si));
  else
    setup.setPlanner(std::make_shared<og::RRTConnect>(si));

  const ob::PlannerStatus status = setup.solve(config_.time_limit);
  if (status != ob::PlannerStatus::EXACT_SOLUTION)
  {
    char buf[160];
    std::snprintf(buf, sizeof(buf), "%s found no path from %s to %s within %.2f s (%s)",
                  config_.planner.c_str(), formatXY(start).c_str(), formatXY(goal).c_str(),
                  config_.time_limit, status.asString().c_str());
    result.error = buf;
    return result;
  }
  if (config_.simplify) setup.simplifySolution();
  const og::PathGeometric& solution = setup.getSolutionPath();

  // Interpolate the straight segments to about one pose per path_resolution, facing along them.
  result.path.push_back(start);
  for (size_t i = 0; i + 1 < solution.getStateCount(); ++i)
  {
    const auto* a = solution.getState(i)->as<ob::SE2StateSpace::StateType>();
    const auto* b = solution.getState(i + 1)->as<ob::SE2StateSpace::StateType>();
    const double dx = b->getX() - a->getX();
    const double dy = b->getY() - a->getY();
    const double length = std::hypot(dx, dy);
    if (length <= 0.0) continue;
    const double heading = std::atan2(dy, dx);
    const int steps = static_cast<int>(std::ceil(length / config_.path_resolution));
    for (int k = 1; k <= steps; ++k)
    {
      const double t = static_cast<double>(k) / steps;
      result.path.push_back(Pose2D{a->getX() + t * dx, a->getY() + t * dy, heading});
    }
  }
  // The last pose is the goal as requested (the solution ends on it up to rounding).
  if (result.path.size() > 1) result.path.pop_back();
  result.path.push_back(goal);
  result.ok = true;
  return result;
}

}  // namespace mbot_navigation
