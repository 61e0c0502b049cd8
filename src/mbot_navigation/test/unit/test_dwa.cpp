/**
 * @file test_dwa.cpp
 * @brief DWA local planner, without ROS: the robot is simulated kinematically with the commands
 *        the planner returns (the velocity reached is the velocity commanded).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <string>
#include <vector>

#include "mbot_navigation/local_planner/dwa_planner.h"

using namespace mbot_navigation;

namespace
{
constexpr double kRadius = 0.15;  // mbot's footprint radius [m]

DwaConfig diffDriveConfig()
{
  DwaConfig c;  // dwa_local_planner's defaults
  c.footprint_radius = kRadius;
  c.max_vel_y = 0.0;
  c.min_vel_y = 0.0;
  return c;
}

DwaConfig omniConfig()
{
  DwaConfig c;  // the defaults sample v_y in [-0.1, 0.1]
  c.footprint_radius = kRadius;
  return c;
}

/// mbot_omni's limits (mbot_description/config/mbot_omni.yaml); `omni` false: the same robot
/// without v_y, as a differential drive.
DwaConfig mbotOmniConfig(bool omni)
{
  DwaConfig c;
  c.footprint_radius = kRadius;
  c.max_vel_x = 0.4;
  c.min_vel_x = -0.4;
  c.max_vel_y = omni ? 0.4 : 0.0;
  c.min_vel_y = omni ? -0.4 : 0.0;
  c.max_vel_theta = 1.5;
  c.acc_lim_x = 1.0;
  c.acc_lim_y = 1.0;
  c.acc_lim_theta = 2.5;
  return c;
}

/// Straight plan from (x0, y0) to (x1, y1), one pose per 0.05 m facing along it; the last pose
/// has yaw `goal_yaw`.
std::vector<Pose2D> straightPlan(double x0, double y0, double x1, double y1, double goal_yaw)
{
  std::vector<Pose2D> plan;
  const double len = std::hypot(x1 - x0, y1 - y0);
  const int n = std::max(1, static_cast<int>(std::ceil(len / 0.05)));
  const double heading = std::atan2(y1 - y0, x1 - x0);
  for (int i = 0; i <= n; ++i)
  {
    const double t = static_cast<double>(i) / n;
    plan.push_back(Pose2D{x0 + t * (x1 - x0), y0 + t * (y1 - y0), heading});
  }
  plan.back().theta = goal_yaw;
  return plan;
}

/// Mark the cells of the world rectangle [x0, x1] x [y0, y1] [m] with `c`.
void fillBox(Costmap2D& map, double x0, double y0, double x1, double y1, uint8_t c = cost::LETHAL)
{
  for (unsigned my = 0; my < map.sizeY(); ++my)
    for (unsigned mx = 0; mx < map.sizeX(); ++mx)
    {
      double wx, wy;
      map.mapToWorld(mx, my, wx, wy);
      if (wx >= x0 && wx <= x1 && wy >= y0 && wy <= y1) map.setCost(mx, my, c);
    }
}

/// Highest cost of the cells the robot's disc covers at (x, y): every cell whose square
/// intersects the disc (found independently of the planner's own check).
int maxCostUnderFootprint(const Costmap2D& map, double x, double y)
{
  int worst = 0;
  const double res = map.resolution();
  const int r = static_cast<int>(std::ceil(kRadius / res)) + 1;
  const int cx = static_cast<int>(std::floor((x - map.originX()) / res));
  const int cy = static_cast<int>(std::floor((y - map.originY()) / res));
  for (int my = std::max(0, cy - r); my <= std::min<int>(map.sizeY() - 1, cy + r); ++my)
    for (int mx = std::max(0, cx - r); mx <= std::min<int>(map.sizeX() - 1, cx + r); ++mx)
    {
      const double cx0 = map.originX() + mx * res, cy0 = map.originY() + my * res;
      // Closest point of the cell's square to the centre.
      const double px = std::clamp(x, cx0, cx0 + res), py = std::clamp(y, cy0, cy0 + res);
      if (std::hypot(px - x, py - y) < kRadius) worst = std::max<int>(worst, map.cost(mx, my));
    }
  return worst;
}

/// The robot's rolling local costmap: 4 x 4 m at the world map's resolution, centred on the
/// robot (origin snapped to the world grid), costs copied from the world map, as the nav node's
/// local costmap would hold them. Cells beyond the world map are NO_INFORMATION.
Costmap2D localWindow(const Costmap2D& world, const Pose2D& robot)
{
  const double res = world.resolution();
  const int n = static_cast<int>(std::lround(4.0 / res));
  const int x0 = static_cast<int>(std::floor((robot.x - world.originX()) / res)) - n / 2;
  const int y0 = static_cast<int>(std::floor((robot.y - world.originY()) / res)) - n / 2;
  Costmap2D local(n, n, res, world.originX() + x0 * res, world.originY() + y0 * res, cost::NO_INFORMATION);
  for (int y = 0; y < n; ++y)
    for (int x = 0; x < n; ++x)
    {
      const int wx = x0 + x, wy = y0 + y;
      if (wx >= 0 && wy >= 0 && wx < static_cast<int>(world.sizeX()) && wy < static_cast<int>(world.sizeY()))
        local.setCost(x, y, world.cost(wx, wy));
    }
  return local;
}

/// One closed-loop run: the planner's commands move the robot for one control period each.
struct ClosedLoopRun
{
  std::vector<Pose2D> poses;             ///< robot pose before each cycle
  std::vector<Twist2D> commands;         ///< command of each cycle
  std::vector<LocalPlanResult> results;  ///< result of each cycle
  bool reached = false;                  ///< isGoalReached became true
  Pose2D final_pose;
  Twist2D final_velocity;
};

ClosedLoopRun simulate(DwaPlanner& planner, const Costmap2D& world, Pose2D pose, int max_cycles,
                       bool stop_when_reached = true)
{
  ClosedLoopRun run;
  Twist2D velocity;
  const double dt = planner.config().simPeriod();
  for (int i = 0; i < max_cycles; ++i)
  {
    if (planner.isGoalReached(pose, velocity))
    {
      run.reached = true;
      if (stop_when_reached) break;
    }
    Twist2D cmd;
    run.poses.push_back(pose);
    run.results.push_back(planner.computeVelocityCommands(pose, velocity, localWindow(world, pose), cmd));
    run.commands.push_back(cmd);
    velocity = cmd;
    for (int k = 0; k < 10; ++k) pose = integratePose(pose, velocity, dt / 10);
  }
  run.final_pose = pose;
  run.final_velocity = velocity;
  return run;
}

/// Every command differs from the one before (the robot's velocity) by at most acc * dt.
void expectWithinAccelerationLimits(const ClosedLoopRun& run, const DwaConfig& c)
{
  const double dt = c.simPeriod();
  Twist2D previous;  // the robot starts at rest
  for (size_t i = 0; i < run.commands.size(); ++i)
  {
    if (!run.results[i].ok) break;  // a failure commands zero at once (recoveries take over)
    const Twist2D& cmd = run.commands[i];
    EXPECT_LE(std::fabs(cmd.vx - previous.vx), c.acc_lim_x * dt + 1e-9) << "cycle " << i;
    EXPECT_LE(std::fabs(cmd.vy - previous.vy), c.acc_lim_y * dt + 1e-9) << "cycle " << i;
    EXPECT_LE(std::fabs(cmd.wz - previous.wz), c.acc_lim_theta * dt + 1e-9) << "cycle " << i;
    previous = cmd;
  }
}
}  // namespace

TEST(TrajectoryGenerator, SamplesTheDynamicWindow)
{
  const DwaConfig c = diffDriveConfig();
  TrajectoryGenerator generator(c);
  generator.initialise(Twist2D{0.3, 0.0, 0.0});
  const double dv = c.acc_lim_x * c.simPeriod();      // 0.125 m/s
  const double dw = c.acc_lim_theta * c.simPeriod();  // 0.16 rad/s
  double min_x = 1e9, max_x = -1e9, min_w = 1e9, max_w = -1e9;
  for (const Twist2D& s : generator.samples())
  {
    min_x = std::min(min_x, s.vx);
    max_x = std::max(max_x, s.vx);
    min_w = std::min(min_w, s.wz);
    max_w = std::max(max_w, s.wz);
    EXPECT_EQ(s.vy, 0.0);
  }
  EXPECT_NEAR(min_x, 0.3 - dv, 1e-12);
  EXPECT_NEAR(max_x, 0.3 + dv, 1e-12);
  EXPECT_NEAR(min_w, -dw, 1e-12);
  EXPECT_NEAR(max_w, dw, 1e-12);
  // 3 v_x samples x (20 omega samples + the added 0, as the range crosses 0)
  EXPECT_EQ(generator.samples().size(), 3u * 21u);

  // Near max_vel_x the window is clipped.
  generator.initialise(Twist2D{0.5, 0.0, 0.0});
  for (const Twist2D& s : generator.samples()) EXPECT_LE(s.vx, c.max_vel_x);

  // A trajectory lasts sim_time, with steps of at most sim_granularity.
  Trajectory t;
  ASSERT_TRUE(generator.generate(Pose2D{1.0, 2.0, 0.0}, Twist2D{0.5, 0.0, 0.0}, t));
  EXPECT_NEAR(t.poses.back().x, 1.0 + 0.5 * c.sim_time, 1e-9);
  EXPECT_NEAR(t.time_delta * (t.poses.size() - 1), c.sim_time, 1e-9);
  for (size_t i = 1; i < t.poses.size(); ++i)
    EXPECT_LE(std::hypot(t.poses[i].x - t.poses[i - 1].x, t.poses[i].y - t.poses[i - 1].y), c.sim_granularity + 1e-12);
  // Too slow to move: rejected.
  EXPECT_FALSE(generator.generate(Pose2D{}, Twist2D{0.05, 0.0, 0.1}, t));
}

TEST(DwaConfig, RejectsAMissingFootprint)
{
  DwaConfig c;
  try
  {
    DwaPlanner planner(c);
    FAIL() << "expected std::invalid_argument";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("footprint_radius"), std::string::npos) << e.what();
  }
}

TEST(DwaPlanner, FailsWithoutAPlan)
{
  DwaPlanner planner(diffDriveConfig());
  Costmap2D map(80, 80, 0.05, 0.0, 0.0);
  Twist2D cmd{1.0, 1.0, 1.0};
  const LocalPlanResult r = planner.computeVelocityCommands(Pose2D{2.0, 2.0, 0.0}, Twist2D{}, map, cmd);
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("no global plan"), std::string::npos) << r.error;
  EXPECT_EQ(cmd.vx, 0.0);
  EXPECT_EQ(cmd.wz, 0.0);
}

TEST(DwaPlanner, FollowsAStraightPlanAtFullSpeed)
{
  const DwaConfig c = diffDriveConfig();
  DwaPlanner planner(c);
  Costmap2D map(160, 80, 0.05, 0.0, 0.0);  // 8 x 4 m, free
  planner.setPlan(straightPlan(0.5, 2.0, 7.5, 2.0, 0.0));
  const ClosedLoopRun run = simulate(planner, map, Pose2D{0.5, 2.0, 0.0}, 60);  // 3 s
  ASSERT_EQ(run.commands.size(), 60u);
  for (size_t i = 0; i < run.results.size(); ++i) ASSERT_TRUE(run.results[i].ok) << run.results[i].error;

  // From rest, max_vel_x is reachable after 0.55 / 0.125 = 5 cycles; from 1 s on it cruises.
  for (size_t i = 20; i < run.commands.size(); ++i)
  {
    EXPECT_GE(run.commands[i].vx, 0.95 * c.max_vel_x) << "cycle " << i;
    EXPECT_LE(run.commands[i].vx, c.max_vel_x + 1e-12) << "cycle " << i;
    EXPECT_LT(std::fabs(run.commands[i].wz), 0.05) << "cycle " << i;
    EXPECT_EQ(run.commands[i].vy, 0.0);
  }
  for (const Pose2D& p : run.poses) EXPECT_LT(std::fabs(p.y - 2.0), 0.02);
  EXPECT_GT(run.final_pose.x, 0.5 + 0.8 * c.max_vel_x * 3.0);
  expectWithinAccelerationLimits(run, c);
}

TEST(DwaPlanner, KeepsDrivingWhenOdometryReadsAboveTheSpeedLimit)
{
  // Noisy odometry of a robot cruising at max_vel_x (0.55 m/s) reads 0.7 m/s, more than one
  // period of acceleration (0.125 m/s) above the limit. The window is built from the limit, so
  // the robot keeps its speed instead of getting no admissible sample (and a zero command).
  const DwaConfig c = diffDriveConfig();
  DwaPlanner planner(c);
  Costmap2D map(160, 80, 0.05, 0.0, 0.0);  // 8 x 4 m, free
  planner.setPlan(straightPlan(0.5, 2.0, 7.5, 2.0, 0.0));
  const double reading = c.max_vel_x + 1.2 * c.acc_lim_x * c.simPeriod();
  const Pose2D pose{1.0, 2.0, 0.0};
  Twist2D cmd;
  const LocalPlanResult r =
      planner.computeVelocityCommands(pose, Twist2D{reading, 0.0, 0.0}, localWindow(map, pose), cmd);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_NEAR(cmd.vx, c.max_vel_x, 1e-9);
  EXPECT_LT(std::fabs(cmd.wz), 0.05);

  // The same when the robot turns faster than max_vel_theta reads.
  TrajectoryGenerator generator(c);
  generator.initialise(Twist2D{0.3, 0.0, c.max_vel_theta + 2.0 * c.acc_lim_theta * c.simPeriod()});
  ASSERT_FALSE(generator.samples().empty());
  for (const Twist2D& s : generator.samples())
  {
    EXPECT_LE(s.wz, c.max_vel_theta + 1e-12);
    EXPECT_GE(s.wz, c.max_vel_theta - c.acc_lim_theta * c.simPeriod() - 1e-12);
  }
}

TEST(DwaPlanner, NeverChoosesATrajectoryThroughAWall)
{
  const DwaConfig c = diffDriveConfig();
  DwaPlanner planner(c);
  Costmap2D map(120, 80, 0.05, 0.0, 0.0);  // 6 x 4 m
  fillBox(map, 3.0, 1.0, 3.1, 3.0);        // a LETHAL wall across the plan, not inflated
  planner.setPlan(straightPlan(0.5, 2.0, 5.5, 2.0, 0.0));
  const ClosedLoopRun run = simulate(planner, map, Pose2D{0.5, 2.0, 0.0}, 200);  // 10 s

  int ok_cycles = 0;
  for (size_t i = 0; i < run.results.size(); ++i)
  {
    const LocalPlanResult& r = run.results[i];
    if (!r.ok) continue;
    ++ok_cycles;
    ASSERT_FALSE(r.trajectory.poses.empty());
    for (const Pose2D& p : r.trajectory.poses)
      ASSERT_LT(maxCostUnderFootprint(map, p.x, p.y), cost::INSCRIBED)
          << "cycle " << i << ": the chosen trajectory touches the wall at (" << p.x << ", " << p.y << ")";
  }
  for (const Pose2D& p : run.poses) ASSERT_LT(maxCostUnderFootprint(map, p.x, p.y), cost::INSCRIBED);
  // It did drive up to the wall (it was not simply standing still) ...
  EXPECT_GT(ok_cycles, 20);
  double max_x = 0.0;
  for (const Pose2D& p : run.poses) max_x = std::max(max_x, p.x);
  EXPECT_GT(max_x, 2.0);
  // ... and stopped in front of it.
  EXPECT_LT(run.final_pose.x + kRadius, 3.0);
}

TEST(DwaPlanner, ReportsFailureWhenWalledIn)
{
  // occdist_scale 0 removes the preference for clearance, not the collision check.
  for (const double occdist_scale : {0.01, 0.0})
  {
    SCOPED_TRACE("occdist_scale " + std::to_string(occdist_scale));
    DwaConfig c = diffDriveConfig();
    c.occdist_scale = occdist_scale;
    DwaPlanner planner(c);
    Costmap2D map(80, 80, 0.05, 0.0, 0.0);
    // A closed box of LETHAL cells 0.25 m around the robot: every sample that translates (at
    // least min_vel_trans for sim_time, from rest) takes the footprint into it.
    fillBox(map, 1.7, 1.7, 2.3, 2.3);
    fillBox(map, 1.76, 1.76, 2.24, 2.24, cost::FREE);
    planner.setPlan(straightPlan(2.0, 2.0, 3.5, 2.0, 0.0));
    Twist2D cmd{1.0, 1.0, 1.0};
    const LocalPlanResult r = planner.computeVelocityCommands(Pose2D{2.0, 2.0, 0.0}, Twist2D{}, map, cmd);
    EXPECT_FALSE(r.ok);
    EXPECT_GT(r.samples, 0);
    EXPECT_NE(r.error.find("no valid trajectory"), std::string::npos) << r.error;
    // Most samples drive into the box; the slow turns in place that stay clear cannot reach the
    // goal (the distance map does not get out of the box either).
    EXPECT_NE(r.error.find("obstacle: "), std::string::npos) << r.error;
    EXPECT_EQ(cmd.vx, 0.0);
    EXPECT_EQ(cmd.vy, 0.0);
    EXPECT_EQ(cmd.wz, 0.0);
  }
}

TEST(DwaPlanner, StopsAtTheGoalWithinTolerances)
{
  const DwaConfig c = diffDriveConfig();
  DwaPlanner planner(c);
  Costmap2D map(120, 80, 0.05, 0.0, 0.0);  // 6 x 4 m, free
  const double goal_yaw = M_PI / 2;
  planner.setPlan(straightPlan(0.5, 1.0, 3.0, 2.5, goal_yaw));
  const ClosedLoopRun run = simulate(planner, map, Pose2D{0.5, 1.0, 0.0}, 600);  // 30 s at most

  ASSERT_TRUE(run.reached) << "not at the goal after 30 s: (" << run.final_pose.x << ", " << run.final_pose.y << ", "
                           << run.final_pose.theta << ")";
  for (const LocalPlanResult& r : run.results) ASSERT_TRUE(r.ok) << r.error;
  EXPECT_LE(std::hypot(run.final_pose.x - 3.0, run.final_pose.y - 2.5), c.xy_goal_tolerance);
  EXPECT_LE(std::fabs(mbot_common::angleDiff(run.final_pose.theta, goal_yaw)), c.yaw_goal_tolerance);
  EXPECT_LE(std::fabs(run.final_velocity.vx), c.trans_stopped_vel);
  EXPECT_LE(std::fabs(run.final_velocity.wz), c.theta_stopped_vel);
  // It turned in place to the goal yaw (the plan arrives heading ~31 deg, the goal is 90 deg).
  const bool rotated = std::any_of(run.results.begin(), run.results.end(),
                                   [](const LocalPlanResult& r) { return r.state == LocalPlannerState::ROTATING; });
  EXPECT_TRUE(rotated);
  expectWithinAccelerationLimits(run, c);

  // Once there, it stays there: the commands brake to exactly zero within a few cycles.
  ClosedLoopRun after = simulate(planner, map, run.final_pose, 20, false);
  for (size_t i = 0; i < after.results.size(); ++i) ASSERT_TRUE(after.results[i].ok);
  EXPECT_EQ(after.commands.back().vx, 0.0);
  EXPECT_EQ(after.commands.back().wz, 0.0);
  EXPECT_LT(std::hypot(after.final_pose.x - run.final_pose.x, after.final_pose.y - run.final_pose.y), 0.01);
  EXPECT_TRUE(planner.isGoalReached(after.final_pose, after.final_velocity));
}

TEST(DwaPlanner, ANewPlanToTheSameGoalKeepsTheRotationInPlace)
{
  // The nav node replans at planner_frequency, also while the robot turns to the goal yaw at the
  // goal position: a new plan to the same goal must not restart the stop (brake, then turn again).
  const DwaConfig c = diffDriveConfig();
  DwaPlanner planner(c);
  Costmap2D map(120, 80, 0.05, 0.0, 0.0);  // 6 x 4 m, free
  const double goal_yaw = M_PI / 2;
  planner.setPlan(straightPlan(1.0, 2.0, 3.0, 2.0, goal_yaw));
  Pose2D pose{3.0, 2.0, 0.0};  // at the goal position, 90 deg off its yaw, standing
  Twist2D velocity;
  Twist2D cmd;
  LocalPlanResult r;
  for (int i = 0; i < 3; ++i)  // turning up
  {
    r = planner.computeVelocityCommands(pose, velocity, localWindow(map, pose), cmd);
    ASSERT_TRUE(r.ok) << r.error;
    velocity = cmd;
    pose = integratePose(pose, velocity, c.simPeriod());
  }
  ASSERT_EQ(r.state, LocalPlannerState::ROTATING);
  ASSERT_GT(velocity.wz, c.theta_stopped_vel);

  // A new plan from where the robot stands to the same goal: it keeps turning, no slower.
  planner.setPlan(straightPlan(2.97, 2.0, 3.0, 2.0, goal_yaw));
  r = planner.computeVelocityCommands(pose, velocity, localWindow(map, pose), cmd);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.state, LocalPlannerState::ROTATING);
  EXPECT_GE(cmd.wz, velocity.wz);
  EXPECT_EQ(cmd.vx, 0.0);

  // A plan to another goal (here: the same position, another yaw) starts over: brake first.
  planner.setPlan(straightPlan(2.97, 2.0, 3.0, 2.0, -goal_yaw));
  r = planner.computeVelocityCommands(pose, velocity, localWindow(map, pose), cmd);
  ASSERT_TRUE(r.ok) << r.error;
  EXPECT_EQ(r.state, LocalPlannerState::STOPPING);
  EXPECT_LT(cmd.wz, velocity.wz);
}

TEST(DwaPlanner, BrakesAtTheGoalOnNoisyOdometry)
{
  // mbot_sim's odometry (noise odom_linear 0.1) reads the velocity with errors of about 0.1 m/s.
  // Braking from the measured velocity alone followed that noise: in nav_office_pf a robot in the
  // goal area sped up from 0.08 to 0.44 m/s while "stopping", left the area and drove a loop.
  // Here the robot moves as commanded and the planner sees that velocity plus Gaussian noise; it
  // comes to the goal as there, at 0.3 m/s (the last 0.4 m, so that the noise cannot push the
  // measured speed past max_vel_x, where no sample would be admissible).
  DwaConfig c = diffDriveConfig();  // mbot's limits (mbot_description/config/mbot.yaml)
  c.max_vel_x = 0.5;
  c.min_vel_x = 0.0;
  c.max_vel_theta = 2.0;
  c.acc_lim_x = 1.0;
  c.acc_lim_theta = 3.0;
  Costmap2D map(120, 80, 0.05, 0.0, 0.0);  // 6 x 4 m, free
  const double dt = c.simPeriod();
  for (unsigned seed = 1; seed <= 20; ++seed)
  {
    DwaPlanner planner(c);
    planner.setPlan(straightPlan(1.0, 2.0, 3.0, 2.0, M_PI / 2));
    std::mt19937 random(seed);
    std::normal_distribution<double> noise(0.0, 0.05);
    Pose2D pose{2.6, 2.0, 0.0};
    Twist2D velocity{0.3, 0.0, 0.0};
    bool entered = false, reached = false;
    double previous_vx = velocity.vx;
    for (int i = 0; i < 200 && !reached; ++i)  // 10 s at most
    {
      const Twist2D measured{velocity.vx + noise(random), 0.0, velocity.wz + noise(random)};
      reached = planner.isGoalReached(pose, measured);
      Twist2D cmd;
      const LocalPlanResult r = planner.computeVelocityCommands(pose, measured, localWindow(map, pose), cmd);
      ASSERT_TRUE(r.ok) << "seed " << seed << ", cycle " << i << ": " << r.error;
      if (r.state != LocalPlannerState::FOLLOWING)
      {
        // At the goal position: the translation command only ever goes down.
        if (entered) EXPECT_LE(std::fabs(cmd.vx), std::fabs(previous_vx) + 1e-12) << "seed " << seed << ", cycle " << i;
        entered = true;
      }
      else  // ... and the robot stays there
        ASSERT_FALSE(entered) << "seed " << seed << ", cycle " << i << ": drives again, "
                              << std::hypot(pose.x - 3.0, pose.y - 2.0) << " m off the goal";
      previous_vx = cmd.vx;
      velocity = cmd;
      pose = integratePose(pose, velocity, dt);
    }
    EXPECT_TRUE(reached) << "seed " << seed << ": not at the goal after 10 s";
  }
}

// A robot that stops as soon as it is within xy_goal_tolerance stops at the tolerance's edge,
// where a few centimetres of localization error put it truly outside. It brakes within half the
// tolerance instead (where the trajectories aim), from any direction of approach.
TEST(DwaPlanner, StopsWellInsideTheGoalTolerance)
{
  DwaConfig c = diffDriveConfig();
  c.xy_goal_tolerance = 0.1;
  c.yaw_goal_tolerance = 0.1;
  Costmap2D map(120, 120, 0.05, 0.0, 0.0);  // 6 x 6 m, free
  double worst = 0.0;
  for (int k = 0; k < 8; ++k)
  {
    const double a = k * M_PI / 4.0;
    const Pose2D start{3.0 + 2.0 * std::cos(a), 3.0 + 2.0 * std::sin(a), a + M_PI};
    DwaPlanner planner(c);
    planner.setPlan(straightPlan(start.x, start.y, 3.0, 3.0, a));
    const ClosedLoopRun run = simulate(planner, map, start, 600);
    ASSERT_TRUE(run.reached) << "approach " << k;
    worst = std::max(worst, std::hypot(run.final_pose.x - 3.0, run.final_pose.y - 3.0));
  }
  EXPECT_LE(worst, 0.6 * c.xy_goal_tolerance);
}

// Within the tolerance but unable to get closer (the goal inside an obstacle's footprint), the
// robot still stops and reports the goal reached instead of pressing on.
TEST(DwaPlanner, StopsWithinTheToleranceWhenItCannotGetCloser)
{
  DwaConfig c = diffDriveConfig();
  c.xy_goal_tolerance = 0.3;
  Costmap2D map(120, 80, 0.05, 0.0, 0.0);
  // a wall 0.1 m beyond the goal at x = 3.0: the obstacle critic keeps the robot's centre about
  // 0.32 m from its face (measured), inside the tolerance, outside half of it
  fillBox(map, 3.1, 0.0, 6.0, 4.0);
  DwaPlanner planner(c);
  planner.setPlan(straightPlan(1.0, 2.0, 3.0, 2.0, 0.0));
  const ClosedLoopRun run = simulate(planner, map, Pose2D{1.0, 2.0, 0.0}, 600);
  ASSERT_TRUE(run.reached) << "final (" << run.final_pose.x << ", " << run.final_pose.y << ")";
  const double off = std::hypot(run.final_pose.x - 3.0, run.final_pose.y - 2.0);
  EXPECT_GT(off, 0.5 * c.xy_goal_tolerance);
  EXPECT_LE(off, c.xy_goal_tolerance);
}

TEST(DwaPlanner, RespectsAccelerationLimitsOnACurvyPlan)
{
  for (const DwaConfig& c : {diffDriveConfig(), omniConfig(), mbotOmniConfig(true), mbotOmniConfig(false)})
  {
    SCOPED_TRACE("max_vel_y " + std::to_string(c.max_vel_y) + ", acc_lim_x " + std::to_string(c.acc_lim_x));
    DwaPlanner planner(c);
    Costmap2D map(160, 100, 0.05, 0.0, 0.0);  // 8 x 5 m, free
    std::vector<Pose2D> plan;
    for (double x = 0.5; x <= 7.0; x += 0.05) plan.push_back(Pose2D{x, 2.5 + 1.2 * std::sin(x), 0.0});
    plan.back().theta = -M_PI / 2;
    planner.setPlan(plan);
    const ClosedLoopRun run = simulate(planner, map, Pose2D{0.5, 2.5, M_PI / 2}, 800);
    EXPECT_TRUE(run.reached);
    for (const LocalPlanResult& r : run.results) ASSERT_TRUE(r.ok) << r.error;
    expectWithinAccelerationLimits(run, c);
    for (const Twist2D& cmd : run.commands)
    {
      EXPECT_LE(cmd.vx, c.max_vel_x + 1e-12);
      EXPECT_GE(cmd.vx, c.min_vel_x - 1e-12);
      EXPECT_LE(std::fabs(cmd.wz), c.max_vel_theta + 1e-12);
      EXPECT_LE(std::hypot(cmd.vx, cmd.vy), c.max_vel_trans + 1e-4);
    }
  }
}

TEST(DwaPlanner, StartsFromRestWithLowAccelerationLimits)
{
  // mbot's limits (mbot_description/config/mbot.yaml): from rest one period reaches 0.05 m/s and
  // 0.15 rad/s, below min_vel_trans (0.1) and min_vel_theta (0.4). dwa_local_planner would reject
  // every sample and never start; the minimums are lowered to what the window reaches.
  DwaConfig c = diffDriveConfig();
  c.max_vel_x = 0.5;
  c.min_vel_x = -0.2;
  c.max_vel_theta = 2.0;
  c.acc_lim_x = 1.0;
  c.acc_lim_theta = 3.0;
  DwaPlanner planner(c);
  Costmap2D world(120, 80, 0.05, 0.0, 0.0);
  planner.setPlan(straightPlan(0.5, 2.0, 5.5, 2.0, 0.0));
  const ClosedLoopRun run = simulate(planner, world, Pose2D{0.5, 2.0, 0.0}, 40);  // 2 s
  for (const LocalPlanResult& r : run.results) ASSERT_TRUE(r.ok) << r.error;
  EXPECT_NEAR(run.commands.front().vx, c.acc_lim_x * c.simPeriod(), 1e-12);  // full acceleration
  EXPECT_GE(run.commands.back().vx, 0.95 * c.max_vel_x);                     // 0.5 s to full speed, then cruising
  expectWithinAccelerationLimits(run, c);
}

TEST(DwaPlanner, OmniRobotSidestepsBackOntoThePlan)
{
  // The robot faces along the plan but stands 0.25 m beside it: an omni robot strafes back while
  // it drives on, a differential drive robot has to steer over (turn, then turn back).
  Costmap2D world(160, 80, 0.05, 0.0, 0.0);  // 8 x 4 m, free
  const auto run_with = [&](const DwaConfig& c) {
    DwaPlanner planner(c);
    planner.setPlan(straightPlan(0.5, 2.0, 7.5, 2.0, 0.0));
    return simulate(planner, world, Pose2D{0.5, 2.25, 0.0}, 40);  // 2 s
  };
  const auto max_yaw = [](const ClosedLoopRun& run) {
    double m = 0.0;
    for (const Pose2D& p : run.poses) m = std::max(m, std::fabs(mbot_common::normalizeAngle(p.theta)));
    return m;
  };

  const DwaConfig omni = mbotOmniConfig(true);
  const ClosedLoopRun strafe = run_with(omni);
  for (const LocalPlanResult& r : strafe.results) ASSERT_TRUE(r.ok) << r.error;
  double strafed = 0.0;  // lateral distance covered with v_y [m], towards the plan is negative
  for (const Twist2D& cmd : strafe.commands) strafed += cmd.vy * omni.simPeriod();
  EXPECT_LT(strafed, -0.15);        // most of the 0.25 m, sideways
  EXPECT_LT(max_yaw(strafe), 0.1);  // without turning much
  expectWithinAccelerationLimits(strafe, omni);

  const DwaConfig diff = mbotOmniConfig(false);
  const ClosedLoopRun steer = run_with(diff);
  for (const LocalPlanResult& r : steer.results) ASSERT_TRUE(r.ok) << r.error;
  for (const Twist2D& cmd : steer.commands) EXPECT_EQ(cmd.vy, 0.0);
  // After 2 s the omni robot is much closer to the plan, and turned less on the way.
  const double omni_error = std::fabs(strafe.final_pose.y - 2.0);
  const double diff_error = std::fabs(steer.final_pose.y - 2.0);
  EXPECT_LT(omni_error, diff_error - 0.05) << "omni " << omni_error << " m, diff " << diff_error << " m";
  EXPECT_GT(max_yaw(steer), max_yaw(strafe));
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}

// ---------------------------------------------------------------------------------------------
// The oscillation critic (dwa_local_planner's OscillationCostFunction): after a reversal on an
// axis, only the new direction is allowed until the robot has moved or turned far enough.

namespace
{
constexpr double kMinVelTrans = 0.1;  // [m/s] below this v_x the robot counts as "not driving"

Trajectory chosen(double vx, double vy, double wz)
{
  Trajectory t;
  t.velocity = Twist2D{vx, vy, wz};
  t.cost = 1.0;  // a valid (chosen) trajectory
  return t;
}

bool allowed(OscillationCritic& critic, double vx, double vy, double wz)
{
  return critic.score(chosen(vx, vy, wz)) >= 0.0;
}
}  // namespace

TEST(OscillationCritic, TurningBackAndForthOnTheSpotIsStoppedUntilTheRobotTurnedFarEnough)
{
  OscillationCritic critic(0.05, 0.2);  // reset after 0.05 m or 0.2 rad
  const Pose2D here{1.0, 2.0, 0.0};
  critic.update(here, chosen(0.0, 0.0, 0.5), kMinVelTrans);   // turns left
  EXPECT_TRUE(allowed(critic, 0.0, 0.0, -0.5));               // one turn is no oscillation yet
  critic.update(here, chosen(0.0, 0.0, -0.5), kMinVelTrans);  // then right: a reversal
  EXPECT_TRUE(allowed(critic, 0.0, 0.0, -0.5));
  EXPECT_FALSE(allowed(critic, 0.0, 0.0, 0.5));  // turning left again is forbidden
  critic.update(Pose2D{1.0, 2.0, -0.1}, chosen(0.0, 0.0, -0.5), kMinVelTrans);
  EXPECT_FALSE(allowed(critic, 0.0, 0.0, 0.5));  // turned 0.1 rad: still restricted
  critic.update(Pose2D{1.0, 2.0, -0.25}, chosen(0.0, 0.0, -0.5), kMinVelTrans);
  EXPECT_TRUE(allowed(critic, 0.0, 0.0, 0.5));  // turned 0.25 rad > 0.2: free again
}

TEST(OscillationCritic, ForwardAndBackwardIsStoppedUntilTheRobotMovedFarEnough)
{
  OscillationCritic critic(0.05, 0.2);
  critic.update(Pose2D{0.0, 0.0, 0.0}, chosen(0.2, 0.0, 0.0), kMinVelTrans);
  critic.update(Pose2D{0.01, 0.0, 0.0}, chosen(-0.1, 0.0, 0.0), kMinVelTrans);  // backs up: a reversal
  EXPECT_FALSE(allowed(critic, 0.2, 0.0, 0.0));
  EXPECT_TRUE(allowed(critic, -0.1, 0.0, 0.0));
  critic.update(Pose2D{-0.03, 0.0, 0.0}, chosen(-0.1, 0.0, 0.0), kMinVelTrans);
  EXPECT_FALSE(allowed(critic, 0.2, 0.0, 0.0));  // 0.04 m from where it reversed
  critic.update(Pose2D{-0.05, 0.0, 0.0}, chosen(-0.1, 0.0, 0.0), kMinVelTrans);
  EXPECT_TRUE(allowed(critic, 0.2, 0.0, 0.0));  // 0.06 m > 0.05: free again
}

TEST(OscillationCritic, TurnsWhileDrivingAndRejectedTrajectoriesSetNoFlags)
{
  OscillationCritic critic(0.05, 0.2);
  const Pose2D here{0.0, 0.0, 0.0};
  // Weaving left and right while driving forward is steering, not oscillating.
  critic.update(here, chosen(0.3, 0.0, 0.5), kMinVelTrans);
  critic.update(here, chosen(0.3, 0.0, -0.5), kMinVelTrans);
  EXPECT_TRUE(allowed(critic, 0.0, 0.0, 0.5));
  EXPECT_TRUE(allowed(critic, 0.0, 0.0, -0.5));
  // A cycle without a valid trajectory (cost < 0) is not a choice.
  critic.update(here, chosen(0.0, 0.0, 0.5), kMinVelTrans);
  Trajectory rejected = chosen(0.0, 0.0, -0.5);
  rejected.cost = -1.0;
  critic.update(here, rejected, kMinVelTrans);
  EXPECT_TRUE(allowed(critic, 0.0, 0.0, 0.5));
  // An omni robot strafing left, then right, on the spot.
  critic.update(here, chosen(0.0, 0.1, 0.0), kMinVelTrans);
  critic.update(here, chosen(0.0, -0.1, 0.0), kMinVelTrans);
  EXPECT_FALSE(allowed(critic, 0.0, 0.1, 0.0));
  critic.reset();  // a new plan clears every restriction
  EXPECT_TRUE(allowed(critic, 0.0, 0.1, 0.0));
}
