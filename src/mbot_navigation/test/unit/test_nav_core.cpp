// Cores of the nav node without a master: goal checks, recovery behaviours and the move_base state
// machine (Navigator) driving an ideal kinematic robot over real costmap layers.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <string>
#include <vector>

#include "mbot_navigation/global_planner/astar_planner.h"
#include "mbot_navigation/navigator/goal_checks.h"
#include "mbot_navigation/costmap/inflation_layer.h"
#include "mbot_navigation/costmap/layered_costmap.h"
#include "mbot_navigation/navigator/navigator.h"
#include "mbot_navigation/navigator/recovery.h"
#include "mbot_navigation/costmap/static_layer.h"
#include "mbot_navigation/local_planner/dwa_planner.h"
#include "mbot_navigation/local_planner/trajectory_generator.h"

using namespace mbot_navigation;

namespace
{
constexpr double kPi = 3.14159265358979;
constexpr double kRadius = 0.15;  // mbot's footprint radius [m]

bool contains(const std::string& text, const std::string& part) { return text.find(part) != std::string::npos; }

/// A 10 x 10 m occupancy map (0.05 m cells, origin (-5, -5)) with outer walls and a wall at
/// x = 0 that has a 1.2 m door at y in [-0.6, 0.6] (or no door).
std::vector<int8_t> roomsMap(bool door)
{
  const int n = 200;
  std::vector<int8_t> occ(n * n, 0);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
    {
      const double wx = -5.0 + (x + 0.5) * 0.05, wy = -5.0 + (y + 0.5) * 0.05;
      const bool outer = x < 3 || y < 3 || x >= n - 3 || y >= n - 3;
      const bool wall = std::fabs(wx) < 0.1 && !(door && std::fabs(wy) < 0.6);
      if (outer || wall) occ[y * n + x] = 100;
    }
  return occ;
}

/// The global costmap of that map: static + inflation layers.
std::unique_ptr<LayeredCostmap> globalCostmap(const std::vector<int8_t>& occ)
{
  LayeredCostmapConfig config;
  config.robot_radius = kRadius;
  auto costmap = std::make_unique<LayeredCostmap>(config);
  auto& static_layer = static_cast<StaticLayer&>(costmap->addLayer(std::make_unique<StaticLayer>()));
  InflationLayerConfig inflation;
  inflation.inflation_radius = 0.5;
  inflation.cost_scaling_factor = 5.0;
  costmap->addLayer(std::make_unique<InflationLayer>(inflation));
  static_layer.setMap(200, 200, 0.05, -5.0, -5.0, occ.data());
  costmap->updateMap(Pose2D{});
  return costmap;
}

/// A 4 x 4 m rolling window over the same map.
std::unique_ptr<LayeredCostmap> localCostmap(const std::vector<int8_t>& occ, StaticLayer*& static_layer)
{
  LayeredCostmapConfig config;
  config.rolling_window = true;
  config.width = config.height = 4.0;
  config.robot_radius = kRadius;
  auto costmap = std::make_unique<LayeredCostmap>(config);
  static_layer = static_cast<StaticLayer*>(&costmap->addLayer(std::make_unique<StaticLayer>()));
  InflationLayerConfig inflation;
  inflation.inflation_radius = 0.5;
  inflation.cost_scaling_factor = 5.0;
  costmap->addLayer(std::make_unique<InflationLayer>(inflation));
  static_layer->setMap(200, 200, 0.05, -5.0, -5.0, occ.data());
  return costmap;
}

/// A* as config/nav_move_base.yaml sets it up: smoothing only where it does not raise the path's
/// cost (the default tolerance of 0.5 pulls paths tight around door jambs, where DWA gets stuck).
std::unique_ptr<GlobalPlanner> planner()
{
  AStarConfig config;
  config.smoothing_tolerance = 0.0;
  return std::make_unique<AStarPlanner>(config);
}

DwaConfig mbotDwa()
{
  DwaConfig c;  // mbot's limits (mbot_description/config/mbot.yaml)
  c.max_vel_x = c.max_vel_trans = 0.5;
  c.min_vel_x = -0.2;
  c.max_vel_y = c.min_vel_y = 0.0;
  c.max_vel_theta = 2.0;
  c.acc_lim_x = 1.0;
  c.acc_lim_y = 0.0;
  c.acc_lim_theta = 3.0;
  c.footprint_radius = kRadius;
  return c;
}

std::unique_ptr<LocalPlanner> dwa() { return std::make_unique<DwaPlanner>(mbotDwa()); }

std::vector<std::unique_ptr<RecoveryBehavior>> standardRecoveries(int* clears)
{
  std::vector<std::unique_ptr<RecoveryBehavior>> r;
  r.push_back(std::make_unique<ClearCostmapsRecovery>([clears]() { ++*clears; }));
  RotateRecoveryConfig rotate;
  rotate.acc_lim_theta = 3.0;
  r.push_back(std::make_unique<RotateRecovery>(rotate));
  BackUpRecoveryConfig back_up;
  back_up.footprint_radius = kRadius;
  r.push_back(std::make_unique<BackUpRecovery>(back_up));
  return r;
}

/// Drives the navigator with an ideal robot (the command is executed exactly) at 20 Hz.
struct Sim
{
  Navigator& nav;
  LayeredCostmap& global;
  LayeredCostmap& local;
  Pose2D pose;
  Twist2D velocity;
  double t = 0.0;
  double travelled = 0.0;  ///< [m]
  NavCycleResult last;

