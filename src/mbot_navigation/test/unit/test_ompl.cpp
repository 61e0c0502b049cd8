/**
 * @file test_ompl.cpp
 * @brief OmplPlanner on small hand-made costmaps, without ROS.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbot_navigation/global_planner/ompl_planner.h"

using namespace mbot_navigation;

namespace
{
constexpr double kRadius = 0.15;  // robot radius [m]: cells this close to a wall are INSCRIBED

/// Mark the cells whose centres lie in [x0, x1] x [y0, y1] [m] LETHAL.
void addWall(Costmap2D& map, double x0, double y0, double x1, double y1)
{
  for (unsigned my = 0; my < map.sizeY(); ++my)
    for (unsigned mx = 0; mx < map.sizeX(); ++mx)
    {
      double wx, wy;
      map.mapToWorld(mx, my, wx, wy);
      if (wx >= x0 && wx <= x1 && wy >= y0 && wy <= y1) map.setCost(mx, my, cost::LETHAL);
    }
}

/// Cells within kRadius of a LETHAL cell become INSCRIBED (what the inflation layer does first).
void inflateInscribed(Costmap2D& map)
{
  const Costmap2D original = map;
  const int r = static_cast<int>(std::ceil(kRadius / map.resolution()));
  for (int y = 0; y < static_cast<int>(map.sizeY()); ++y)
    for (int x = 0; x < static_cast<int>(map.sizeX()); ++x)
    {
      if (original.cost(x, y) != cost::LETHAL) continue;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx)
        {
          const int nx = x + dx, ny = y + dy;
          if (nx < 0 || ny < 0 || nx >= static_cast<int>(map.sizeX()) || ny >= static_cast<int>(map.sizeY())) continue;
          if (std::hypot(dx, dy) * map.resolution() <= kRadius && map.cost(nx, ny) < cost::INSCRIBED)
            map.setCost(nx, ny, cost::INSCRIBED);
        }
    }
}

/// 10 x 6 m at 0.05 m; a wall at x = 5 m across the whole map except a gap for y in [4.0, 4.8].
Costmap2D wallWithGap()
{
  Costmap2D map(200, 120, 0.05, 0.0, 0.0);
  addWall(map, 4.9, 0.0, 5.1, 4.0);
  addWall(map, 4.9, 4.8, 5.1, 6.0);
  inflateInscribed(map);
  return map;
}

/**
 * Inflate LETHAL cells as the nav node's costmaps do (config/nav_costmaps.yaml, inflation_layer.h):
 * within kRadius INSCRIBED, out to 0.6 m 252 * exp(-5 (d - kRadius)), d between cell centres.
 */
void inflateLikeTheNavNode(Costmap2D& map)
{
  constexpr double kInflationRadius = 0.6, kScaling = 5.0;
  const double res = map.resolution();
  const int r = static_cast<int>(std::ceil(kInflationRadius / res));
  // Distance [m] from every cell to the nearest LETHAL cell, spread out from the LETHAL cells.
  std::vector<double> dist(map.sizeX() * map.sizeY(), 1e9);
  for (int y = 0; y < static_cast<int>(map.sizeY()); ++y)
    for (int x = 0; x < static_cast<int>(map.sizeX()); ++x)
    {
      if (map.cost(x, y) != cost::LETHAL) continue;
      for (int dy = -r; dy <= r; ++dy)
        for (int dx = -r; dx <= r; ++dx)
          if (map.inBounds(x + dx, y + dy))
          {
            double& d = dist[map.index(x + dx, y + dy)];
            d = std::min(d, std::hypot(dx, dy) * res);
          }
    }
  for (unsigned y = 0; y < map.sizeY(); ++y)
    for (unsigned x = 0; x < map.sizeX(); ++x)
    {
      const double d = dist[map.index(x, y)];
      if (d == 0.0) continue;  // LETHAL
      if (d <= kRadius)
        map.setCost(x, y, cost::INSCRIBED);
      else if (d <= kInflationRadius)
        map.setCost(x, y, static_cast<uint8_t>(std::floor(252.0 * std::exp(-kScaling * (d - kRadius)))));
    }
}

/// 10 x 6 m at 0.05 m; a wall at x = 5 m with a 1.2 m door for y in [2.4, 3.6] (the office's
/// doors are 1.2 m), inflated like the nav node's costmap.
Costmap2D wallWithDoor(double resolution = 0.05)
{
  Costmap2D map(static_cast<unsigned>(std::lround(10.0 / resolution)),
                static_cast<unsigned>(std::lround(6.0 / resolution)), resolution, 0.0, 0.0);
  addWall(map, 4.9, 0.0, 5.1, 2.4);
  addWall(map, 4.9, 3.6, 5.1, 6.0);
  inflateLikeTheNavNode(map);
  return map;
}

