#include "mbot_navigation/global_planner/ompl_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <limits>
#include <memory>
#include <stdexcept>
#include <utility>
#include <vector>

#include <ompl/base/MotionValidator.h>
#include <ompl/base/PlannerTerminationCondition.h>
#include <ompl/base/ScopedState.h>
#include <ompl/base/SpaceInformation.h>
#include <ompl/base/objectives/StateCostIntegralObjective.h>
#include <ompl/base/spaces/RealVectorStateSpace.h>
#include <ompl/geometric/PathSimplifier.h>
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
using State2D = ob::RealVectorStateSpace::StateType;  // values[0] = x, values[1] = y [m]

/// The highest cost a valid state can be on (INSCRIBED - 1).
constexpr double kMaxFreeCost = cost::INSCRIBED - 1;

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
  if (mx < 0 || my < 0 || mx >= static_cast<int>(map.sizeX()) || my >= static_cast<int>(map.sizeY())) return false;
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

/// Checks the straight segment between two states cell by cell (see firstBlocked).
class GridMotionValidator : public ob::MotionValidator
{
public:
  GridMotionValidator(const ob::SpaceInformationPtr& si, const Costmap2D& map) : ob::MotionValidator(si), map_(map) {}

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

  bool checkMotion(const ob::State* s1, const ob::State* s2, std::pair<ob::State*, double>& last_valid) const override
  {
    const double t = blockedAt(s1, s2);
    if (t < 0.0)
    {
      ++valid_;
      return true;
    }
    // The last valid state lies just before the first blocked cell.
    last_valid.second = std::max(0.0, t - 1e-6);
    if (last_valid.first != nullptr) si_->getStateSpace()->interpolate(s1, s2, last_valid.second, last_valid.first);
    ++invalid_;
    return false;
  }

private:
  double blockedAt(const ob::State* s1, const ob::State* s2) const
  {
    const auto* a = s1->as<State2D>();
    const auto* b = s2->as<State2D>();
    return firstBlocked(map_, a->values[0], a->values[1], b->values[0], b->values[1]);
  }

  const Costmap2D& map_;
};

/**
 * The cost-aware optimisation objective: the integral along the path of
 *   1 + weight * c / 252   per metre,
 * where c is the cost of the costmap cell under the path. In free space it is the path length;
 * next to an obstacle (c up to 252) a metre counts as up to 1 + weight metres.
 */
class CostmapObjective : public ob::StateCostIntegralObjective
{
public:
  CostmapObjective(const ob::SpaceInformationPtr& si, const Costmap2D& map, double weight)
      : ob::StateCostIntegralObjective(si, true), map_(map), weight_(weight)
  {
    description_ = "costmap cost integral";
  }

  /// The cost of one metre at the state.
  ob::Cost stateCost(const ob::State* s) const override
  {
    const auto* p = s->as<State2D>();
    return ob::Cost(costPerMetre(p->values[0], p->values[1]));
  }

  /// The integral over the straight segment, sampled at the middle of steps of at most half a cell.
  ob::Cost motionCost(const ob::State* s1, const ob::State* s2) const override
  {
    const auto* a = s1->as<State2D>();
    const auto* b = s2->as<State2D>();
    const double dx = b->values[0] - a->values[0];
    const double dy = b->values[1] - a->values[1];
    const double length = std::hypot(dx, dy);
    const int steps = std::max(1, static_cast<int>(std::ceil(length / (0.5 * map_.resolution()))));
    double sum = 0.0;
    for (int k = 0; k < steps; ++k)
    {
      const double t = (k + 0.5) / steps;
      sum += costPerMetre(a->values[0] + t * dx, a->values[1] + t * dy);
    }
    return ob::Cost(sum * length / steps);
  }

  /// A lower bound for motionCost(): every metre costs at least 1.
  ob::Cost motionCostHeuristic(const ob::State* s1, const ob::State* s2) const override
  {
    return ob::Cost(si_->distance(s1, s2));
  }

private:
  double costPerMetre(double x, double y) const
  {
    unsigned mx, my;
    double c = kMaxFreeCost;  // off the map (never on a valid path)
    if (map_.worldToMap(x, y, mx, my)) c = std::min<double>(map_.cost(mx, my), kMaxFreeCost);
    return 1.0 + weight_ * c / kMaxFreeCost;
  }

