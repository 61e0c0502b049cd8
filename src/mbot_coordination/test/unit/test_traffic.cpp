// The live planner's core: planning grid from a map, timed waypoints, marked poses, following
// conflicts, goal sets (reader and checks), re-planning around fixed paths.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <fstream>

#include "mbot_common/map_io.h"
#include "mbot_coordination/sipp.h"
#include "mbot_coordination/traffic.h"

using namespace mbot_coordination;

namespace
{
// A 4 x 2 m map at 0.05 m, free, with a wall row at y in [1.0, 1.05) from x = 0 to 2 m.
mbot_common::OccupancyMap smallMap()
{
  mbot_common::OccupancyMap map;
  map.width = 80;
  map.height = 40;
  map.resolution = 0.05;
  map.origin_x = -1.0;
  map.origin_y = -1.0;
  map.data.assign(80 * 40, 0);
  for (int x = 0; x < 40; ++x) map.data[20 * 80 + x] = 100;
  return map;
}

std::string writeFile(const std::string& name, const std::string& text)
{
  const std::string path = testing::TempDir() + name;
  std::ofstream(path) << text;
  return path;
}

std::string goalError(const std::vector<FleetGoal>& goals, const PlanningGrid& grid)
{
  try
  {
    checkGoals(goals, {"robot_0", "robot_1"}, grid);
  }
  catch (const std::invalid_argument& e)
  {
    return e.what();
  }
  return "";
}

std::string fileError(const std::string& text)
{
  try
  {
    readGoalsFile(writeFile("goals.yaml", text));
  }
  catch (const mbot_common::ConfigError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(PlanningGrid, CoarseCellsBlockedNearWallsAndMapFrame)
{
  const PlanningGrid g = makePlanningGrid(smallMap(), 0.5, 0.15);
  EXPECT_EQ(g.grid.width(), 8);
  EXPECT_EQ(g.grid.height(), 4);
  // The wall at y = 0.0 m (row 20) from x = -1 to 1 m: cells of rows 1 and 2 (y in [-0.5, 0.5))
  // lie within 0.15 m of it for x < 1.15 m, so columns 0..4 (x < 1.5) are blocked there.
  for (int cx = 0; cx < 8; ++cx)
  {
    // beyond the map is unknown: the border cells (column 7, rows 0 and 3) are blocked too
    EXPECT_EQ(g.grid.isFree(cx, 1), cx >= 5 && cx <= 6) << cx;
    EXPECT_EQ(g.grid.isFree(cx, 2), cx >= 5 && cx <= 6) << cx;
    EXPECT_FALSE(g.grid.isFree(cx, 0)) << cx;
    EXPECT_FALSE(g.grid.isFree(cx, 3)) << cx;
  }
  const int c = g.cellAt(1.3, 0.2);
  EXPECT_EQ(g.grid.x(c), 4);
  EXPECT_EQ(g.grid.y(c), 2);
  EXPECT_NEAR(g.centre(c).x, 1.25, 1e-12);
  EXPECT_NEAR(g.centre(c).y, 0.25, 1e-12);
  EXPECT_EQ(g.cellAt(3.1, 0.0), -1);
  EXPECT_EQ(g.cellAt(NAN, 0.0), -1);
  EXPECT_EQ(g.grid.x(g.nearestFreeCell(1.3, 0.2)), 5);
}

TEST(PlanningGrid, RefusesCellsSmallerThanTheRobotAndRotatedMaps)
{
  try
  {
    makePlanningGrid(smallMap(), 0.25, 0.15);
    FAIL() << "no error";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("smaller than the robot's diameter 0.3 m"), std::string::npos) << e.what();
  }
  auto rotated = smallMap();
  rotated.origin_yaw = 0.1;
  EXPECT_THROW(makePlanningGrid(rotated, 0.5, 0.15), std::invalid_argument);
}

TEST(PlanningGrid, CorridorMapHasTwoLanes)
{
  // maps/corridor.yaml: a 1.5 m wide corridor (y in [-0.75, 0.75]) from x = -10 to 10 m.
  const auto map = mbot_common::loadMap(MAPS_DIR "/corridor.yaml");
  const PlanningGrid g = makePlanningGrid(map, 0.5, 0.15);
  int free_rows = 0;
  for (int cy = 0; cy < g.grid.height(); ++cy)
    if (g.grid.isFree(g.cellAt(0.0, g.origin_y + (cy + 0.5) * 0.5))) ++free_rows;
  EXPECT_EQ(free_rows, 2);  // [-0.5, 0) and [0, 0.5): 0.25 m from the walls, > 0.15
  EXPECT_EQ(g.grid.distancesTo(g.cellAt(8.2, 0.2))[g.cellAt(-8.2, 0.2)], 33);
}

TEST(TimedWaypoints, CellCentresTimesWaitsAndYaw)
{
  const PlanningGrid g = makePlanningGrid(smallMap(), 0.5, 0.15);
  const int a = g.grid.id(5, 1), b = g.grid.id(6, 1), c = g.grid.id(6, 2);
  const auto poses = timedWaypoints(g, {a, b, b, c}, 10.0, 0.25, 1.0);
  ASSERT_EQ(poses.size(), 4u);
  EXPECT_NEAR(poses[0].x, 1.75, 1e-12);
  EXPECT_NEAR(poses[0].y, -0.25, 1e-12);
  for (size_t k = 0; k < 4; ++k) EXPECT_NEAR(poses[k].t, 10.0 + 2.0 * k, 1e-12);  // 0.5 m at 0.25 m/s
  EXPECT_EQ(poses[1].x, poses[2].x);  // the wait: one pose twice, later time
  EXPECT_EQ(poses[1].y, poses[2].y);
  EXPECT_NEAR(poses[0].yaw, 0.0, 1e-12);       // east
  EXPECT_NEAR(poses[1].yaw, M_PI / 2, 1e-12);  // then north
  EXPECT_NEAR(poses[3].yaw, 1.0, 1e-12);       // the goal's yaw
  EXPECT_THROW(timedWaypoints(g, {a}, 0.0, 0.0, 0.0), std::invalid_argument);
}

TEST(MarkedPoses, WaitsCornersHeldCellsAndEnds)
{
  // a row 0 1 2 3, wait at 3, then 13 (up), 23: marks 0, 3 (wait and corner), 6 (last)
  const std::vector<int> path{0, 1, 2, 3, 3, 13, 23};
  EXPECT_EQ(markedPoses(path, {}), (std::vector<size_t>{0, 3, 6}));
  EXPECT_EQ(waitEnd(path, 3), 4u);
  EXPECT_EQ(waitEnd(path, 1), 1u);
  // hold before index 2 (cell 2 shared with another robot): index 1 is marked too
  std::vector<bool> hold(path.size(), false);
  hold[2] = true;
  EXPECT_EQ(markedPoses(path, hold), (std::vector<size_t>{0, 1, 3, 6}));
  // hold before index 5 (after the wait): the wait's first pose is already marked
  hold.assign(path.size(), false);
  hold[5] = true;
  EXPECT_EQ(markedPoses(path, hold), (std::vector<size_t>{0, 3, 6}));
}

TEST(Following, PlannersKeepOneStepBetweenRobots)
{
  // a 1 x 7 corridor: agent 0 from 0 to 4, agent 1 from 1 to 5, both east
  const Grid grid(7, 1, std::vector<uint8_t>(7, 1));
  Instance inst{&grid, {0, 1}, {4, 5}};
  PlannerOptions options;
  options.time_limit_s = 5.0;
  auto plain = makePlanner("pp")->solve(inst, options);
  ASSERT_TRUE(plain.solved);
  EXPECT_EQ(validate(inst, plain.paths), "");
  // without the option, agent 0 enters cell 1 just as agent 1 leaves it
  EXPECT_NE(validate(inst, plain.paths, true).find("following conflict"), std::string::npos);
  options.following = true;
  for (const std::string name : {"pp", "auto"})
  {
    auto r = makePlanner(name)->solve(inst, options);
    ASSERT_TRUE(r.solved) << name << ": " << r.message;
    EXPECT_EQ(validate(inst, r.paths, true), "") << name;
    EXPECT_EQ(sumOfCosts(r.paths), 9) << name;  // agent 0 starts one step later
  }
  for (const std::string name : {"lacam", "ecbs", "eecbs"})
    EXPECT_THROW(makePlanner(name)->solve(inst, options), std::invalid_argument) << name;
  // the earlier-planned agent may not enter a later agent's start one step after t = 0 either:
  // agent 0 (short journey, planned first) from 2 to 3, agent 1 from 3 to 6
  Instance ahead{&grid, {2, 3}, {3, 6}};
  auto r = makePlanner("pp")->solve(ahead, options);
  ASSERT_TRUE(r.solved);
  EXPECT_EQ(validate(ahead, r.paths, true), "");
}

TEST(Following, RandomMapThirtyAgentsValidWithLns)
{
  const Grid grid = readMap(MAPF_BENCH_DIR "/random-32-32-10.map");
  const Instance inst = instanceFromScen(grid, readScen(MAPF_BENCH_DIR "/random-32-32-10-random-1.scen", &grid), 30);
  PlannerOptions options;
  options.time_limit_s = 20.0;
  options.following = true;
  auto r = makePlanner("auto")->solve(inst, options);
  ASSERT_TRUE(r.solved) << r.message;
  EXPECT_EQ(validate(inst, r.paths, true), "");
  EXPECT_GE(sumOfCosts(r.paths), lowerBound(inst));
}

TEST(Goals, CheckedWithClearMessages)
{
  const PlanningGrid g = makePlanningGrid(smallMap(), 0.5, 0.15);
  EXPECT_EQ(goalError({{"robot_0", 1.8, -0.2, 0.0}, {"robot_1", 2.3, 0.2, 0.0}}, g), "");
  EXPECT_EQ(goalError({}, g), "no goals");
  EXPECT_EQ(goalError({{"robot_7", 1.8, -0.2, 0.0}}, g), "unknown robot 'robot_7' (known: robot_0, robot_1)");
  EXPECT_EQ(goalError({{"robot_0", 1.8, -0.2, 0.0}, {"robot_0", 2.3, 0.2, 0.0}}, g),
            "robot_0: two goals for one robot");
  EXPECT_EQ(goalError({{"robot_0", NAN, -0.2, 0.0}}, g), "robot_0: goal (nan, -0.2, 0) is not a finite pose");
  EXPECT_EQ(goalError({{"robot_0", 1.0, 0.0, INFINITY}}, g), "robot_0: goal (1, 0, inf) is not a finite pose");
  EXPECT_EQ(goalError({{"robot_0", 5.0, 0.0, 0.0}}, g),
            "robot_0: goal (5, 0, 0) is outside the map ([-1, 3] x [-1, 1] m)");
  EXPECT_EQ(goalError({{"robot_0", 0.0, 0.0, 0.0}}, g),
            "robot_0: goal (0, 0, 0) is in a wall or too close to one for the robot (planning cell of 0.5 m blocked)");
  EXPECT_EQ(goalError({{"robot_0", 1.8, -0.2, 0.0}, {"robot_1", 1.7, -0.1, 0.0}}, g),
            "robot_0 and robot_1: two robots, one goal (the same planning cell of 0.5 m)");
}

TEST(Goals, FileReaderIsStrict)
{
  const auto goals = readGoalsFile(writeFile("ok.yaml", "goals:\n  robot_0: [1.0, 2.0, 0.5]\n  robot_1: [-1, 0, 0]\n"));
  ASSERT_EQ(goals.size(), 2u);
  EXPECT_EQ(goals[0].robot, "robot_0");
  EXPECT_EQ(goals[0].y, 2.0);
  EXPECT_EQ(goals[1].x, -1.0);
  const auto has = [](const std::string& error, const std::string& part) {
    return error.find(part) != std::string::npos;
  };
  std::string e = fileError("goal:\n  robot_0: [1, 2, 0]\n");
  EXPECT_TRUE(has(e, "goal: unknown key")) << e;
  e = fileError("goals:\n  robot_0: [1, .nan, 0]\n");
  EXPECT_TRUE(has(e, "goals.robot_0: expected [x, y, yaw] in m, m, rad (3 finite numbers)")) << e;
  e = fileError("goals:\n  robot_0: [1, 2]\n");
  EXPECT_TRUE(has(e, "goals.robot_0: expected")) << e;
  e = fileError("goals: {}\n");
  EXPECT_TRUE(has(e, "goals: expected a map robot name")) << e;
  e = fileError("goals:\n  robot_0: [1, 2, 0]\n  robot_0: [2, 2, 0]\n");
  EXPECT_FALSE(e.empty());
  EXPECT_THROW(readGoalsFile("/nonexistent/goals.yaml"), mbot_common::ConfigError);
}

TEST(PlanAround, ReplannedRobotsAvoidFixedPaths)
{
  // a 5 x 3 grid; a fixed robot crosses the middle row west to east; robot A goes north-south
  // through the middle column and must let it pass
  const Grid grid(5, 3, std::vector<uint8_t>(15, 1));
  const Paths fixed{{5, 6, 7, 8, 9}};
  PlannerOptions options;
  options.time_limit_s = 2.0;
  options.following = true;
  const Paths paths = planAround(grid, fixed, {2}, {12}, options);
  ASSERT_EQ(paths.size(), 1u);
  const Instance all{&grid, {5, 2}, {9, 12}};
  EXPECT_EQ(validate(all, {fixed[0], paths[0]}, true), "");
  EXPECT_GT(agentCost(paths[0]), 2);  // it waited or went round
  // a robot walled in by a parked fixed robot on its only way: no path, and why
  const Grid line(3, 1, std::vector<uint8_t>(3, 1));
  std::string why;
  EXPECT_TRUE(planAround(line, {{1}}, {0}, {2}, options, &why).empty());
  EXPECT_NE(why.find("robot 0 found no path"), std::string::npos) << why;
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