  /// Run until the goal ends or `max_time` [s] passes; returns the outcome.
  NavOutcome run(double max_time)
  {
    const double dt = 0.05;
    for (; t < max_time; t += dt)
    {
      global.updateMap(pose);
      local.updateMap(pose);
      last = nav.cycle(t, pose, velocity, global.costmap(), local.costmap());
      if (last.outcome == NavOutcome::SUCCEEDED || last.outcome == NavOutcome::ABORTED) return last.outcome;
      const Pose2D next = integratePose(pose, last.cmd, dt);
      travelled += std::hypot(next.x - pose.x, next.y - pose.y);
      pose = next;
      velocity = last.cmd;
    }
    return last.outcome;
  }
};
}  // namespace

// =============================================================================================
// goal checks

TEST(GoalValues, SaysWhatIsWrong)
{
  GoalValues ok;
  ok.qz = std::sin(0.4);
  ok.qw = std::cos(0.4);
  EXPECT_EQ(checkGoalValues(ok), "");

  GoalValues nan = ok;
  nan.y = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(checkGoalValues(nan), "goal has a NaN coordinate");
  GoalValues nan_q = ok;
  nan_q.qw = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(checkGoalValues(nan_q), "goal has a NaN coordinate");

  GoalValues half;
  half.qw = 0.5;
  EXPECT_EQ(checkGoalValues(half), "goal orientation is not a unit quaternion (norm 0.50)");
  GoalValues zero;
  zero.qw = 0.0;
  EXPECT_EQ(checkGoalValues(zero), "goal orientation is not a unit quaternion (norm 0.00)");
  // 1e-3 is the tolerance: 1.0009 passes, 1.002 does not.
  GoalValues close = ok;
  close.qz *= 1.0009;
  close.qw *= 1.0009;
  EXPECT_EQ(checkGoalValues(close), "");
  GoalValues off = ok;
  off.qz *= 1.002;
  off.qw *= 1.002;
  EXPECT_EQ(checkGoalValues(off), "goal orientation is not a unit quaternion (norm 1.00)");

  GoalValues tilted;  // 90 degrees about x
  tilted.qx = std::sqrt(0.5);
  tilted.qw = std::sqrt(0.5);
  EXPECT_TRUE(contains(checkGoalValues(tilted), "not a rotation about the z axis")) << checkGoalValues(tilted);
}

