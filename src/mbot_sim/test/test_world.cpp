/**
 * @file test_world.cpp
 * @brief The simulation core without ROS: kinematics against analytic poses, limits, the
 *        watchdog, contacts, lasers, sensor rates, moving obstacles, determinism, faults and
 *        the run-time requests.
 */
#include "mbot_sim/world.h"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <vector>

using mbot_description::DriveType;
using mbot_description::RobotModel;
using namespace mbot_sim;

namespace
{
const std::string kFixtures = MBOT_SIM_FIXTURES;
constexpr double kPi = 3.14159265358979323846;

/// mbot's numbers (urdf/mbot.urdf, config/mbot.yaml): round, r = 0.15 m.
RobotModel diffModel()
{
  RobotModel m;
  m.name = "mbot";
  m.drive = DriveType::DIFF;
  m.footprint_radius = 0.15;
  for (int i = 0; i < 16; ++i)
    m.footprint.push_back({0.15 * std::cos(2 * kPi * i / 16), 0.15 * std::sin(2 * kPi * i / 16)});
  m.mass = 2.4;
  m.wheel_radius = 0.04;
  m.wheel_separation = 0.22;
  m.wheel_joints = {"left_wheel_joint", "right_wheel_joint"};
  m.laser.mount_x = 0.05;
  m.laser.mount_z = 0.16;
  m.limits = mbot_description::Limits{0.5, -0.2, 0.0, 2.0, 1.0, 0.0, 3.0};
  return m;
}

/// mbot_omni-like: a 0.3 x 0.24 m box body, mecanum wheels.
RobotModel omniModel()
{
  RobotModel m = diffModel();
  m.name = "mbot_omni";
  m.drive = DriveType::OMNI;
  m.footprint = {{0.15, -0.12}, {0.15, 0.12}, {-0.15, 0.12}, {-0.15, -0.12}};
  m.footprint_radius = std::hypot(0.15, 0.12);
  m.wheel_base = 0.2;
  m.wheel_joints = {"fl", "fr", "rl", "rr"};
  m.limits = mbot_description::Limits{0.4, -0.4, 0.4, 1.5, 1.0, 1.0, 2.5};
  return m;
}

/// Very large acceleration limits: the commanded twist holds from the first step, so the
/// analytic pose of a constant twist applies.
RobotModel stiff(RobotModel m)
{
  m.limits.acc_lim_x = m.limits.acc_lim_y = m.limits.acc_lim_theta = 1e6;
  return m;
}

/// A free 40 m x 40 m map (no walls), origin at (-20, -20).
OccupancyMap openMap()
{
  OccupancyMap map;
  map.width = map.height = 400;
  map.resolution = 0.1;
  map.origin_x = map.origin_y = -20.0;
  map.data.assign(400 * 400, 0);
  return map;
}

OccupancyMap roomMap() { return loadMap(kFixtures + "/room.yaml"); }

/// Keeps every sample and contact.
struct Recorder : SensorListener
{
  std::map<int, std::vector<OdometrySample>> odom;
  std::map<int, std::vector<GroundTruthSample>> truth;
  std::map<int, std::vector<ScanSample>> scans;
  std::map<int, std::vector<JointStateSample>> joints;
  std::vector<ContactEvent> contacts;
  std::vector<double> odom_release_times;   ///< sim time at which each odom sample arrived
  std::vector<double> truth_release_times;  ///< sim time at which each ground truth sample arrived
  std::vector<double> scan_release_times;   ///< sim time at which each scan arrived
  const World* world = nullptr;

  void onOdometry(int r, const OdometrySample& s) override
  {
    odom[r].push_back(s);
    if (world) odom_release_times.push_back(world->time());
  }
  void onGroundTruth(int r, const GroundTruthSample& s) override
  {
    truth[r].push_back(s);
    if (world) truth_release_times.push_back(world->time());
  }
  void onScan(int r, const ScanSample& s) override
  {
    scans[r].push_back(s);
    if (world) scan_release_times.push_back(world->time());
  }
  void onJointState(int r, const JointStateSample& s) override { joints[r].push_back(s); }
  void onContact(const ContactEvent& e) override { contacts.push_back(e); }

  int contactsBetween(const std::string& a, const std::string& b) const
  {
    int n = 0;
    for (const auto& c : contacts) n += (c.body_a == a && c.body_b == b) || (c.body_a == b && c.body_b == a);
    return n;
  }
};

/// Drive `robot` with `cmd` for `seconds`, repeating the command at 10 Hz (as a controller does).
void drive(World& world, int robot, const Twist2D& cmd, double seconds)
{
  const int steps = static_cast<int>(std::lround(seconds / world.physicsStep()));
  for (int i = 0; i < steps; ++i)
  {
    if (i % 10 == 0) world.setCommand(robot, cmd);
    world.step();
  }
}

void run(World& world, double seconds)
{
  const int steps = static_cast<int>(std::lround(seconds / world.physicsStep()));
  for (int i = 0; i < steps; ++i) world.step();
}

/// Index of the beam pointing along `angle` [rad] in the laser frame.
size_t beamAt(const RobotModel& m, double angle)
{
  const double inc = m.laser.angleIncrement();
  return static_cast<size_t>(std::lround(std::remainder(angle - m.laser.min_angle, 2 * kPi) / inc + m.laser.beams) %
                             m.laser.beams);
}
}  // namespace

// ---- kinematics -------------------------------------------------------------------------------