/// Distance [m] from (x, y) to the nearest LETHAL cell centre (1e9 when none within 2 m).
double clearance(const Costmap2D& map, double x, double y)
{
  double best = 1e9;
  for (unsigned my = 0; my < map.sizeY(); ++my)
    for (unsigned mx = 0; mx < map.sizeX(); ++mx)
    {
      double wx, wy;
      map.mapToWorld(mx, my, wx, wy);
      if (map.cost(mx, my) == cost::LETHAL && std::fabs(wx - x) < 2.0 && std::fabs(wy - y) < 2.0)
        best = std::min(best, std::hypot(wx - x, wy - y));
    }
  return best;
}

int costAt(const Costmap2D& map, double x, double y)
{
  unsigned mx, my;
  if (!map.worldToMap(x, y, mx, my)) return 1000;  // off the map
  return map.cost(mx, my);
}

double pathLength(const std::vector<Pose2D>& path)
{
  double len = 0.0;
  for (size_t i = 1; i < path.size(); ++i) len += std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  return len;
}

/// Every pose on a free cell, every segment free at 5 mm steps, poses at most one cell apart,
/// endpoints equal to start and goal.
void expectValidPath(const Costmap2D& map, const PlanResult& r, const Pose2D& start, const Pose2D& goal)
{
  const double max_spacing = map.resolution();
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_GE(r.path.size(), 2u);
  EXPECT_DOUBLE_EQ(r.path.front().x, start.x);
  EXPECT_DOUBLE_EQ(r.path.front().y, start.y);
  EXPECT_DOUBLE_EQ(r.path.front().theta, start.theta);
  EXPECT_DOUBLE_EQ(r.path.back().x, goal.x);
  EXPECT_DOUBLE_EQ(r.path.back().y, goal.y);
  EXPECT_DOUBLE_EQ(r.path.back().theta, goal.theta);
  double max_step = 0.0;
  for (size_t i = 0; i < r.path.size(); ++i)
  {
    const Pose2D& p = r.path[i];
    ASSERT_LT(costAt(map, p.x, p.y), cost::INSCRIBED) << "pose " << i << " (" << p.x << ", " << p.y << ")";
    if (i == 0) continue;
    const Pose2D& q = r.path[i - 1];
    const double d = std::hypot(p.x - q.x, p.y - q.y);
    max_step = std::max(max_step, d);
    const int n = static_cast<int>(std::ceil(d / 0.005));
    for (int k = 1; k < n; ++k)
    {
      const double t = static_cast<double>(k) / n;
      ASSERT_LT(costAt(map, q.x + t * (p.x - q.x), q.y + t * (p.y - q.y)), cost::INSCRIBED)
          << "between poses " << i - 1 << " and " << i;
    }
  }
  EXPECT_LE(max_step, max_spacing + 1e-9) << "poses this far apart";
}
}  // namespace

TEST(OmplPlanner, FindsThePathThroughTheGapWithEveryPlanner)
{
  const Costmap2D map = wallWithGap();
  const Pose2D start{1.0, 1.0, 0.0}, goal{9.0, 1.0, M_PI};
  // Any way crosses x = 5 m at y >= 4.1 m (the wall's cells end at 4.0 m, their INSCRIBED ring
  // reaches at least 0.1 m further), so no path is shorter than through (5.0, 4.1).
  const double shortest = 2.0 * std::hypot(4.0, 3.1);
  for (const std::string name : {"rrtconnect", "rrtstar", "prmstar"})
  {
    SCOPED_TRACE(name);
    OmplConfig config;
    config.planner = name;
    config.time_limit = 0.5;
    OmplPlanner planner(config);
    EXPECT_EQ(planner.name(), "ompl");
    const PlanResult r = planner.makePlan(map, start, goal);
    expectValidPath(map, r, start, goal);
    // It went through the gap ...
    bool through_gap = false;
    for (const Pose2D& p : r.path) through_gap |= std::fabs(p.x - 5.0) < 0.1 && p.y > 4.0 && p.y < 4.8;
    EXPECT_TRUE(through_gap);
    // ... without a large detour (simplification shortcuts the random tree).
    const double length = pathLength(r.path);
    EXPECT_GE(length, shortest);
    EXPECT_LT(length, 1.1 * shortest) << "length " << length << " m";
  }
}