TEST(StaticGoalChecker, OutsideObstacleUnreachable)
{
  // The 20 x 20 m office geometry: origin (-10, -10), 400 x 400 cells; a closed wall at x = 0.
  std::vector<int8_t> occ(400 * 400, 0);
  for (int y = 0; y < 400; ++y)
    for (int x = 198; x < 202; ++x) occ[y * 400 + x] = 100;
  LayeredCostmapConfig config;
  config.robot_radius = kRadius;
  LayeredCostmap costmap(config);
  auto& static_layer = static_cast<StaticLayer&>(costmap.addLayer(std::make_unique<StaticLayer>()));
  costmap.addLayer(std::make_unique<InflationLayer>());
  static_layer.setMap(400, 400, 0.05, -10.0, -10.0, occ.data());
  costmap.updateMap(Pose2D{});

  StaticGoalChecker checker;
  EXPECT_FALSE(checker.ready());
  EXPECT_EQ(checker.check(nullptr, Pose2D{12.0, 3.0, 0.0}), "");  // nothing to check against yet
  checker.setCostmap(costmap.costmap());
  ASSERT_TRUE(checker.ready());

  const Pose2D start{-5.0, 0.0, 0.0};
  EXPECT_EQ(checker.check(&start, Pose2D{12.0, 3.0, 0.0}),
            "goal (12.00, 3.00) is outside the map [-10, 10] x [-10, 10]");
  EXPECT_EQ(checker.check(&start, Pose2D{-3.0, -10.5, 0.0}),
            "goal (-3.00, -10.50) is outside the map [-10, 10] x [-10, 10]");
  const std::string wall = checker.check(&start, Pose2D{0.0, 1.0, 0.0});
  EXPECT_EQ(wall.rfind("goal is in an obstacle: (0.00, 1.00) is a wall of the map (cost 254)", 0), 0u) << wall;
  // 0.07 m from the wall face (x = -0.1): inside the robot's radius.
  const std::string close = checker.check(&start, Pose2D{-0.17, 1.0, 0.0});
  EXPECT_TRUE(contains(close, "goal is in an obstacle")) << close;
  EXPECT_TRUE(contains(close, "cost 253")) << close;
  const std::string other_side = checker.check(&start, Pose2D{5.0, 1.0, 0.0});
  EXPECT_EQ(other_side.rfind("no path from start to goal", 0), 0u) << other_side;
  EXPECT_EQ(checker.check(&start, Pose2D{-5.0, 8.0, 1.0}), "");
  EXPECT_EQ(checker.check(nullptr, Pose2D{5.0, 1.0, 0.0}), "");  // robot unknown: not checked

  // A robot pushed into the inflated zone still counts as standing on its side of the wall.
  const Pose2D squeezed{-0.2, 0.0, 0.0};
  EXPECT_EQ(checker.regionNear(-0.2, 0.0, 0.0), -1);
  EXPECT_EQ(checker.regionNear(-0.2, 0.0, 0.5), checker.regionNear(-5.0, 0.0, 0.0));
  EXPECT_EQ(checker.check(&squeezed, Pose2D{-5.0, 8.0, 1.0}), "");
  EXPECT_EQ(checker.check(&squeezed, Pose2D{5.0, 1.0, 0.0}).rfind("no path from start to goal", 0), 0u);
}

// =============================================================================================
// recovery behaviours

TEST(RotateRecovery, TurnsOnceWithinLimits)
{
  Costmap2D local(80, 80, 0.05, -2.0, -2.0);
  RotateRecoveryConfig config;
  config.max_vel_theta = 1.0;
  config.acc_lim_theta = 3.0;
  RotateRecovery rotate(config);
  RecoveryInput in{0.0, Pose2D{0.0, 0.0, 2.5}, Twist2D{}, &local};
  rotate.start(in);
  double turned = 0.0, last_w = 0.0, max_w = 0.0, max_dw = 0.0, first_w = -1.0;
  RecoveryStatus status = RecoveryStatus::RUNNING;
  int steps = 0;
  for (; steps < 1000 && status == RecoveryStatus::RUNNING; ++steps)
  {
    Twist2D cmd;
    status = rotate.step(in, cmd);
    if (status != RecoveryStatus::RUNNING) break;
    EXPECT_EQ(cmd.vx, 0.0);
    max_w = std::max(max_w, cmd.wz);
    if (first_w < 0.0)
      first_w = cmd.wz;
    else
      max_dw = std::max(max_dw, cmd.wz - last_w);
    last_w = cmd.wz;
    in.now += 0.05;
    in.pose.theta = mbot_common::normalizeAngle(in.pose.theta + cmd.wz * 0.05);
    turned += cmd.wz * 0.05;
  }
  EXPECT_EQ(status, RecoveryStatus::DONE);
  EXPECT_NEAR(turned, 2.0 * kPi - config.tolerance, 0.06);
  EXPECT_LE(max_w, 1.0 + 1e-9);
  // The first command is the slowest turn that moves the robot (min_vel_theta), then the
  // acceleration limit holds.
  EXPECT_DOUBLE_EQ(first_w, config.min_vel_theta);
  EXPECT_LE(max_dw, 3.0 * 0.05 + 1e-9);
  // About 2 pi / 1 rad/s plus the ramps: 6.3 .. 7.5 s.
  EXPECT_GT(steps * 0.05, 6.0);
  EXPECT_LT(steps * 0.05, 7.5);

  // A robot that does not turn: the recovery gives up after its timeout.
  RotateRecovery stuck(config);
  RecoveryInput still{0.0, Pose2D{}, Twist2D{}, &local};
  stuck.start(still);
  Twist2D cmd;
  for (still.now = 0.0; still.now < 20.0; still.now += 0.5) ASSERT_EQ(stuck.step(still, cmd), RecoveryStatus::RUNNING);
  still.now = 20.5;
  EXPECT_EQ(stuck.step(still, cmd), RecoveryStatus::FAILED);
  EXPECT_TRUE(contains(stuck.message(), "turned only 0.00")) << stuck.message();
}