  const Costmap2D& map_;
  const double weight_;
};

/**
 * Move the path's points sideways, away from obstacles, where that lowers the path's cost (a
 * simple, deterministic "elastic band"). The path is first split into pieces of at most `spacing`
 * [m]. A sweep tries to move every inner point by `step` to either side (perpendicular to the
 * path there) and keeps the move when both segments at the point stay valid and cost less
 * together. Sweeps repeat until no point moves; then the step is halved, down to `min_step`.
 * The length term of the objective keeps the band tight; the costmap term pushes it to the middle
 * of doors and away from corners. Returns false when `ptc` stopped it early.
 * (A point moves at most one step per sweep, and every move lowers the cost, so it ends.)
 */
bool relaxPath(og::PathGeometric& path, const ob::OptimizationObjective& objective, double spacing, double step,
               double min_step, const ob::PlannerTerminationCondition& ptc)
{
  constexpr int kMaxSweeps = 100;    // per step size
  constexpr double kMinGain = 1e-9;  // a move must gain more than rounding noise
  const ob::SpaceInformationPtr& si = path.getSpaceInformation();
  path.interpolate(static_cast<unsigned>(std::ceil(path.length() / spacing)) + 1);
  std::vector<ob::State*>& points = path.getStates();
  ob::ScopedState<ob::RealVectorStateSpace> moved(si->getStateSpace());

  // The cost of the two segments at point i with the point at `p`.
  auto costAround = [&](size_t i, const ob::State* p) {
    return objective.motionCost(points[i - 1], p).value() + objective.motionCost(p, points[i + 1]).value();
  };

  for (; step >= min_step; step /= 2.0)
  {
    for (int sweep = 0; sweep < kMaxSweeps; ++sweep)
    {
      if (ptc) return false;
      bool any_moved = false;
      for (size_t i = 1; i + 1 < points.size(); ++i)
      {
        // The unit normal of the path at point i (perpendicular to its neighbours' chord).
        const auto* prev = points[i - 1]->as<State2D>();
        const auto* next = points[i + 1]->as<State2D>();
        const double chord = std::hypot(next->values[0] - prev->values[0], next->values[1] - prev->values[1]);
        if (chord <= 0.0) continue;
        const double nx = -(next->values[1] - prev->values[1]) / chord;
        const double ny = (next->values[0] - prev->values[0]) / chord;

        auto* point = points[i]->as<State2D>();
        double best_cost = costAround(i, points[i]);
        double best_x = 0.0, best_y = 0.0;
        bool improved = false;
        for (const double side : {-1.0, 1.0})
        {
          moved[0] = point->values[0] + side * step * nx;
          moved[1] = point->values[1] + side * step * ny;
          const double c = costAround(i, moved.get());
          if (c < best_cost - kMinGain && si->checkMotion(points[i - 1], moved.get()) &&
              si->checkMotion(moved.get(), points[i + 1]))
          {
            best_cost = c;
            best_x = moved[0];
            best_y = moved[1];
            improved = true;
          }
        }
        if (!improved) continue;
        point->values[0] = best_x;
        point->values[1] = best_y;
        any_moved = true;
      }
      if (!any_moved) break;
    }
  }
  return true;
}

/**
 * Improve a valid path without raising its cost, until `ptc` ends it:
 *  1. OMPL's shortcutPath, which replaces a part of the path by a straight segment only when that
 *     costs less (it does not cut back onto a door jamb to save a few centimetres);
 *  2. relaxPath, which moves the path away from obstacles where that costs less;
 *  3. shortcutPath again, to drop the points that relaxPath left on straight stretches.
 * PathSimplifier::simplify() is not used: its reduceVertices, collapseCloseVertices and
 * smoothBSpline only check validity, so they would pull the path back onto the jambs.
 * Deterministic (the simplifier's random numbers come from the seeded OMPL) unless `ptc` stops it.
 */