// From (1, 1) to (9, 1) the shortest way grazes the door's lower jamb (5, 2.4); the local planner
// stalls there. The cost-aware path goes through the middle of the door instead.
TEST(OmplPlanner, GoesThroughTheMiddleOfADoorNotAlongTheJamb)
{
  const Costmap2D map = wallWithDoor();
  const Pose2D start{1.0, 1.0, 0.0}, goal{9.0, 1.0, 0.0};
  const double shortest = 2.0 * std::hypot(4.0, 1.55);  // via (5, 2.55), just off the jamb
  for (const std::string name : {"rrtconnect", "rrtstar", "prmstar"})
  {
    SCOPED_TRACE(name);
    OmplConfig config;
    config.planner = name;
    config.time_limit = 0.5;
    OmplPlanner planner(config);
    const PlanResult r = planner.makePlan(map, start, goal);
    expectValidPath(map, r, start, goal);
    double max_cost = 0.0, sum_cost = 0.0, min_clearance = 1e9;
    for (const Pose2D& p : r.path)
    {
      max_cost = std::max(max_cost, static_cast<double>(costAt(map, p.x, p.y)));
      sum_cost += costAt(map, p.x, p.y);
      if (std::fabs(p.x - 5.0) < 0.5) min_clearance = std::min(min_clearance, clearance(map, p.x, p.y));
    }
    // In the middle of the door the clearance is 0.6 m (cost 26); grazing the jamb it is about
    // 0.2 m (cost above 190).
    EXPECT_GE(min_clearance, 0.45) << "the path passes the jamb that close";
    EXPECT_LE(max_cost, 60.0);
    EXPECT_LE(sum_cost / r.path.size(), 15.0) << "mean cost along the path";
    EXPECT_LT(pathLength(r.path), 1.15 * shortest) << "no large detour for it";
  }
}