TEST(BackUpRecovery, BacksUpAsFarAsTheWayIsFree)
{
  // A wall 0.5 m behind a robot at the origin facing +x: x in [-0.6, -0.5].
  Costmap2D local(80, 80, 0.05, -2.0, -2.0);
  for (unsigned y = 0; y < 80; ++y)
    for (unsigned x = 28; x < 30; ++x) local.setCost(x, y, cost::LETHAL);
  const Pose2D pose{0.0, 0.0, 0.0};
  // The footprint (0.15 m) reaches the wall face (x = -0.6 .. -0.5 cell centres -0.575, -0.525)
  // after 0.525 - 0.15 = 0.375 m.
  EXPECT_NEAR(BackUpRecovery::freeDistanceBehind(local, pose, 1.0, kRadius), 0.375, 0.026);
  EXPECT_DOUBLE_EQ(BackUpRecovery::freeDistanceBehind(local, pose, 0.3, kRadius), 0.3);
  // Obstacles beside or ahead of the robot do not stop it backing away from them.
  Costmap2D touching = local;
  for (unsigned y = 37; y < 43; ++y) touching.setCost(43, y, cost::LETHAL);  // 0.15 m ahead
  EXPECT_DOUBLE_EQ(BackUpRecovery::freeDistanceBehind(touching, pose, 0.3, kRadius), 0.3);

  BackUpRecoveryConfig config;
  config.distance = 0.3;
  config.speed = 0.1;
  config.footprint_radius = kRadius;
  BackUpRecovery back_up(config);
  RecoveryInput in{0.0, pose, Twist2D{}, &local};
  back_up.start(in);
  Twist2D cmd;
  RecoveryStatus status;
  int steps = 0;
  while ((status = back_up.step(in, cmd)) == RecoveryStatus::RUNNING && steps++ < 200)
  {
    EXPECT_DOUBLE_EQ(cmd.vx, -0.1);
    in.pose = integratePose(in.pose, cmd, 0.05);
    in.now += 0.05;
  }
  EXPECT_EQ(status, RecoveryStatus::DONE);
  EXPECT_NEAR(in.pose.x, -0.3, 0.006);

  // Against the wall: nowhere to go.
  BackUpRecovery blocked(config);
  RecoveryInput at_wall{0.0, Pose2D{-0.33, 0.0, 0.0}, Twist2D{}, &local};
  blocked.start(at_wall);
  EXPECT_EQ(blocked.step(at_wall, cmd), RecoveryStatus::FAILED);
  EXPECT_TRUE(contains(blocked.message(), "no room to back up")) << blocked.message();
  EXPECT_EQ(cmd.vx, 0.0);
}

// =============================================================================================
// the state machine

TEST(Navigator, ReachesAGoalThroughADoor)
{
  const std::vector<int8_t> occ = roomsMap(true);
  auto global = globalCostmap(occ);
  StaticLayer* local_static = nullptr;
  auto local = localCostmap(occ, local_static);
  int clears = 0;
  Navigator nav(NavigatorConfig(), dwa(), planner(), standardRecoveries(&clears));
  EXPECT_EQ(nav.state(), NavState::IDLE);

  const Pose2D goal{2.5, 2.0, kPi / 2};
  nav.setGoal(goal, 0.0);
  EXPECT_EQ(nav.state(), NavState::PLANNING);
  Sim sim{nav, *global, *local, Pose2D{-2.5, -2.0, 0.0}};
  const NavOutcome outcome = sim.run(120.0);
  ASSERT_EQ(outcome, NavOutcome::SUCCEEDED) << sim.last.text << " at t = " << sim.t;
  EXPECT_EQ(nav.state(), NavState::IDLE);
  EXPECT_LT(std::hypot(sim.pose.x - goal.x, sim.pose.y - goal.y), 0.1 + 1e-6);
  EXPECT_LT(std::fabs(mbot_common::angleDiff(sim.pose.theta, goal.theta)), 0.1 + 1e-6);
  // Through the door: (-2.5, -2) -> (0, 0) -> (2.5, 2) is 6.40 m; allow 15 % for the curves.
  EXPECT_GT(sim.travelled, 6.3);
  EXPECT_LT(sim.travelled, 6.40 * 1.15);
  EXPECT_LT(sim.t, 40.0);
  EXPECT_EQ(clears, 0);
  EXPECT_TRUE(nav.recoveriesTried().empty());
}