TEST(Kinematics, DiffDriveArcMatchesTheAnalyticPose)
{
  World world(openMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", stiff(diffModel()), Pose2D{0.0, 0.0, 0.0});
  const double v = 0.4, w = 0.5, T = 4.0;
  drive(world, id, Twist2D{v, 0.0, w}, T);
  const Pose2D p = world.groundTruth(id);
  const double R = v / w;
  EXPECT_NEAR(p.x, R * std::sin(w * T), 0.005);
  EXPECT_NEAR(p.y, R * (1.0 - std::cos(w * T)), 0.005);
  EXPECT_NEAR(p.theta, w * T, 0.005);
  // Without noise the odometry is the ground truth (both start at the same pose here).
  const Pose2D o = world.odometry(id);
  EXPECT_NEAR(o.x, p.x, 1e-6);
  EXPECT_NEAR(o.y, p.y, 1e-6);
  EXPECT_NEAR(o.theta, p.theta, 1e-6);
}

TEST(Kinematics, DiffDriveIgnoresSidewaysCommands)
{
  World world(openMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", stiff(diffModel()), Pose2D{0.0, 0.0, kPi / 2});
  drive(world, id, Twist2D{0.0, 0.4, 0.0}, 1.0);
  const Pose2D p = world.groundTruth(id);
  EXPECT_NEAR(p.x, 0.0, 1e-6);
  EXPECT_NEAR(p.y, 0.0, 1e-6);
}

TEST(Kinematics, OmniDriveTranslatesAndTurnsAsAnalytic)
{
  World world(openMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", stiff(omniModel()), Pose2D{1.0, -1.0, 0.0});
  const double vx = 0.2, vy = 0.3, w = 0.5, T = 3.0;
  drive(world, id, Twist2D{vx, vy, w}, T);
  const Pose2D p = world.groundTruth(id);
  // A constant body twist: position = integral of R(w t) (vx, vy) dt.
  const double s = std::sin(w * T), c = std::cos(w * T);
  EXPECT_NEAR(p.x, 1.0 + (vx * s + vy * (c - 1.0)) / w, 0.005);
  EXPECT_NEAR(p.y, -1.0 + (vx * (1.0 - c) + vy * s) / w, 0.005);
  EXPECT_NEAR(p.theta, w * T, 0.005);
  const Pose2D o = world.odometry(id);  // odom starts at identity: the displacement
  EXPECT_NEAR(o.x, p.x - 1.0, 1e-6);
  EXPECT_NEAR(o.y, p.y + 1.0, 1e-6);
}

TEST(Kinematics, AccelerationAndVelocityLimitsHold)
{
  World world(openMap(), WorldSettings{});
  const RobotModel model = diffModel();  // acc 1.0 m/s^2, 3.0 rad/s^2; max 0.5 m/s, 2.0 rad/s
  const int id = world.addRobot("robot_0", model, Pose2D{});
  double last_v = 0.0, last_w = 0.0;
  const double dt = world.physicsStep();
  for (int i = 0; i < 200; ++i)  // 2 s of a too-fast command
  {
    if (i % 10 == 0) world.setCommand(id, Twist2D{5.0, 0.0, 10.0});
    world.step();
    const Twist2D v = world.velocity(id);
    EXPECT_LE(std::abs(v.vx - last_v), model.limits.acc_lim_x * dt + 1e-9) << "step " << i;
    EXPECT_LE(std::abs(v.wz - last_w), model.limits.acc_lim_theta * dt + 1e-9) << "step " << i;
    EXPECT_LE(v.vx, model.limits.max_vel_x + 1e-9);
    EXPECT_LE(v.wz, model.limits.max_vel_theta + 1e-9);
    last_v = v.vx;
    last_w = v.wz;
    if (i == 19)  // after 0.2 s: 0.2 m/s and 0.6 rad/s
    {
      EXPECT_NEAR(v.vx, 0.2, 1e-6);
      EXPECT_NEAR(v.wz, 0.6, 1e-6);
    }
  }
  EXPECT_NEAR(last_v, 0.5, 1e-9);
  EXPECT_NEAR(last_w, 2.0, 1e-9);
}

TEST(Kinematics, StraightRunWithRampMatchesTheAnalyticDistance)
{
  World world(openMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{});
  drive(world, id, Twist2D{0.5, 0.0, 0.0}, 2.0);
  // 0.5 s ramp at 1 m/s^2 (0.125 m), then 1.5 s at 0.5 m/s: 0.875 m
  EXPECT_NEAR(world.groundTruth(id).x, 0.875, 0.005);
  EXPECT_NEAR(world.groundTruth(id).y, 0.0, 1e-9);
}

TEST(Kinematics, WatchdogStopsARobotWithoutCommands)
{
  World world(openMap(), WorldSettings{});  // watchdog 0.2 s
  const int id = world.addRobot("robot_0", stiff(diffModel()), Pose2D{});
  world.setCommand(id, Twist2D{0.5, 0.0, 0.0});  // once
  run(world, 0.1);
  EXPECT_NEAR(world.velocity(id).vx, 0.5, 1e-9);  // still driving within the timeout
  run(world, 0.2);
  EXPECT_NEAR(world.velocity(id).vx, 0.0, 1e-9);
  const double x = world.groundTruth(id).x;
  EXPECT_NEAR(x, 0.5 * 0.2, 0.011);  // drove for the 0.2 s of the timeout (+ one step)
  run(world, 1.0);
  EXPECT_NEAR(world.groundTruth(id).x, x, 1e-9);  // and stays
}

// ---- true zeros: a stopped robot at rest measures exactly 0 (stage_ros's tests count on it) ----

namespace
{
bool exactlyZero(const Twist2D& t) { return t.vx == 0.0 && t.vy == 0.0 && t.wz == 0.0; }
}  // namespace

TEST(TrueZeros, AStoppedRobotReportsExactlyZeroTwistInOdometryAndGroundTruth)
{
  WorldSettings settings;
  settings.noise.odom_linear = 0.05;  // noise only while the wheels turn
  settings.noise.odom_angular = 0.05;
  World world(roomMap(), settings);
  Recorder rec;
  world.setListener(&rec);
  // against_wall: into the wall block at x = 7.0 at an angle, stopped by the watchdog, resting
  // against the wall (the contact solver's residue used to leave ~1e-6..1e-14 m/s, and odometry
  // noise on top while it was above 1e-9); floor: stopped in the open by a zero command;
  // omni: strafed into the north wall, stopped by a zero command.
  const int against_wall = world.addRobot("against_wall", diffModel(), Pose2D{6.0, 1.5, 0.0});
  const int floor = world.addRobot("floor", diffModel(), Pose2D{2.0, 4.0, 0.0});
  const int omni = world.addRobot("omni", omniModel(), Pose2D{5.0, 6.5, 0.0});
  for (int i = 0; i < 400; ++i)  // 4 s
  {
    if (i % 10 == 0)
    {
      world.setCommand(against_wall, Twist2D{0.5, 0.0, 0.3});
      world.setCommand(floor, Twist2D{0.3, 0.0, 0.5});
      world.setCommand(omni, Twist2D{0.0, 0.4, 0.0});
    }
    world.step();
  }
  ASSERT_GE(rec.contactsBetween("against_wall", "map"), 1);
  ASSERT_GE(rec.contactsBetween("omni", "map"), 1);
  world.setCommand(floor, Twist2D{});
  world.setCommand(omni, Twist2D{});
  run(world, 1.0);  // braking takes at most 0.5 s
  const double t_rest = world.time();
  std::map<int, Pose2D> truth_at_rest, odom_at_rest;
  for (int id : {against_wall, floor, omni})
  {
    truth_at_rest[id] = world.groundTruth(id);
    odom_at_rest[id] = world.odometry(id);
  }
  run(world, 2.0);
  for (int id : {against_wall, floor, omni})
  {
    const std::string name = world.robotName(id);
    int truth_samples = 0, odom_samples = 0;
    for (const auto& s : rec.truth[id])
    {
      if (s.stamp <= t_rest) continue;
      ++truth_samples;
      EXPECT_TRUE(exactlyZero(s.twist)) << name << " ground truth at t = " << s.stamp << ": " << s.twist.vx << ", "
                                        << s.twist.vy << ", " << s.twist.wz;
      EXPECT_EQ(s.pose.x, truth_at_rest[id].x) << name;
      EXPECT_EQ(s.pose.y, truth_at_rest[id].y) << name;
      EXPECT_EQ(s.pose.theta, truth_at_rest[id].theta) << name;
    }
    for (const auto& s : rec.odom[id])
    {
      if (s.stamp <= t_rest) continue;
      ++odom_samples;
      EXPECT_TRUE(exactlyZero(s.twist)) << name << " odometry at t = " << s.stamp << ": " << s.twist.vx << ", "
                                        << s.twist.vy << ", " << s.twist.wz;
      EXPECT_EQ(s.pose.x, odom_at_rest[id].x) << name;
      EXPECT_EQ(s.pose.y, odom_at_rest[id].y) << name;
      EXPECT_EQ(s.pose.theta, odom_at_rest[id].theta) << name;
    }
    EXPECT_EQ(truth_samples, 100) << name;  // 50 Hz for 2 s
    EXPECT_EQ(odom_samples, 100) << name;
    for (double v : rec.joints[id].back().velocity) EXPECT_EQ(v, 0.0) << name;
    EXPECT_TRUE(exactlyZero(world.velocity(id))) << name;
  }
}

TEST(TrueZeros, APushedRobotIsNotAtRestAndReportsItsMotion)
{
  World world(openMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int pusher = world.addRobot("pusher", diffModel(), Pose2D{0.0, 0.0, 0.0});
  const int pushed = world.addRobot("pushed", diffModel(), Pose2D{1.0, 0.0, 0.0});  // never commanded
  drive(world, pusher, Twist2D{0.3, 0.0, 0.0}, 4.0);  // touches after ~2.5 s, then pushes for ~1.5 s
  const Pose2D moved = world.groundTruth(pushed);
  EXPECT_GT(moved.x, 1.2);
  double fastest_truth = 0.0, fastest_odom = 0.0;
  for (const auto& s : rec.truth[pushed]) fastest_truth = std::max(fastest_truth, s.twist.vx);
  for (const auto& s : rec.odom[pushed]) fastest_odom = std::max(fastest_odom, s.twist.vx);
  EXPECT_GT(fastest_truth, 0.1);                   // far above the rest threshold (1e-4 m/s)
  EXPECT_NEAR(fastest_odom, fastest_truth, 1e-9);  // its wheels turn along (a diff drive senses forward motion)
  // Once the pusher has stopped (watchdog) both come to rest: exact zeros again.
  run(world, 1.5);
  EXPECT_TRUE(exactlyZero(rec.truth[pushed].back().twist));
  EXPECT_TRUE(exactlyZero(rec.odom[pushed].back().twist));
  EXPECT_TRUE(exactlyZero(rec.truth[pusher].back().twist));
}

TEST(TrueZeros, AtRestOnlyWhileTheDriveStandsStillAndNothingPushes)
{
  // stage_node's lockstep asks this: a zero command that finds the robot at rest is "holding".
  World world(openMap(), WorldSettings{});
  const int pusher = world.addRobot("pusher", diffModel(), Pose2D{0.0, 0.0, 0.0});
  // never commanded:
  const int pushed = world.addRobot("pushed", diffModel(), Pose2D{1.0, 0.0, 0.0});
  EXPECT_TRUE(world.atRest(pusher));  // as placed
  drive(world, pusher, Twist2D{0.3, 0.0, 0.0}, 0.5);
  EXPECT_FALSE(world.atRest(pusher));  // driving
  world.setCommand(pusher, Twist2D{});
  world.step();
  EXPECT_FALSE(world.atRest(pusher));  // braking from 0.3 m/s at 1 m/s^2 takes 0.3 s
  run(world, 0.5);
  EXPECT_TRUE(world.atRest(pusher));
  drive(world, pusher, Twist2D{0.3, 0.0, 0.0}, 3.0);  // touches the other robot after ~2 s
  EXPECT_FALSE(world.atRest(pushed));                 // pushed: moving although never commanded
  run(world, 1.5);                                    // the watchdog stops the pusher
  EXPECT_TRUE(world.atRest(pusher));
  EXPECT_TRUE(world.atRest(pushed));
}

// ---- contacts ---------------------------------------------------------------------------------

TEST(Contacts, RobotDrivenIntoAWallStopsAtItAndOneContactIsReported)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{6.0, 1.5, 0.0});  // wall block at x = 7.0
  const double wall_x = 7.0, radius = 0.15;
  double max_x = 0.0;
  for (int i = 0; i < 400; ++i)  // 4 s at 0.5 m/s: would be 2 m, the wall is 0.85 m away
  {
    if (i % 10 == 0) world.setCommand(id, Twist2D{0.5, 0.0, 0.0});
    world.step();
    max_x = std::max(max_x, world.groundTruth(id).x);
  }
  EXPECT_LE(max_x + radius, wall_x) << "the footprint entered the wall";
  EXPECT_NEAR(world.groundTruth(id).x, wall_x - radius, 0.02) << "stopped short of the wall";
  EXPECT_NEAR(world.velocity(id).vx, 0.0, 0.01);
  ASSERT_EQ(rec.contacts.size(), 1u);
  EXPECT_EQ(rec.contactsBetween("robot_0", "map"), 1);
  EXPECT_NEAR(rec.contacts[0].x, wall_x, 0.02);
  // reached the wall after about (0.85 - 0.01 m margin - 0.25 m ramp) / 0.5 + 1.0 s ramp ... ~ 2.2 s
  EXPECT_GT(rec.contacts[0].stamp, 1.5);
  EXPECT_LT(rec.contacts[0].stamp, 2.5);
}

TEST(Contacts, RobotRobotContactIsReportedOnceWhenItStarts)
{
  World world(openMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int a = world.addRobot("robot_0", diffModel(), Pose2D{0.0, 0.0, 0.0});
  world.addRobot("robot_1", diffModel(), Pose2D{1.0, 0.0, 0.0});
  double first_touch_distance = -1.0;
  for (int i = 0; i < 400; ++i)
  {
    if (i % 10 == 0) world.setCommand(a, Twist2D{0.3, 0.0, 0.0});
    const size_t before = rec.contacts.size();
    world.step();
    if (rec.contacts.size() > before && first_touch_distance < 0)
      first_touch_distance = world.groundTruth(1).x - world.groundTruth(0).x;
    // Bodies never pass through each other.
    EXPECT_GE(world.groundTruth(1).x - world.groundTruth(0).x, 0.3 - 0.005);
  }
  EXPECT_EQ(rec.contactsBetween("robot_0", "robot_1"), 1);
  EXPECT_EQ(rec.contacts.size(), 1u);
  EXPECT_NEAR(first_touch_distance, 0.32, 0.01);  // 2 radii + 2 contact margins
  EXPECT_GT(world.groundTruth(1).x, 1.1);         // robot_1 was pushed
}

TEST(Contacts, MovingObstacleFollowsItsPathAndCannotBePushed)
{
  World world(openMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  MovingObstacleConfig person;
  person.name = "person_1";
  person.shape.type = ShapeConfig::Type::CYLINDER;
  person.shape.radius = 0.25;
  person.waypoints = {{-2.0, 0.0}, {2.0, 0.0}};
  person.speed = 0.5;
  person.mode = MovingObstacleConfig::Mode::PING_PONG;
  person.yielding = 0.0;  // blind: it keeps to its timetable whatever is in the way
  world.addMovingObstacle(person);
  // A robot in the way, driving against the person.
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{1.0, 0.0, kPi});
  for (int i = 0; i < 600; ++i)  // 6 s: 3 m along the route
  {
    if (i % 10 == 0) world.setCommand(id, Twist2D{0.2, 0.0, 0.0});
    world.step();
    const ObstacleState s = world.obstacles().front();
    const double d = 0.5 * world.time();  // path distance; -2 -> 2 takes 8 s
    EXPECT_NEAR(s.pose.x, -2.0 + d, 1e-6) << "t = " << world.time();
  }
  EXPECT_EQ(rec.contactsBetween("robot_0", "person_1"), 1);
  EXPECT_GT(world.groundTruth(id).x, 1.2);  // pushed back, not through
  // ping-pong: at 12 s it is back at x = 0, going towards -2
  run(world, 6.0);
  EXPECT_NEAR(world.obstacles().front().pose.x, 0.0, 1e-6);
  EXPECT_NEAR(std::abs(world.obstacles().front().pose.theta), kPi, 1e-9);
}

TEST(Contacts, LoopingMoverReturnsToTheFirstWaypoint)
{
  World world(openMap(), WorldSettings{});
  MovingObstacleConfig cart;
  cart.name = "cart";
  cart.shape.type = ShapeConfig::Type::BOX;
  cart.shape.length = 0.6;
  cart.shape.width = 0.4;
  cart.waypoints = {{0.0, 0.0}, {3.0, 0.0}, {3.0, 4.0}};  // loop length 3 + 4 + 5 = 12 m
  cart.speed = 1.0;
  cart.yielding = 0.0;
  world.addMovingObstacle(cart);
  run(world, 5.0);  // 3 m along x, then 2 m up
  Pose2D p = world.obstacles().front().pose;
  EXPECT_NEAR(p.x, 3.0, 1e-6);
  EXPECT_NEAR(p.y, 2.0, 1e-6);
  EXPECT_NEAR(p.theta, kPi / 2, 1e-9);
  run(world, 7.0);
  p = world.obstacles().front().pose;
  EXPECT_NEAR(p.x, 0.0, 1e-6);
  EXPECT_NEAR(p.y, 0.0, 1e-6);
}

// ---- walkers (moving obstacles that give way) --------------------------------------------------

namespace
{
MovingObstacleConfig walkerConfig(const std::string& name, std::vector<Point2D> waypoints, double yielding = 1.0)
{
  MovingObstacleConfig person;
  person.name = name;
  person.shape.type = ShapeConfig::Type::CYLINDER;
  person.shape.radius = 0.25;
  person.waypoints = std::move(waypoints);
  person.speed = 0.6;
  person.mode = MovingObstacleConfig::Mode::PING_PONG;
  person.yielding = yielding;
  return person;
}

/// What a walker did over a run: how close it came to each waypoint and to a robot, how far it
/// left the line of its route (y = route_y) and the contacts.
struct WalkLog
{
  std::vector<double> closest_to_waypoint;
  double min_gap = 1e9;        ///< [m] between its outline and the robot's
  double max_deviation = 0.0;  ///< [m] from the line y = route_y
  size_t contacts = 0;
};

/// Step `world` for `seconds` and log obstacle `index` (a cylinder of radius 0.25) against
/// robot `robot` (round, radius 0.15; -1: none). `robot_cmd` is repeated at 10 Hz when set.
WalkLog walk(World& world, size_t index, const std::vector<Point2D>& waypoints, double route_y, int robot,
             double seconds, const Twist2D* robot_cmd = nullptr)
{
  Recorder rec;
  world.setListener(&rec);
  WalkLog log;
  log.closest_to_waypoint.assign(waypoints.size(), 1e9);
  const int steps = static_cast<int>(std::lround(seconds / world.physicsStep()));
  for (int i = 0; i < steps; ++i)
  {
    if (robot_cmd && i % 10 == 0) world.setCommand(robot, *robot_cmd);
    world.step();
    const Pose2D p = world.obstacles()[index].pose;
    for (size_t k = 0; k < waypoints.size(); ++k)
      log.closest_to_waypoint[k] =
          std::min(log.closest_to_waypoint[k], std::hypot(p.x - waypoints[k].x, p.y - waypoints[k].y));
    log.max_deviation = std::max(log.max_deviation, std::abs(p.y - route_y));
    if (robot >= 0)
    {
      const Pose2D r = world.groundTruth(robot);
      log.min_gap = std::min(log.min_gap, std::hypot(p.x - r.x, p.y - r.y) - 0.25 - 0.15);
    }
  }
  log.contacts = rec.contacts.size();
  world.setListener(nullptr);
  return log;
}
}  // namespace

TEST(Walker, AloneItWalksItsRouteAtItsSpeed)
{
  World world(openMap(), WorldSettings{});
  const std::vector<Point2D> route = {{0.0, 0.0}, {3.0, 0.0}, {3.0, 4.0}};
  MovingObstacleConfig person = walkerConfig("person_1", route);
  person.mode = MovingObstacleConfig::Mode::LOOP;  // 3 + 4 + 5 = 12 m: 20 s at 0.6 m/s
  world.addMovingObstacle(person);
  const WalkLog first_lap = walk(world, 0, route, 0.0, -1, 19.0);
  for (double d : first_lap.closest_to_waypoint) EXPECT_LT(d, 0.01);
  // Nobody near: at its speed along the route, the same as a blind mover (to a step per corner).
  run(world, 1.0);
  const Pose2D p = world.obstacles().front().pose;
  EXPECT_LT(std::hypot(p.x, p.y), 0.03);
}

TEST(Walker, StepsAroundARobotStandingOnItsPathAndStillReachesItsWaypoints)
{
  const std::vector<Point2D> route = {{-3.0, 0.0}, {3.0, 0.0}};
  for (double yielding : {1.0, 0.3})
  {
    World world(openMap(), WorldSettings{});
    world.addMovingObstacle(walkerConfig("person_1", route, yielding));
    const int robot = world.addRobot("robot_0", diffModel(), Pose2D{0.0, 0.0, 0.0});  // on the path
    const WalkLog log = walk(world, 0, route, 0.0, robot, 30.0);                      // there and back: 20 s alone
    EXPECT_EQ(log.contacts, 0u) << "yielding " << yielding;
    EXPECT_GT(log.min_gap, 0.04) << "yielding " << yielding;
    for (double d : log.closest_to_waypoint) EXPECT_LT(d, 0.01) << "yielding " << yielding;
    EXPECT_GT(log.max_deviation, 0.4) << "yielding " << yielding;  // around, not through
    EXPECT_NEAR(world.groundTruth(robot).x, 0.0, 1e-9);            // and it never pushed the robot
  }
  // Blind (yielding 0), the same walk runs into the robot: what the walker above avoids.
  World world(openMap(), WorldSettings{});
  world.addMovingObstacle(walkerConfig("person_1", route, 0.0));
  const int robot = world.addRobot("robot_0", diffModel(), Pose2D{0.0, 0.0, 0.0});
  EXPECT_GT(walk(world, 0, route, 0.0, robot, 30.0).contacts, 0u);
}

TEST(Walker, YieldingSetsHowEarlyAndHowFarItGivesWay)
{
  const std::vector<Point2D> route = {{-3.0, 0.0}, {3.0, 0.0}};
  std::vector<double> deviation;
  for (double yielding : {0.2, 0.5, 1.0})
  {
    World world(openMap(), WorldSettings{});
    world.addMovingObstacle(walkerConfig("person_1", route, yielding));
    // A robot just off the path: a walker that yields more keeps further from it.
    const int robot = world.addRobot("robot_0", diffModel(), Pose2D{0.0, 0.45, 0.0});
    const WalkLog log = walk(world, 0, route, 0.0, robot, 10.0);
    EXPECT_EQ(log.contacts, 0u);
    deviation.push_back(log.max_deviation);
  }
  EXPECT_LT(deviation[0], deviation[1]);
  EXPECT_LT(deviation[1], deviation[2]);
}

TEST(Walker, GivesWayToARobotDrivingAtIt)
{
  World world(openMap(), WorldSettings{});
  const std::vector<Point2D> route = {{-3.0, 0.0}, {3.0, 0.0}};
  world.addMovingObstacle(walkerConfig("person_1", route));
  // A robot driving straight along the path towards the walker, not steering at all.
  const int robot = world.addRobot("robot_0", diffModel(), Pose2D{3.0, 0.0, kPi});
  const Twist2D cmd{0.3, 0.0, 0.0};
  const WalkLog log = walk(world, 0, route, 0.0, robot, 12.0, &cmd);
  EXPECT_EQ(log.contacts, 0u);
  EXPECT_GT(log.min_gap, 0.0);
  EXPECT_LT(world.groundTruth(robot).x, -0.5);  // the robot went past it
}

TEST(Walker, TwoWalkersPassEachOther)
{
  World world(openMap(), WorldSettings{});
  const std::vector<Point2D> route = {{-3.0, 0.0}, {3.0, 0.0}};
  world.addMovingObstacle(walkerConfig("person_1", route));
  world.addMovingObstacle(walkerConfig("person_2", {{3.0, 0.0}, {-3.0, 0.0}}));
  double min_distance = 1e9;
  for (int i = 0; i < 1000; ++i)
  {
    world.step();
    const auto o = world.obstacles();
    min_distance = std::min(min_distance, std::hypot(o[0].pose.x - o[1].pose.x, o[0].pose.y - o[1].pose.y));
  }
  EXPECT_GT(min_distance, 0.5 + 0.04);  // two radii and the minimum gap
  const auto o = world.obstacles();
  EXPECT_GT(o[0].pose.x, 2.0);  // both got through
  EXPECT_LT(o[1].pose.x, -2.0);
}

TEST(Walker, ARobotAgainstAWallMakesItGoRoundTheOtherSideNotThroughTheWall)
{
  // The room's south wall is y < 0.1 m. The walker's path runs along it with 0.1 m to spare, a
  // robot stands on the path: the right-hand way round (into the wall) is shut.
  World world(roomMap(), WorldSettings{});
  const std::vector<Point2D> route = {{1.0, 0.45}, {6.0, 0.45}};
  world.addMovingObstacle(walkerConfig("person_1", route));
  const int robot = world.addRobot("robot_0", diffModel(), Pose2D{3.5, 0.4, 0.0});
  Recorder rec;
  world.setListener(&rec);
  double lowest = 1e9;
  bool reached_far_end = false;
  for (int i = 0; i < 2500; ++i)
  {
    world.step();
    const Pose2D p = world.obstacles().front().pose;
    lowest = std::min(lowest, p.y);
    reached_far_end = reached_far_end || std::hypot(p.x - 6.0, p.y - 0.45) < 0.01;
  }
  EXPECT_GE(lowest - 0.25, 0.1 - 1e-9);  // its outline never entered the wall
  EXPECT_TRUE(reached_far_end);
  EXPECT_EQ(rec.contacts.size(), 0u);
  EXPECT_NEAR(world.groundTruth(robot).y, 0.4, 1e-9);
}

TEST(Walker, ResetPutsItBackAtItsFirstWaypoint)
{
  World world(openMap(), WorldSettings{});
  world.addMovingObstacle(walkerConfig("person_1", {{-3.0, 0.0}, {3.0, 0.0}}));
  run(world, 3.0);
  ASSERT_GT(world.obstacles().front().pose.x, -1.5);
  world.resetPositions();
  EXPECT_NEAR(world.obstacles().front().pose.x, -3.0, 1e-9);
  run(world, 1.0);
  EXPECT_NEAR(world.obstacles().front().pose.x, -3.0 + 0.6, 1e-6);
}

// ---- sensors ----------------------------------------------------------------------------------

TEST(Sensors, LaserSeesWallsRobotsAndObstaclesAtTheirDistance)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const RobotModel model = diffModel();
  const int id = world.addRobot("robot_0", model, Pose2D{2.0, 4.0, 0.0});  // laser at x = 2.05
  world.addRobot("robot_1", model, Pose2D{3.0, 4.0, 0.0});                 // 0.8 m ahead of the laser
  ObstacleConfig crate;
  crate.name = "crate";
  crate.shape.type = ShapeConfig::Type::BOX;
  crate.shape.length = crate.shape.width = 0.4;
  crate.pose = Pose2D{2.05, 6.0, 0.0};  // straight left: 2.0 - 0.2 = 1.8 m
  world.addObstacle(crate);
  run(world, 0.1);  // the first scan comes one period (0.1 s) after the start
  ASSERT_EQ(rec.scans[id].size(), 1u);
  const std::vector<float>& r = rec.scans[id][0].ranges;
  ASSERT_EQ(r.size(), 360u);
  EXPECT_NEAR(r[beamAt(model, kPi)], 2.05 - 0.1, 0.05);         // west wall (inner face x = 0.1)
  EXPECT_NEAR(r[beamAt(model, -kPi / 2)], 4.0 - 0.1, 0.05);     // south wall
  EXPECT_NEAR(r[beamAt(model, 0.0)], 3.0 - 0.15 - 2.05, 1e-3);  // robot_1's body
  EXPECT_NEAR(r[beamAt(model, kPi / 2)], 1.8, 1e-3);            // the crate
  // The robot's own body is not seen: no beam is shorter than the walls around it allow.
  for (float v : r) EXPECT_GT(v, 0.5);
}

TEST(Sensors, RatesFollowTheModelInSimTime)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});
  run(world, 2.0);
  EXPECT_EQ(rec.odom[id].size(), 100u);   // 50 Hz
  EXPECT_EQ(rec.truth[id].size(), 100u);  // 50 Hz
  EXPECT_EQ(rec.joints[id].size(), 100u);
  EXPECT_EQ(rec.scans[id].size(), 20u);  // 10 Hz
  EXPECT_NEAR(rec.scans[id][1].stamp - rec.scans[id][0].stamp, 0.1, 1e-9);
  EXPECT_NEAR(rec.odom[id][1].stamp - rec.odom[id][0].stamp, 0.02, 1e-9);
}