void improvePath(og::PathSimplifier& simplifier, og::PathGeometric& path, const ob::OptimizationObjective& objective,
                 double resolution, const ob::PlannerTerminationCondition& ptc)
{
  simplifier.shortcutPath(path);
  if (ptc) return;
  // Points every 5 cells, first moved 2 cells at a time, last a quarter cell.
  if (!relaxPath(path, objective, 5.0 * resolution, 2.0 * resolution, 0.25 * resolution, ptc)) return;
  simplifier.shortcutPath(path);
}

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
    throw std::invalid_argument("OMPL time_limit = " + std::to_string(config_.time_limit) + ": expected > 0 [s]");
  if (!(config_.simplify_time_limit >= 0.0))
    throw std::invalid_argument("OMPL simplify_time_limit = " + std::to_string(config_.simplify_time_limit) +
                                ": expected >= 0 [s]");
  if (!(config_.cost_weight >= 0.0))
    throw std::invalid_argument("OMPL cost_weight = " + std::to_string(config_.cost_weight) + ": expected >= 0");
  if (!(config_.path_resolution >= 0.0))
    throw std::invalid_argument("OMPL path_resolution = " + std::to_string(config_.path_resolution) +
                                ": expected >= 0 [m] (0: the costmap's resolution)");
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

  // The plane, bounded by the costmap.
  auto space = std::make_shared<ob::RealVectorStateSpace>(2);
  ob::RealVectorBounds bounds(2);
  bounds.setLow(0, costmap.originX());
  bounds.setHigh(0, costmap.originX() + costmap.sizeX() * costmap.resolution());
  bounds.setLow(1, costmap.originY());
  bounds.setHigh(1, costmap.originY() + costmap.sizeY() * costmap.resolution());
  space->setBounds(bounds);

  auto si = std::make_shared<ob::SpaceInformation>(space);
  si->setStateValidityChecker([&costmap](const ob::State* state) {
    const auto* s = state->as<State2D>();
    return pointFree(costmap, s->values[0], s->values[1]);
  });
  si->setMotionValidator(std::make_shared<GridMotionValidator>(si, costmap));
  si->setup();

  og::SimpleSetup setup(si);
  ob::ScopedState<ob::RealVectorStateSpace> s(space), g(space);
  s[0] = start.x;
  s[1] = start.y;
  g[0] = goal.x;
  g[1] = goal.y;
  setup.setStartAndGoalStates(s, g);
  auto objective = std::make_shared<CostmapObjective>(si, costmap, config_.cost_weight);
  setup.setOptimizationObjective(objective);
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
    std::snprintf(buf, sizeof(buf), "%s found no path from %s to %s within %.2f s (%s)", config_.planner.c_str(),
                  formatXY(start).c_str(), formatXY(goal).c_str(), config_.time_limit, status.asString().c_str());
    result.error = buf;
    return result;
  }
  og::PathGeometric& solution = setup.getSolutionPath();
  if (config_.simplify && config_.simplify_time_limit > 0.0)
  {
    og::PathSimplifier simplifier(si, setup.getGoal(), objective);
    improvePath(simplifier, solution, *objective, costmap.resolution(),
                ob::timedPlannerTerminationCondition(config_.simplify_time_limit));
  }

  // Interpolate the straight segments to about one pose per path_resolution, facing along them.
  const double spacing = config_.path_resolution > 0.0 ? config_.path_resolution : costmap.resolution();
  result.path.push_back(start);
  for (size_t i = 0; i + 1 < solution.getStateCount(); ++i)
  {
    const auto* a = solution.getState(i)->as<State2D>();
    const auto* b = solution.getState(i + 1)->as<State2D>();
    const double dx = b->values[0] - a->values[0];
    const double dy = b->values[1] - a->values[1];
    const double length = std::hypot(dx, dy);
    if (length <= 0.0) continue;
    const double heading = std::atan2(dy, dx);
    const int steps = static_cast<int>(std::ceil(length / spacing));
    for (int k = 1; k <= steps; ++k)
    {
      const double t = static_cast<double>(k) / steps;
      result.path.push_back(Pose2D{a->values[0] + t * dx, a->values[1] + t * dy, heading});
    }
  }
  // The last pose is the goal as requested (the solution ends on it up to rounding).
  if (result.path.size() > 1) result.path.pop_back();
  result.path.push_back(goal);
  result.ok = true;
  return result;
}

}  // namespace mbot_navigation