TEST(Navigator, ReplansWhenThePlanIsBlocked)
{
  // Two doors: the plan takes the lower one; it is then closed in the global costmap, and the
  // navigator must notice at once and take the upper one.
  std::vector<int8_t> occ(200 * 200, 0);
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x)
    {
      const double wx = -5.0 + (x + 0.5) * 0.05, wy = -5.0 + (y + 0.5) * 0.05;
      const bool door = std::fabs(wy + 1.0) < 0.6 || std::fabs(wy - 3.0) < 0.6;
      if (x < 3 || y < 3 || x >= 197 || y >= 197 || (std::fabs(wx) < 0.1 && !door)) occ[y * 200 + x] = 100;
    }
  auto global = globalCostmap(occ);
  StaticLayer* local_static = nullptr;
  auto local = localCostmap(occ, local_static);
  int clears = 0;
  Navigator nav(NavigatorConfig(), dwa(), planner(), standardRecoveries(&clears));
  nav.setGoal(Pose2D{2.5, -1.0, 0.0}, 0.0);
  Sim sim{nav, *global, *local, Pose2D{-2.5, -1.0, 0.0}};
  sim.run(0.5);
  ASSERT_EQ(nav.state(), NavState::CONTROLLING);
  double max_y = -10.0;
  for (const Pose2D& p : nav.globalPlan()) max_y = std::max(max_y, p.y);
  EXPECT_LT(max_y, 0.0);  // through the lower door

  // Close the lower door (a static map update, as a sensed obstacle would).
  for (int y = 0; y < 200; ++y)
    for (int x = 0; x < 200; ++x)
    {
      const double wx = -5.0 + (x + 0.5) * 0.05, wy = -5.0 + (y + 0.5) * 0.05;
      if (std::fabs(wx) < 0.1 && std::fabs(wy + 1.0) < 0.6) occ[y * 200 + x] = 100;
    }
  auto& global_static = static_cast<StaticLayer&>(global->layer(0));
  global_static.setMap(200, 200, 0.05, -5.0, -5.0, occ.data());
  local_static->setMap(200, 200, 0.05, -5.0, -5.0, occ.data());
  global->updateMap(sim.pose);
  const NavCycleResult r = nav.cycle(sim.t, sim.pose, sim.velocity, global->costmap(), local->costmap());
  EXPECT_TRUE(r.plan_updated);
  ASSERT_FALSE(nav.globalPlan().empty());
  max_y = -10.0;
  for (const Pose2D& p : nav.globalPlan()) max_y = std::max(max_y, p.y);
  EXPECT_GT(max_y, 2.5);  // now through the upper door
  EXPECT_EQ(Navigator::firstBlockedPose(global->costmap(), nav.globalPlan(), 0, true), -1);
  EXPECT_EQ(sim.run(120.0), NavOutcome::SUCCEEDED) << sim.last.text;
}