TEST(Sensors, WheelAnglesFollowTheMotion)
{
  World world(openMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", stiff(diffModel()), Pose2D{});
  drive(world, id, Twist2D{0.0, 0.0, 1.0}, 0.5);  // turn in place: wheels turn opposite ways
  const JointStateSample& j = rec.joints[id].back();
  ASSERT_EQ(j.position.size(), 2u);
  // left wheel at y = +0.11 rolls backwards: -w * 0.11 / 0.04 rad/s
  EXPECT_NEAR(j.velocity[0], -1.0 * 0.11 / 0.04, 1e-6);
  EXPECT_NEAR(j.velocity[1], 1.0 * 0.11 / 0.04, 1e-6);
  EXPECT_NEAR(j.position[0], std::remainder(-0.5 * 0.11 / 0.04, 2 * kPi), 0.03);
}

// ---- determinism and noise --------------------------------------------------------------------

namespace
{
struct Trace
{
  std::vector<double> values;
};

Trace noisyRun(unsigned seed)
{
  WorldSettings settings;
  settings.seed = seed;
  settings.noise = NoiseConfig{0.02, 0.05, 0.05};
  World world(roomMap(), settings);
  Recorder rec;
  world.setListener(&rec);
  const int a = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});
  const int b = world.addRobot("robot_1", diffModel(), Pose2D{2.0, 5.0, 0.0});
  for (int i = 0; i < 300; ++i)
  {
    if (i % 10 == 0)
    {
      world.setCommand(a, Twist2D{0.3, 0.0, 0.4 * std::sin(i * 0.01)});
      world.setCommand(b, Twist2D{0.2, 0.0, -0.3});
    }
    world.step();
  }
  Trace t;
  for (int id : {a, b})
  {
    const Pose2D o = world.odometry(id);
    t.values.insert(t.values.end(), {o.x, o.y, o.theta});
    for (float r : rec.scans[id].back().ranges) t.values.push_back(r);
  }
  return t;
}
}  // namespace