// cost_weight 0 is the old objective, the length alone: the path grazes the jamb.
TEST(OmplPlanner, WithoutTheCostTermTheShortestPathGrazesTheJamb)
{
  const Costmap2D map = wallWithDoor();
  OmplConfig config;
  config.planner = "rrtconnect";
  config.cost_weight = 0.0;
  OmplPlanner planner(config);
  const PlanResult r = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  expectValidPath(map, r, Pose2D{1.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  double min_clearance = 1e9;
  for (const Pose2D& p : r.path) min_clearance = std::min(min_clearance, clearance(map, p.x, p.y));
  EXPECT_LT(min_clearance, 0.3);
}

// Shortcuts must not undo the clearance: a straight start-goal line through a door off-centre
// is valid but costs more than bending through the middle.
TEST(OmplPlanner, SimplificationKeepsTheClearance)
{
  const Costmap2D map = wallWithDoor();
  // Straight from (1, 2.7) to (9, 2.7) is valid (0.3 m from the lower jamb), the middle is at 3.0.
  const Pose2D start{1.0, 2.7, 0.0}, goal{9.0, 2.7, 0.0};
  OmplConfig config;
  config.planner = "rrtconnect";
  OmplPlanner planner(config);
  const PlanResult r = planner.makePlan(map, start, goal);
  expectValidPath(map, r, start, goal);
  const Pose2D* in_door = &r.path.front();  // the pose closest to the wall's centre line
  for (const Pose2D& p : r.path)
    if (std::fabs(p.x - 5.0) < std::fabs(in_door->x - 5.0)) in_door = &p;
  EXPECT_NEAR(in_door->x, 5.0, 0.05);
  EXPECT_NEAR(in_door->y, 3.0, 0.15) << "crossing the door off its middle (3.0)";
}

// The path is interpolated to the costmap's resolution by default (path_resolution 0).
TEST(OmplPlanner, PathIsDenseAtTheCostmapResolution)
{
  for (const double resolution : {0.025, 0.1})
  {
    SCOPED_TRACE(resolution);
    const Costmap2D map = wallWithDoor(resolution);
    OmplConfig config;
    config.planner = "rrtconnect";
    OmplPlanner planner(config);
    const Pose2D start{1.0, 1.0, 0.0}, goal{9.0, 1.0, M_PI};
    const PlanResult r = planner.makePlan(map, start, goal);
    expectValidPath(map, r, start, goal);  // poses at most one cell apart
    EXPECT_GT(r.path.size(), pathLength(r.path) / resolution);
  }
  // An explicit spacing wins.
  OmplConfig config;
  config.planner = "rrtconnect";
  config.path_resolution = 0.2;
  OmplPlanner planner(config);
  const PlanResult r = planner.makePlan(wallWithDoor(), Pose2D{1.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  ASSERT_TRUE(r.ok) << r.error;
  for (size_t i = 1; i < r.path.size(); ++i)
    EXPECT_LE(std::hypot(r.path[i].x - r.path[i - 1].x, r.path[i].y - r.path[i - 1].y), 0.2 + 1e-9);
}

TEST(OmplPlanner, NoPathThroughAClosedDoor)
{
  Costmap2D map = wallWithDoor();
  addWall(map, 4.9, 2.3, 5.1, 3.7);  // close the door
  inflateLikeTheNavNode(map);
  for (const std::string name : {"rrtconnect", "rrtstar", "prmstar"})
  {
    SCOPED_TRACE(name);
    OmplConfig config;
    config.planner = name;
    config.time_limit = 0.2;
    OmplPlanner planner(config);
    const PlanResult r = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(r.path.empty());
    EXPECT_NE(r.error.find("found no path"), std::string::npos) << r.error;
  }
}

TEST(OmplPlanner, SameSeedSamePath)
{
  const Costmap2D map = wallWithDoor();
  OmplConfig config;
  config.planner = "rrtconnect";  // stops at its first solution: no dependence on timing
  OmplPlanner planner(config);
  const PlanResult a = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  const PlanResult b = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  ASSERT_TRUE(a.ok && b.ok);
  ASSERT_EQ(a.path.size(), b.path.size());
  for (size_t i = 0; i < a.path.size(); ++i)
  {
    EXPECT_DOUBLE_EQ(a.path[i].x, b.path[i].x);
    EXPECT_DOUBLE_EQ(a.path[i].y, b.path[i].y);
  }
}

TEST(OmplPlanner, FailsWithinTheTimeLimitWhenTheGoalIsWalledIn)
{
  Costmap2D map = wallWithGap();
  // A closed square room around the goal.
  addWall(map, 7.9, 0.4, 8.1, 1.6);
  addWall(map, 9.6, 0.4, 9.8, 1.6);
  addWall(map, 7.9, 0.4, 9.8, 0.5);
  addWall(map, 7.9, 1.5, 9.8, 1.6);
  inflateInscribed(map);
  for (const std::string name : {"rrtconnect", "rrtstar"})
  {
    SCOPED_TRACE(name);
    OmplConfig config;
    config.planner = name;
    config.time_limit = 0.3;
    OmplPlanner planner(config);
    const auto t0 = std::chrono::steady_clock::now();
    const PlanResult r = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{8.8, 1.0, 0.0});
    const double elapsed = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    EXPECT_FALSE(r.ok);
    EXPECT_TRUE(r.path.empty());
    EXPECT_NE(r.error.find("found no path from (1.00, 1.00) to (8.80, 1.00) within 0.30 s"), std::string::npos)
        << r.error;
    EXPECT_LT(elapsed, config.time_limit + 1.0);  // the limit holds (generous for a loaded machine)
  }
}

TEST(OmplPlanner, RejectsAStartInAWallAndAGoalOffTheMap)
{
  const Costmap2D map = wallWithGap();
  OmplPlanner planner(OmplConfig{});
  PlanResult r = planner.makePlan(map, Pose2D{5.0, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "start (5.00, 1.00) is in an obstacle (cost 254)");
  r = planner.makePlan(map, Pose2D{4.85, 1.0, 0.0}, Pose2D{9.0, 1.0, 0.0});
  EXPECT_EQ(r.error, "start (4.85, 1.00) is in an obstacle (cost 253)");
  r = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{12.0, 1.0, 0.0});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "goal (12.00, 1.00) is outside the costmap");
}

TEST(OmplPlanner, StartOnTheGoal)
{
  const Costmap2D map = wallWithDoor();
  OmplConfig config;
  config.time_limit = 0.2;
  OmplPlanner planner(config);
  const PlanResult r = planner.makePlan(map, Pose2D{1.0, 1.0, 0.0}, Pose2D{1.0, 1.0, 1.0});
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_GE(r.path.size(), 1u);
  EXPECT_DOUBLE_EQ(r.path.back().x, 1.0);
  EXPECT_DOUBLE_EQ(r.path.back().y, 1.0);
  EXPECT_DOUBLE_EQ(r.path.back().theta, 1.0);
}

TEST(OmplPlanner, RejectsParametersOutOfRange)
{
  OmplConfig config;
  config.simplify_time_limit = -1.0;
  EXPECT_THROW(OmplPlanner{config}, std::invalid_argument);
  config = OmplConfig{};
  config.cost_weight = -1.0;
  EXPECT_THROW(OmplPlanner{config}, std::invalid_argument);
  config = OmplConfig{};
  config.path_resolution = -0.05;
  EXPECT_THROW(OmplPlanner{config}, std::invalid_argument);
  config = OmplConfig{};
  config.time_limit = 0.0;
  EXPECT_THROW(OmplPlanner{config}, std::invalid_argument);
}

TEST(OmplPlanner, RejectsAnUnknownPlannerName)
{
  OmplConfig config;
  config.planner = "rrt_star";
  try
  {
    OmplPlanner planner(config);
    FAIL() << "expected std::invalid_argument";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("'rrt_star' is unknown: expected rrtstar, prmstar or rrtconnect"),
              std::string::npos)
        << e.what();
  }
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