TEST(Navigator, AbortsAfterPatienceAndRecoveriesWithTheReason)
{
  // No door: the goal is unreachable. Planner patience 5 s, then clear, rotate, back up, each
  // followed by another 5 s of planning, then ABORTED naming the planner's error and the recoveries.
  const std::vector<int8_t> occ = roomsMap(false);
  auto global = globalCostmap(occ);
  StaticLayer* local_static = nullptr;
  auto local = localCostmap(occ, local_static);
  int clears = 0;
  NavigatorConfig config;
  Navigator nav(config, dwa(), planner(), standardRecoveries(&clears));
  nav.setGoal(Pose2D{2.5, 2.0, 0.0}, 0.0);
  Sim sim{nav, *global, *local, Pose2D{-2.5, -2.0, 0.0}};
  ASSERT_EQ(sim.run(200.0), NavOutcome::ABORTED);
  const std::string& text = sim.last.text;
  EXPECT_EQ(text.rfind("the global planner (astar) found no valid plan for 5.0 s: ", 0), 0u) << text;
  EXPECT_TRUE(contains(text, "unreachable")) << text;
  EXPECT_TRUE(contains(text, "recoveries tried: clear_costmaps, rotate_recovery, back_up")) << text;
  EXPECT_EQ(clears, 1);
  // 4 x 5 s of patience plus a turn (about 7 s) and a 0.3 m back-up (3 s).
  EXPECT_GT(sim.t, 4 * 5.0 + 6.0 + 2.5);
  EXPECT_LT(sim.t, 4 * 5.0 + 7.5 + 3.5 + 1.0);
  EXPECT_EQ(nav.state(), NavState::IDLE);
  EXPECT_TRUE(nav.globalPlan().empty());

  // Without recoveries: aborted right after the patience.
  NavigatorConfig no_recovery;
  no_recovery.recovery_behavior_enabled = false;
  no_recovery.planner_patience = 2.0;
  Navigator nav2(no_recovery, dwa(), planner(), standardRecoveries(&clears));
  nav2.setGoal(Pose2D{2.5, 2.0, 0.0}, 0.0);
  Sim sim2{nav2, *global, *local, Pose2D{-2.5, -2.0, 0.0}};
  ASSERT_EQ(sim2.run(50.0), NavOutcome::ABORTED);
  EXPECT_NEAR(sim2.t, 2.05, 0.051);
  EXPECT_TRUE(contains(sim2.last.text, "(recovery behaviours are disabled)")) << sim2.last.text;
}

TEST(Navigator, CancelStopsAndANewGoalReplaces)
{
  const std::vector<int8_t> occ = roomsMap(true);
  auto global = globalCostmap(occ);
  StaticLayer* local_static = nullptr;
  auto local = localCostmap(occ, local_static);
  int clears = 0;
  Navigator nav(NavigatorConfig(), dwa(), planner(), standardRecoveries(&clears));
  nav.setGoal(Pose2D{2.5, 2.0, 0.0}, 0.0);
  Sim sim{nav, *global, *local, Pose2D{-2.5, -2.0, 0.0}};
  sim.run(3.0);
  EXPECT_EQ(nav.state(), NavState::CONTROLLING);
  EXPECT_GT(std::hypot(sim.last.cmd.vx, sim.last.cmd.wz), 0.05);
  nav.cancel();
  const NavCycleResult idle = nav.cycle(sim.t, sim.pose, sim.velocity, global->costmap(), local->costmap());
  EXPECT_EQ(idle.outcome, NavOutcome::NONE);
  EXPECT_EQ(idle.cmd.vx, 0.0);
  EXPECT_EQ(idle.cmd.wz, 0.0);

  // A new goal in the same room.
  nav.setGoal(Pose2D{-3.0, 2.0, 0.0}, sim.t);
  EXPECT_EQ(sim.run(sim.t + 60.0), NavOutcome::SUCCEEDED) << sim.last.text;
  EXPECT_LT(std::hypot(sim.pose.x + 3.0, sim.pose.y - 2.0), 0.1 + 1e-6);
}

TEST(Navigator, PlansOutOfAnInflatedStart)
{
  const std::vector<int8_t> occ = roomsMap(true);
  auto global = globalCostmap(occ);
  int clears = 0;
  Navigator nav(NavigatorConfig(), dwa(), planner(), standardRecoveries(&clears));
  // 0.075 m from the wall face at x = -0.1: inside the inscribed radius.
  const Pose2D start{-0.17, 2.0, 0.0};
  unsigned mx, my;
  ASSERT_TRUE(global->costmap().worldToMap(start.x, start.y, mx, my));
  ASSERT_GE(global->costmap().cost(mx, my), cost::INSCRIBED);
  AStarConfig plain_config;
  AStarPlanner plain(plain_config);
  EXPECT_FALSE(plain.makePlan(global->costmap(), start, Pose2D{-3.0, 2.0, 0.0}).ok);
  const PlanResult plan = nav.makePlan(global->costmap(), start, Pose2D{-3.0, 2.0, 0.0});
  ASSERT_TRUE(plan.ok) << plan.error;
  EXPECT_DOUBLE_EQ(plan.path.front().x, start.x);
  EXPECT_DOUBLE_EQ(plan.path.front().y, start.y);
  EXPECT_LT(std::hypot(plan.path[1].x - start.x, plan.path[1].y - start.y), 0.1);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