TEST(Determinism, SameSeedSameTrajectoryAndScans)
{
  const Trace first = noisyRun(11), second = noisyRun(11), other = noisyRun(12);
  ASSERT_EQ(first.values.size(), second.values.size());
  for (size_t i = 0; i < first.values.size(); ++i) ASSERT_EQ(first.values[i], second.values[i]) << i;
  size_t differ = 0;
  for (size_t i = 0; i < first.values.size(); ++i) differ += first.values[i] != other.values[i];
  EXPECT_GT(differ, first.values.size() / 2) << "another seed should give other noise";
}

TEST(Noise, LaserNoiseHasTheConfiguredSpread)
{
  WorldSettings settings;
  settings.noise.laser_range = 0.05;
  World world(roomMap(), settings);
  Recorder rec;
  world.setListener(&rec);
  const RobotModel model = diffModel();
  const int id = world.addRobot("robot_0", model, Pose2D{2.0, 4.0, 0.0});
  run(world, 10.0);  // 100 scans of a robot standing still
  const size_t beam = beamAt(model, kPi);
  double sum = 0.0, sum2 = 0.0;
  for (const auto& s : rec.scans[id])
  {
    sum += s.ranges[beam];
    sum2 += s.ranges[beam] * s.ranges[beam];
  }
  const double n = rec.scans[id].size();
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 1.95, 0.02);
  EXPECT_NEAR(sd, 0.05, 0.015);
}

