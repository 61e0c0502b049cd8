// make_plan's tolerance search (goal_tolerance.h) on hand-made grids (no ROS master).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mbot_navigation/global_planner/goal_tolerance.h"

using namespace mbot_navigation;

namespace
{
const double kRes = 0.1;  // [m/cell]

/// A free 20 x 20 grid (2 m x 2 m, origin 0, 0).
Costmap2D freeGrid() { return Costmap2D(20, 20, kRes, 0.0, 0.0, cost::FREE); }

Pose2D centreOf(const Costmap2D& m, unsigned mx, unsigned my)
{
  Pose2D p;
  m.mapToWorld(mx, my, p.x, p.y);
  p.theta = 0.7;
  return p;
}

/// Cells (x0..x1, y0..y1) become lethal.
void wall(Costmap2D& m, unsigned x0, unsigned y0, unsigned x1, unsigned y1)
{
  for (unsigned y = y0; y <= y1; ++y)
    for (unsigned x = x0; x <= x1; ++x) m.setCost(x, y, cost::LETHAL);
}
}  // namespace

TEST(GoalTolerance, AFreeGoalIsItself)
{
  const Costmap2D m = freeGrid();
  const Pose2D goal = centreOf(m, 10, 10);
  Pose2D out;
  ASSERT_TRUE(nearestFreeGoal(m, goal, 0.5, out));
  EXPECT_DOUBLE_EQ(out.x, goal.x);
  EXPECT_DOUBLE_EQ(out.y, goal.y);
  EXPECT_DOUBLE_EQ(out.theta, goal.theta);
}

TEST(GoalTolerance, AGoalInAWallMovesToTheNearestFreeCell)
{
  Costmap2D m = freeGrid();
  wall(m, 8, 0, 12, 19);                   // a wall 5 cells thick across the map; free at x <= 7 and x >= 13
  const Pose2D goal = centreOf(m, 8, 10);  // one cell inside its left edge
  Pose2D out;
  ASSERT_TRUE(nearestFreeGoal(m, goal, 0.5, out));
  EXPECT_TRUE(isFreeGoal(m, out));
  EXPECT_NEAR(std::hypot(out.x - goal.x, out.y - goal.y), kRes, 1e-9);  // the first ring: one cell away
  unsigned mx, my;
  ASSERT_TRUE(m.worldToMap(out.x, out.y, mx, my));
  EXPECT_EQ(mx, 7u);   // left of the wall, the nearer side
  EXPECT_LE(my, 11u);  // on the ring of one cell: 22.5 degree steps reach the row above or below
  EXPECT_GE(my, 9u);
  EXPECT_DOUBLE_EQ(out.theta, goal.theta);

  // Deeper in (3 cells from the free side): the answer is 3 cells away, not less.
  const Pose2D deep = centreOf(m, 10, 10);
  ASSERT_TRUE(nearestFreeGoal(m, deep, 0.5, out));
  EXPECT_TRUE(isFreeGoal(m, out));
  EXPECT_NEAR(std::hypot(out.x - deep.x, out.y - deep.y), 3 * kRes, 1e-9);
}

TEST(GoalTolerance, NothingFreeWithinToleranceIsAFailure)
{
  Costmap2D m = freeGrid();
  wall(m, 8, 0, 12, 19);
  const Pose2D deep = centreOf(m, 10, 10);  // 3 cells from free space
  Pose2D out;
  EXPECT_FALSE(nearestFreeGoal(m, deep, 0.25, out));  // 2.5 cells
  EXPECT_TRUE(goalsAround(m, deep, 0.25).empty());
  // Unknown space is not a free goal either, nor is a goal off the map.
  Costmap2D unknown(20, 20, kRes, 0.0, 0.0, cost::NO_INFORMATION);
  EXPECT_FALSE(nearestFreeGoal(unknown, centreOf(unknown, 5, 5), 0.5, out));
  Pose2D off;
  off.x = -1.0;
  off.y = -1.0;
  EXPECT_FALSE(nearestFreeGoal(m, off, 0.05, out));
}

TEST(GoalTolerance, GoalsAroundAreNearestFirstAndWithinTolerance)
{
  const Costmap2D m = freeGrid();
  const Pose2D goal = centreOf(m, 10, 10);
  const std::vector<Pose2D> around = goalsAround(m, goal, 0.3);
  ASSERT_EQ(around.size(), 3u * 16u);  // three rings of 16 on a free map
  double previous = 0.0;
  for (const Pose2D& g : around)
  {
    const double d = std::hypot(g.x - goal.x, g.y - goal.y);
    EXPECT_GE(d, previous - 1e-9);
    EXPECT_LE(d, 0.3 + 1e-9);
    previous = d;
  }
}

TEST(GoalTolerance, PlanWithToleranceTriesTheGoalThenTheNearestOthers)
{
  Costmap2D m = freeGrid();
  wall(m, 8, 0, 12, 19);
  const Pose2D goal = centreOf(m, 8, 10);
  std::vector<Pose2D> asked;
  // A planner that only reaches goals right of the wall (x > 1.2 m): the free cells left of it
  // (the nearer ones) fail, so the search goes on until a ring reaches the right side.
  auto plan = [&](const Pose2D& g) {
    asked.push_back(g);
    PlanResult r;
    r.ok = g.x > 1.2;
    if (r.ok)
      r.path = {g};
    else
      r.error = "unreachable";
    return r;
  };
  const PlanResult r = planWithTolerance(m, goal, 0.6, plan);
  ASSERT_TRUE(r.ok);
  ASSERT_GE(asked.size(), 2u);
  EXPECT_DOUBLE_EQ(asked.front().x, goal.x);  // the goal itself first, though it is in the wall
  EXPECT_GT(r.path.front().x, 1.2);
  for (size_t i = 1; i + 1 < asked.size(); ++i) EXPECT_LE(asked[i].x, 1.2);  // all before it failed

  // Without tolerance only the goal is tried; with nothing reachable the last failure comes back.
  asked.clear();
  EXPECT_FALSE(planWithTolerance(m, goal, 0.0, plan).ok);
  EXPECT_EQ(asked.size(), 1u);
  asked.clear();
  const PlanResult none = planWithTolerance(m, goal, 0.3, plan);
  EXPECT_FALSE(none.ok);
  EXPECT_EQ(none.error, "unreachable");
  EXPECT_GT(asked.size(), 1u);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
