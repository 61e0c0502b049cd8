/**
 * @file test_ompl.cpp
 * @brief OmplPlanner on small hand-made costmaps, without ROS.
 */
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <string>

#include "mbot_navigation/ompl_planner.h"

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
          if (nx < 0 || ny < 0 || nx >= static_cast<int>(map.sizeX()) || ny >= static_cast<int>(map.sizeY()))
            continue;
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

int costAt(const Costmap2D& map, double x, double y)
{
  unsigned mx, my;
  if (!map.worldToMap(x, y, mx, my)) return 1000;  // off the map
  return map.cost(mx, my);
}

double pathLength(const std::vector<Pose2D>& path)
{
  double len = 0.0;
  for (size_t i = 1; i < path.size(); ++i)
    len += std::hypot(path[i].x - path[i - 1].x, path[i].y - path[i - 1].y);
  return len;
}

/// Every pose on a free cell, every segment free at 5 mm steps, poses <= 0.05 m apart,
/// endpoints equal to start and goal.
void expectValidPath(const Costmap2D& map, const PlanResult& r, const Pose2D& start, const Pose2D& goal)
{
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_GE(r.path.size(), 2u);
  EXPECT_DOUBLE_EQ(r.path.front().x, start.x);
  EXPECT_DOUBLE_EQ(r.path.front().y, start.y);
  EXPECT_DOUBLE_EQ(r.path.front().theta, start.theta);
  EXPECT_DOUBLE_EQ(r.path.back().x, goal.x);
  EXPECT_DOUBLE_EQ(r.path.back().y, goal.y);
  EXPECT_DOUBLE_EQ(r.path.back().theta, goal.theta);
  for (size_t i = 0; i < r.path.size(); ++i)
  {
    const Pose2D& p = r.path[i];
    ASSERT_LT(costAt(map, p.x, p.y), cost::INSCRIBED) << "pose " << i << " (" << p.x << ", " << p.y << ")";
    if (i == 0) continue;
    const Pose2D& q = r.path[i - 1];
    const double d = std::hypot(p.x - q.x, p.y - q.y);
    EXPECT_LE(d, 0.05 + 1e-9) << "pose " << i;
    const int n = static_cast<int>(std::ceil(d / 0.005));
    for (int k = 1; k < n; ++k)
    {
      const double t = static_cast<double>(k) / n;
      ASSERT_LT(costAt(map, q.x + t * (p.x - q.x), q.y + t * (p.y - q.y)), cost::INSCRIBED)
          << "between poses " << i - 1 << " and " << i;
    }
  }
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

TEST(OmplPlanner, SameSeedSamePath)
{
  const Costmap2D map = wallWithGap();
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
    EXPECT_NE(r.error.find("found no path from (1.00, 1.00) to (8.80, 1.00) within 0.30 s"),
              std::string::npos)
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