namespace
{
/// Standard deviation of `values` (0 for fewer than 2).
double spread(const std::vector<double>& values)
{
  if (values.size() < 2) return 0.0;
  double mean = 0.0, sum2 = 0.0;
  for (double v : values) mean += v / values.size();
  for (double v : values) sum2 += (v - mean) * (v - mean);
  return std::sqrt(sum2 / values.size());
}
}  // namespace

// Live tuning (stage_node's dynamic_reconfigure server): new noise is in force from the next step.
TEST(Noise, SetNoiseChangesTheSpreadFromTheNextStep)
{
  World world(roomMap(), WorldSettings{});  // no noise
  Recorder rec;
  world.setListener(&rec);
  const RobotModel model = diffModel();
  const int still = world.addRobot("robot_0", model, Pose2D{2.0, 4.0, 0.0});
  const int mover = world.addRobot("robot_1", model, Pose2D{2.0, 2.0, 0.0});
  const size_t beam = beamAt(model, kPi);
  // Beam kPi of the standing robot, and the measured speed of the one driving at 0.2 m/s (after
  // its ramp), from sample `first` on.
  const auto beamRanges = [&](size_t first) {
    std::vector<double> v;
    for (size_t i = first; i < rec.scans[still].size(); ++i) v.push_back(rec.scans[still][i].ranges[beam]);
    return v;
  };
  const auto speeds = [&](size_t first) {
    std::vector<double> v;
    for (size_t i = first; i < rec.odom[mover].size(); ++i) v.push_back(rec.odom[mover][i].twist.vx);
    return v;
  };
  drive(world, mover, Twist2D{0.2, 0.0, 0.0}, 1.0);  // up to speed
  size_t scans0 = rec.scans[still].size(), odom0 = rec.odom[mover].size();
  drive(world, mover, Twist2D{0.2, 0.0, 0.0}, 3.0);
  ASSERT_GE(beamRanges(scans0).size(), 20u);
  EXPECT_LT(spread(beamRanges(scans0)), 1e-6) << "no laser noise yet";
  EXPECT_LT(spread(speeds(odom0)), 1e-3) << "no odometry noise yet";

  world.setNoise(NoiseConfig{0.05, 0.03, 0.0});
  EXPECT_EQ(world.noise().laser_range, 0.05);
  EXPECT_EQ(world.noise().odom_linear, 0.03);
  scans0 = rec.scans[still].size();
  odom0 = rec.odom[mover].size();
  drive(world, mover, Twist2D{0.2, 0.0, 0.0}, 3.0);
  ASSERT_GE(beamRanges(scans0).size(), 20u);
  EXPECT_NEAR(spread(beamRanges(scans0)), 0.05, 0.02) << "laser noise from the next scan on";
  EXPECT_NEAR(spread(speeds(odom0)), 0.03, 0.012) << "odometry noise from the next step on";

  // A bad value is refused with its name, and the noise in force stays.
  std::string error;
  try
  {
    world.setNoise(NoiseConfig{0.01, -0.1, 0.0});
  }
  catch (const SimError& e)
  {
    error = e.what();
  }
  EXPECT_NE(error.find("noise.odom_linear"), std::string::npos) << error;
  EXPECT_THROW(world.setNoise(NoiseConfig{std::nan(""), 0.0, 0.0}), SimError);
  EXPECT_EQ(world.noise().laser_range, 0.05);
  EXPECT_EQ(world.noise().odom_linear, 0.03);

  world.setNoise(NoiseConfig{});  // and back to none
  scans0 = rec.scans[still].size();
  run(world, 2.0);
  EXPECT_LT(spread(beamRanges(scans0)), 1e-6);
}

// ---- faults -----------------------------------------------------------------------------------

TEST(Faults, LaserDropoutFractionMatchesTheProbability)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  world.addRobot("robot_0", diffModel(), Pose2D{5.0, 5.0, 0.0});  // every beam hits a wall
  FaultConfig f;
  f.laser_dropout = 0.3;
  world.setFaults("robot_0", f);
  run(world, 2.0);  // 20 scans, 7200 beams
  size_t nan = 0, inf = 0, total = 0;
  for (const auto& s : rec.scans[0])
    for (float r : s.ranges)
    {
      nan += std::isnan(r);
      inf += std::isinf(r);
      ++total;
    }
  ASSERT_EQ(total, 7200u);
  // A dropped beam is NaN (REP-117 invalid), never +Inf ("nothing in range"): every beam here
  // hits a wall, so no beam may read Inf.
  EXPECT_NEAR(static_cast<double>(nan) / total, 0.3, 0.025);  // 4.6 sigma
  EXPECT_EQ(inf, 0u);
}

TEST(Faults, FrozenDriveIgnoresCommands)
{
  World world(openMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{});
  drive(world, id, Twist2D{0.5, 0.0, 0.0}, 1.0);
  ASSERT_GT(world.velocity(id).vx, 0.4);
  FaultConfig f;
  f.drive_frozen = true;
  world.setFaults("robot_0", f);
  const double x = world.groundTruth(id).x;
  drive(world, id, Twist2D{0.5, 0.0, 1.0}, 1.0);
  EXPECT_NEAR(world.groundTruth(id).x, x, 1e-9);  // stopped at once: motors failed
  EXPECT_NEAR(world.velocity(id).vx, 0.0, 1e-12);
  world.setFaults("robot_0", FaultConfig{});  // cleared: drives again
  drive(world, id, Twist2D{0.5, 0.0, 0.0}, 1.0);
  EXPECT_GT(world.groundTruth(id).x, x + 0.2);
}

TEST(Faults, SilencedRobotPublishesOnlyGroundTruth)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});
  FaultConfig f;
  f.silenced = true;
  world.setFaults("robot_0", f);
  run(world, 1.0);
  EXPECT_EQ(rec.odom[id].size(), 0u);
  EXPECT_EQ(rec.scans[id].size(), 0u);
  EXPECT_EQ(rec.joints[id].size(), 0u);
  EXPECT_EQ(rec.truth[id].size(), 50u);
}

TEST(Faults, LatencyDelaysSamplesButKeepsTheirStamps)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  rec.world = &world;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});
  FaultConfig f;
  f.sensor_latency = 0.1;
  world.setFaults("robot_0", f);
  run(world, 1.0);
  ASSERT_EQ(rec.odom[id].size(), 45u);  // 50 measured, the last 5 still on their way
  for (size_t i = 0; i < rec.odom[id].size(); ++i)
    EXPECT_NEAR(rec.odom_release_times[i] - rec.odom[id][i].stamp, 0.1, 1e-9);
  EXPECT_NEAR(rec.odom[id].front().stamp, 0.02, 1e-9);  // the first one period after the start
  // Ground truth is an oracle: never delayed.
  ASSERT_EQ(rec.truth[id].size(), 50u);
  for (size_t i = 0; i < rec.truth[id].size(); ++i)
    EXPECT_NEAR(rec.truth_release_times[i], rec.truth[id][i].stamp, 1e-9);
}

TEST(Faults, JitterAddsARandomDelayButKeepsTheOrder)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  rec.world = &world;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});
  const double latency = 0.1, jitter = 0.02;  // [s]; jitter = the extra delay's standard deviation
  FaultConfig f;
  f.sensor_latency = latency;
  f.sensor_jitter = jitter;
  world.setFaults("robot_0", f);
  run(world, 20.0);
  const std::vector<OdometrySample>& odom = rec.odom[id];
  ASSERT_GT(odom.size(), 900u);  // 1000 measured at 50 Hz, the last few still on their way
  double sum = 0.0, largest = 0.0;
  for (size_t i = 0; i < odom.size(); ++i)
  {
    const double extra = rec.odom_release_times[i] - odom[i].stamp - latency;
    EXPECT_GE(extra, -1e-9) << "sample " << i << " came before its latency";
    if (i > 0) EXPECT_GT(odom[i].stamp, odom[i - 1].stamp) << "sample " << i << " overtook the one before";
    sum += extra;
    largest = std::max(largest, extra);
  }
  // Each sample waits |N(0, jitter)| more, or longer when the sample before it is still held
  // (the order is kept): at least the half-normal mean jitter * sqrt(2 / pi) on average.
  const double mean = sum / odom.size();
  EXPECT_GT(mean, jitter * std::sqrt(2.0 / M_PI) * 0.9);
  EXPECT_LT(mean, 3.0 * jitter);
  EXPECT_LT(largest, 5.0 * jitter);
  // A delayed sample physically stays what it measured: the stamp is when it was measured.
  EXPECT_NEAR(odom.front().stamp, 0.02, 1e-9);
}

TEST(Faults, ResetDropsSamplesStillHeldBackByLatency)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  rec.world = &world;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});
  FaultConfig f;
  f.sensor_latency = 0.5;
  f.sensor_jitter = 0.05;
  world.setFaults("robot_0", f);
  drive(world, id, Twist2D{0.3, 0.0, 0.0}, 2.0);
  ASSERT_GT(world.odometry(id).x, 0.3);
  const double t_reset = world.time();
  const size_t odom_before = rec.odom[id].size(), scans_before = rec.scans[id].size();
  ASSERT_GT(odom_before, 50u);  // the pipeline is full: 0.5 s of samples on their way
  world.resetPositions();
  run(world, 2.0);
  // Nothing measured before the reset arrives after it; what comes is new, delayed as before.
  ASSERT_GT(rec.odom[id].size(), odom_before + 50);
  for (size_t i = odom_before; i < rec.odom[id].size(); ++i)
  {
    EXPECT_GT(rec.odom[id][i].stamp, t_reset) << "sample " << i;
    EXPECT_NEAR(rec.odom[id][i].pose.x, 0.0, 1e-9) << "old odometry after the reset";
    EXPECT_GE(rec.odom_release_times[i] - rec.odom[id][i].stamp, 0.5 - 1e-9);
  }
  ASSERT_GT(rec.scans[id].size(), scans_before + 5);
  for (size_t i = scans_before; i < rec.scans[id].size(); ++i) EXPECT_GT(rec.scans[id][i].stamp, t_reset);
  // The delivery order did not stall: the first new odometry came 0.5 s (+ jitter) after it was measured.
  EXPECT_LT(rec.odom_release_times[odom_before] - t_reset, 0.5 + 0.02 + 4 * 0.05);
}

TEST(Faults, OdometryDriftTurnsTheOdomFrame)
{
  World world(openMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{});
  FaultConfig f;
  f.odom_drift = 0.05;
  world.setFaults("robot_0", f);
  run(world, 2.0);
  EXPECT_NEAR(world.odometry(id).theta, 0.1, 1e-6);
  EXPECT_NEAR(world.groundTruth(id).theta, 0.0, 1e-9);
}

// ---- run-time requests ------------------------------------------------------------------------

TEST(Requests, SpawnTeleportRemoveAndTheirErrors)
{
  World world(roomMap(), WorldSettings{});
  const RobotModel model = diffModel();
  world.addRobot("robot_0", model, Pose2D{2.0, 2.0, 0.0});
  EXPECT_THROW(world.addRobot("robot_0", model, Pose2D{4.0, 4.0, 0.0}), SimError);   // duplicate
  EXPECT_THROW(world.addRobot("robot_1", model, Pose2D{0.05, 4.0, 0.0}), SimError);  // in a wall
  EXPECT_THROW(world.addRobot("robot_1", model, Pose2D{2.2, 2.0, 0.0}), SimError);   // on robot_0
  EXPECT_THROW(world.addRobot("map", model, Pose2D{4.0, 4.0, 0.0}), SimError);       // the walls' name
  const int b = world.addRobot("robot_1", model, Pose2D{4.0, 4.0, 0.0});
  EXPECT_EQ(world.robotCount(), 2u);

  try
  {
    world.teleport("robot_1", Pose2D{7.25, 1.0, 0.0});
    FAIL() << "teleport into a wall must fail";
  }
  catch (const SimError& e)
  {
    EXPECT_NE(std::string(e.what()).find("would overlap a wall"), std::string::npos) << e.what();
  }
  EXPECT_NEAR(world.groundTruth(b).x, 4.0, 1e-9);  // unchanged
  EXPECT_THROW(world.teleport("robot_9", Pose2D{4.0, 4.0, 0.0}), SimError);
  world.teleport("robot_1", Pose2D{5.0, 6.0, 1.0});
  world.step();
  EXPECT_NEAR(world.groundTruth(b).x, 5.0, 1e-9);
  EXPECT_NEAR(world.groundTruth(b).theta, 1.0, 1e-9);
  EXPECT_NEAR(world.odometry(b).x, 0.0, 1e-9);  // a kidnapping: the wheels did not turn
  EXPECT_NEAR(world.odometry(b).theta, 0.0, 1e-9);

  FaultConfig bad;
  bad.laser_dropout = 1.5;
  EXPECT_THROW(world.setFaults("robot_1", bad), SimError);
  EXPECT_THROW(world.setFaults("nobody", FaultConfig{}), SimError);

  world.removeRobot("robot_0");
  EXPECT_EQ(world.robotCount(), 1u);
  EXPECT_EQ(world.findRobot("robot_0"), -1);
  EXPECT_THROW(world.removeRobot("robot_0"), SimError);
  // Its place is free again; a new robot gets a new id.
  const int c = world.addRobot("robot_0", model, Pose2D{2.0, 2.0, 0.0});
  EXPECT_EQ(c, 2);
  world.step();
}

/// Step until the robot's next scan (at most 1 s); return it.
std::vector<float> nextScan(World& world, Recorder& rec, int robot)
{
  const size_t before = rec.scans[robot].size();
  for (int i = 0; i < 100 && rec.scans[robot].size() == before; ++i) world.step();
  if (rec.scans[robot].size() == before) ADD_FAILURE() << "no scan within 1 s";
  return rec.scans[robot].empty() ? std::vector<float>() : rec.scans[robot].back().ranges;
}

ObstacleConfig box(const std::string& name, double length, double width, const Pose2D& pose)
{
  ObstacleConfig o;
  o.name = name;
  o.shape.type = ShapeConfig::Type::BOX;
  o.shape.length = length;
  o.shape.width = width;
  o.pose = pose;
  return o;
}

/// The message of the SimError `f` throws ("" and a test failure when it throws none).
template <class F>
std::string errorOf(F f)
{
  try
  {
    f();
  }
  catch (const SimError& e)
  {
    return e.what();
  }
  ADD_FAILURE() << "expected a SimError";
  return "";
}

// stage_node's cmd_pose and cmd_pose_stamped: the odometry moves with the robot, the odom frame
// stays where it is in the map (stage_ros with Stage's default "gps" localization).
TEST(Requests, TeleportWithOdometryFollowingKeepsTheOdomFrameInTheMap)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.5});
  drive(world, id, Twist2D{0.3, 0.0, 0.4}, 2.0);
  run(world, 1.0);  // at rest
  const Pose2D odom_frame = mbot_common::compose(world.groundTruth(id), mbot_common::inverse(world.odometry(id)));
  const Pose2D target{5.0, 6.0, -2.0};
  world.teleport("robot_0", target, true);
  world.step();
  const Pose2D truth = world.groundTruth(id);
  EXPECT_NEAR(truth.x, target.x, 1e-9);
  EXPECT_NEAR(truth.y, target.y, 1e-9);
  EXPECT_NEAR(truth.theta, target.theta, 1e-9);
  // the odometry jumped with the robot: map -> odom is unchanged
  const Pose2D odom_frame_after = mbot_common::compose(truth, mbot_common::inverse(world.odometry(id)));
  EXPECT_NEAR(odom_frame_after.x, odom_frame.x, 1e-9);
  EXPECT_NEAR(odom_frame_after.y, odom_frame.y, 1e-9);
  EXPECT_NEAR(mbot_common::normalizeAngle(odom_frame_after.theta - odom_frame.theta), 0.0, 1e-9);
  // at rest at once: true zeros
  run(world, 0.1);
  EXPECT_EQ(rec.odom[id].back().twist.vx, 0.0);
  EXPECT_EQ(rec.odom[id].back().twist.wz, 0.0);
  EXPECT_EQ(rec.truth[id].back().twist.vx, 0.0);
  EXPECT_EQ(rec.truth[id].back().twist.wz, 0.0);
}

TEST(Requests, SpawnedObstacleIsSeenFromTheNextScanAndGoneAfterRemoval)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const RobotModel model = diffModel();
  const int id = world.addRobot("robot_0", model, Pose2D{4.0, 4.0, 0.0});  // laser at x = 4.05
  const size_t ahead = beamAt(model, 0.0), left = beamAt(model, kPi / 2);
  const double wall_ahead = 9.9 - 4.05, wall_left = 7.9 - 4.0;  // east and north inner faces
  run(world, 0.15);                                             // between two scans (0.1 s, 0.2 s)
  ASSERT_EQ(rec.scans[id].size(), 1u);
  EXPECT_NEAR(rec.scans[id][0].ranges[ahead], wall_ahead, 1e-3);

  world.addObstacle(box("crate", 0.4, 0.6, Pose2D{6.0, 4.0, 0.0}));  // near face at x = 5.8
  ObstacleConfig drum;
  drum.name = "drum";
  drum.shape.type = ShapeConfig::Type::CYLINDER;
  drum.shape.radius = 0.25;
  drum.pose = Pose2D{4.05, 6.0, 0.0};  // 2.0 - 0.25 m left of the laser
  world.addObstacle(drum);
  ASSERT_EQ(world.obstacles().size(), 2u);
  std::vector<float> r = nextScan(world, rec, id);
  EXPECT_NEAR(rec.scans[id].back().stamp, 0.2, 1e-9);  // the first scan after the spawn
  EXPECT_NEAR(r[ahead], 5.8 - 4.05, 1e-3);
  EXPECT_NEAR(r[left], 2.0 - 0.25, 1e-3);

  world.removeObstacle("crate");
  EXPECT_EQ(world.obstacles().size(), 1u);
  EXPECT_EQ(world.obstacles().front().name, "drum");
  r = nextScan(world, rec, id);
  EXPECT_NEAR(r[ahead], wall_ahead, 1e-3);  // the wall again
  EXPECT_NEAR(r[left], 2.0 - 0.25, 1e-3);   // the drum stays
  world.removeObstacle("drum");
  EXPECT_TRUE(world.obstacles().empty());
  r = nextScan(world, rec, id);
  EXPECT_NEAR(r[left], wall_left, 1e-3);

  // The name is free again; a robot driven into the new crate stops at it, one contact with its name.
  world.addObstacle(box("crate", 0.4, 0.6, Pose2D{5.0, 4.0, 0.0}));  // near face at x = 4.8
  double max_x = 0.0;
  for (int i = 0; i < 300; ++i)  // 3 s at up to 0.5 m/s: would be > 1 m, the crate is 0.65 m away
  {
    if (i % 10 == 0) world.setCommand(id, Twist2D{0.5, 0.0, 0.0});
    world.step();
    max_x = std::max(max_x, world.groundTruth(id).x);
  }
  EXPECT_LE(max_x + 0.15, 4.8) << "the footprint entered the crate";
  EXPECT_NEAR(world.groundTruth(id).x, 4.8 - 0.15, 0.02);
  EXPECT_EQ(rec.contactsBetween("robot_0", "crate"), 1);
  EXPECT_EQ(rec.contacts.size(), 1u);

  // Removed while the robot rests against it: the way is free, the robot drives on.
  world.removeObstacle("crate");
  drive(world, id, Twist2D{0.5, 0.0, 0.0}, 1.0);
  EXPECT_GT(world.groundTruth(id).x, 4.8);
  EXPECT_EQ(rec.contacts.size(), 1u);
}

TEST(Requests, ObstacleFromTheWorldFileCanBeRemoved)
{
  WorldConfig config;
  config.file = "test.world.yaml";
  config.map = config.map_path = kFixtures + "/room.yaml";
  config.map_data = roomMap();
  ObstacleConfig crate = box("crate_1", 1.0, 1.0, Pose2D{2.0, 2.0, 0.0});
  crate.key = "obstacles[0]";
  config.obstacles.push_back(crate);
  auto world = buildWorld(config, [](const std::string&) { return diffModel(); });
  ASSERT_EQ(world->obstacles().size(), 1u);
  EXPECT_FALSE(world->isFree(2.0, 2.0, 0.15));
  world->removeObstacle("crate_1");
  EXPECT_TRUE(world->obstacles().empty());
  EXPECT_TRUE(world->isFree(2.0, 2.0, 0.15));
  world->addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.0});  // where the crate was
}

TEST(Requests, BadObstacleRequestsAreRefusedWithTheirReasonAndChangeNothing)
{
  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const RobotModel model = diffModel();
  const int id = world.addRobot("robot_0", model, Pose2D{2.0, 2.0, 0.0});
  MovingObstacleConfig person;
  person.name = "person_1";
  person.shape.type = ShapeConfig::Type::CYLINDER;
  person.shape.radius = 0.25;
  person.waypoints = {{8.5, 1.0}, {8.5, 2.5}};  // behind the wall block: robot_0 cannot see it
  world.addMovingObstacle(person);
  world.addObstacle(box("crate", 0.4, 0.4, Pose2D{4.0, 2.0, 0.0}));  // near face at x = 3.8
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const double inf = std::numeric_limits<double>::infinity();
  const Pose2D free_pose{3.0, 2.0, 0.0};  // in robot_0's laser beam, between it and the crate

  struct Case
  {
    ObstacleConfig obstacle;
    std::string message;
  };
  std::vector<Case> cases = {
      {box("crate", 0.4, 0.4, free_pose), "duplicate name \"crate\": a body of that name exists already"},
      {box("robot_0", 0.4, 0.4, free_pose), "duplicate name \"robot_0\""},
      {box("person_1", 0.4, 0.4, free_pose), "duplicate name \"person_1\""},
      {box("map", 0.4, 0.4, free_pose), "duplicate name \"map\""},
      {box("bad name", 0.4, 0.4, free_pose),
       "obstacle name: expected a name of letters, digits and _ (not starting with a digit), got \"bad name\""},
      {box("1crate", 0.4, 0.4, free_pose), "obstacle name: expected a name of letters"},
      {box("", 0.4, 0.4, free_pose), "obstacle name: expected a name of letters"},
      {box("b", 0.0, 0.4, free_pose), "obstacle b: length: expected a number > 0 [m], got 0"},
      {box("b", 0.4, -0.5, free_pose), "obstacle b: width: expected a number > 0 [m], got -0.5"},
      {box("b", nan, 0.4, free_pose), "obstacle b: length: expected a number > 0 [m], got nan"},
      {box("b", 0.4, 0.4, Pose2D{nan, 2.0, 0.0}), "obstacle b: the pose is not finite"},
      {box("b", 0.4, 0.4, Pose2D{3.0, inf, 0.0}), "obstacle b: the pose is not finite"},
      {box("b", 0.4, 0.4, Pose2D{3.0, 2.0, nan}), "obstacle b: the pose is not finite"},
      {box("b", 0.4, 0.4, Pose2D{40.0, 2.0, 0.0}), "obstacle b at (40.00, 2.00) is outside the map"},
      {box("b", 0.4, 0.4, Pose2D{2.0, -0.5, 0.0}), "obstacle b at (2.00, -0.50) is outside the map"},
      {box("b", 0.4, 0.4, Pose2D{2.3, 2.0, 0.0}), "obstacle b at (2.30, 2.00) overlaps robot robot_0"},
      {box("b", 0.4, 0.4, Pose2D{2.0, 2.3, 0.8}), "obstacle b at (2.00, 2.30) overlaps robot robot_0"},
  };
  ObstacleConfig cylinder;
  cylinder.name = "c";
  cylinder.shape.type = ShapeConfig::Type::CYLINDER;
  cylinder.pose = free_pose;
  cylinder.shape.radius = 0.0;
  cases.push_back({cylinder, "obstacle c: radius: expected a number > 0 [m], got 0"});
  cylinder.shape.radius = nan;
  cases.push_back({cylinder, "obstacle c: radius: expected a number > 0 [m], got nan"});
  cylinder.shape.radius = 0.3;
  cylinder.pose = Pose2D{2.0, 1.6, 0.0};  // 0.4 m apart, radii 0.15 + 0.3
  cases.push_back({cylinder, "obstacle c at (2.00, 1.60) overlaps robot robot_0"});

  run(world, 0.1);
  const std::vector<float> before = rec.scans[id].back().ranges;
  const size_t ahead = beamAt(model, 0.0);
  ASSERT_NEAR(before[ahead], 3.8 - 2.05, 1e-3);
  for (const Case& c : cases)
  {
    const std::string message = errorOf([&] { world.addObstacle(c.obstacle); });
    EXPECT_NE(message.find(c.message), std::string::npos) << "got: " << message << "\nexpected: " << c.message;
  }
  // Nothing changed: the same bodies, the same scan.
  ASSERT_EQ(world.obstacles().size(), 2u);
  EXPECT_EQ(world.obstacles()[0].name, "crate");
  EXPECT_NEAR(world.obstacles()[0].pose.x, 4.0, 1e-12);
  EXPECT_EQ(world.robotCount(), 1u);
  const std::vector<float> after = nextScan(world, rec, id);
  ASSERT_EQ(after.size(), before.size());
  for (size_t i = 0; i < after.size(); ++i) EXPECT_EQ(after[i], before[i]) << "beam " << i;

  // Removal: only static obstacles, by their name.
  EXPECT_EQ(errorOf([&] { world.removeObstacle("nothing"); }), "unknown obstacle \"nothing\"");
  EXPECT_EQ(errorOf([&] { world.removeObstacle("robot_0"); }), "\"robot_0\" is a robot, not an obstacle");
  EXPECT_EQ(errorOf([&] { world.removeObstacle("person_1"); }),
            "\"person_1\" is a moving obstacle; only static obstacles can be removed");
  EXPECT_EQ(errorOf([&] { world.removeObstacle("map"); }), "\"map\" is the walls, not an obstacle");
  EXPECT_EQ(world.obstacles().size(), 2u);
  EXPECT_EQ(world.robotCount(), 1u);

  // Touching a wall is allowed (the wall block is x in [7.0, 7.5]): as in a world file.
  world.addObstacle(box("against_the_block", 0.4, 0.4, Pose2D{6.9, 1.0, 0.0}));
  EXPECT_EQ(world.obstacles().size(), 3u);
  world.resetPositions();  // moves robots and movers only
  EXPECT_EQ(world.obstacles().size(), 3u);
}

TEST(Requests, ObstacleRequestShapesAsTheWorldFileReaderWordsThem)
{
  const Pose2D pose{3.0, 2.0, 0.5};
  const ObstacleConfig b = obstacleFromRequest("crate", "box", 0.5, 0.4, 0.0, pose);
  EXPECT_EQ(b.name, "crate");
  EXPECT_EQ(b.shape.type, ShapeConfig::Type::BOX);
  EXPECT_DOUBLE_EQ(b.shape.length, 0.5);
  EXPECT_DOUBLE_EQ(b.shape.width, 0.4);
  EXPECT_DOUBLE_EQ(b.pose.theta, 0.5);
  const ObstacleConfig c = obstacleFromRequest("drum", "cylinder", 0.0, 0.0, 0.3, pose);
  EXPECT_EQ(c.shape.type, ShapeConfig::Type::CYLINDER);
  EXPECT_DOUBLE_EQ(c.shape.radius, 0.3);

  EXPECT_EQ(errorOf([&] { obstacleFromRequest("t", "triangle", 0.5, 0.5, 0.0, pose); }),
            "obstacle t: shape: expected box or cylinder, got \"triangle\"");
  EXPECT_EQ(errorOf([&] { obstacleFromRequest("t", "", 0.5, 0.5, 0.0, pose); }),
            "obstacle t: shape: expected box or cylinder, got \"\"");
  EXPECT_EQ(errorOf([&] { obstacleFromRequest("t", "Box", 0.5, 0.5, 0.0, pose); }),
            "obstacle t: shape: expected box or cylinder, got \"Box\"");
  EXPECT_EQ(errorOf([&] { obstacleFromRequest("t", "box", 0.5, 0.5, 0.2, pose); }),
            "obstacle t: radius: a box has a size [length, width], not a radius");
  EXPECT_EQ(errorOf([&] { obstacleFromRequest("t", "cylinder", 0.5, 0.0, 0.2, pose); }),
            "obstacle t: length, width: a cylinder has a radius, not a size");
}

TEST(Requests, ResetPutsRobotsBackAndZeroesOdometry)
{
  World world(roomMap(), WorldSettings{});
  const int id = world.addRobot("robot_0", diffModel(), Pose2D{2.0, 2.0, 0.3});
  drive(world, id, Twist2D{0.3, 0.0, 0.5}, 2.0);
  ASSERT_GT(std::hypot(world.odometry(id).x, world.odometry(id).y), 0.3);
  const double t = world.time();
  world.resetPositions();
  world.step();
  EXPECT_NEAR(world.groundTruth(id).x, 2.0, 1e-9);
  EXPECT_NEAR(world.groundTruth(id).theta, 0.3, 1e-9);
  EXPECT_NEAR(world.odometry(id).x, 0.0, 1e-9);
  EXPECT_NEAR(world.odometry(id).theta, 0.0, 1e-9);
  EXPECT_GT(world.time(), t);  // sim time goes on
}

// The fixture the wall and laser tests use (read by mbot_common::loadMap, tested there).
TEST(Walls, RoomFixtureHasWallsAroundAndFreeInside)
{
  const OccupancyMap map = roomMap();
  ASSERT_EQ(map.width, 200u);
  ASSERT_EQ(map.height, 160u);
  EXPECT_EQ(map.at(0, 0), 100);
  EXPECT_EQ(map.at(1, 80), 100);    // x = 0.075 m: inside the 0.1 m west wall
  EXPECT_EQ(map.at(2, 80), 0);      // x = 0.125 m: free
  EXPECT_EQ(map.at(100, 80), 0);    // the middle
  EXPECT_EQ(map.at(145, 30), 100);  // x = 7.25, y = 1.5: the wall block
  EXPECT_EQ(map.at(145, 70), 0);    // x = 7.25, y = 3.5: above the block
}

TEST(Walls, MergedRectanglesCoverExactlyTheOccupiedCells)
{
  const OccupancyMap map = roomMap();
  const std::vector<CellRect> rects = mergeOccupiedCells(map);
  std::vector<int> covered(map.data.size(), 0);
  for (const auto& r : rects)
    for (unsigned y = r.y; y < r.y + r.height; ++y)
      for (unsigned x = r.x; x < r.x + r.width; ++x) ++covered[y * map.width + x];
  for (size_t i = 0; i < map.data.size(); ++i) ASSERT_EQ(covered[i], map.data[i] == 100 ? 1 : 0) << i;
  EXPECT_LE(rects.size(), 6u);  // 4 walls + the block (+ a split)
}

// ---- the real models of mbot_description ------------------------------------------------------

TEST(RealModels, MbotOmniBoxBodyStrafesIntoAWallAndStopsAtIt)
{
  const RobotModel omni = mbot_description::loadRobotModel(MBOT_DESCRIPTION_DIR, "mbot_omni");
  const RobotModel mbot = mbot_description::loadRobotModel(MBOT_DESCRIPTION_DIR, "mbot");
  ASSERT_EQ(omni.drive, DriveType::OMNI);
  ASSERT_EQ(omni.footprint.size(), 4u);  // a rectangle: a box body
  double half_width = 0.0;               // footprint extent along y [m]
  for (const auto& p : omni.footprint) half_width = std::max(half_width, std::abs(p.y));

  World world(roomMap(), WorldSettings{});
  Recorder rec;
  world.setListener(&rec);
  const int id = world.addRobot("omni", omni, Pose2D{3.0, 1.0, 0.0});
  world.addRobot("round", mbot, Pose2D{5.0, 1.0, 0.0});
  double min_y = 1.0;
  for (int i = 0; i < 500; ++i)  // 5 s sideways (right, -y) towards the south wall (y = 0.1)
  {
    if (i % 10 == 0) world.setCommand(id, Twist2D{0.0, -0.3, 0.0});
    world.step();
    min_y = std::min(min_y, world.groundTruth(id).y);
  }
  EXPECT_GE(min_y - half_width, 0.1) << "the box body entered the wall";
  EXPECT_NEAR(world.groundTruth(id).y, 0.1 + half_width, 0.02);
  EXPECT_NEAR(world.groundTruth(id).theta, 0.0, 0.01);  // a flat face against a flat wall: no turn
  EXPECT_EQ(rec.contactsBetween("omni", "map"), 1);
  // Its first scan (0.1 s, before it moved away sideways) saw the round robot 2 m ahead, from
  // the laser mount at laser.mount_x.
  const std::vector<float>& r = rec.scans[id].front().ranges;
  EXPECT_NEAR(r[beamAt(omni, 0.0)], 5.0 - 0.15 - (3.0 + omni.laser.mount_x), 0.01);
}
