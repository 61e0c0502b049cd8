/**
 * @file test_world_config.cpp
 * @brief The strict world file reader: a file with every key reads into the right values, and
 *        each invalid world fails with a message naming the file, the key and the problem: the
 *        invalid_* fixtures of mbot_common (its reader's cases) and those here (buildWorld's).
 */
#include "mbot_sim/world.h"

#include <gtest/gtest.h>
#include <mbot_common/testing/fixture_cases.h>

#include <string>

using mbot_sim::MovingObstacleConfig;
using mbot_sim::ShapeConfig;
using mbot_sim::WorldConfig;
using mbot_sim::WorldConfigError;

namespace
{
const std::string kFixtures = MBOT_SIM_FIXTURES;
const std::string kCommonWorlds = MBOT_COMMON_WORLD_FIXTURES;

/// A circular robot model like mbot (the geometry tests do not need the URDF).
mbot_description::RobotModel testModel(const std::string& name)
{
  if (name != "mbot" && name != "mbot_omni") throw std::runtime_error("no model named " + name);
  mbot_description::RobotModel m;
  m.name = name;
  m.drive = name == "mbot" ? mbot_description::DriveType::DIFF : mbot_description::DriveType::OMNI;
  m.footprint_radius = 0.15;
  m.mass = 2.4;
  m.wheel_radius = 0.04;
  m.wheel_separation = 0.22;
  m.wheel_joints = {"left_wheel_joint", "right_wheel_joint"};
  return m;
}

/// The message of reading and building the world file `path`, or "" when it works.
std::string worldError(const std::string& path)
{
  try
  {
    const WorldConfig config = mbot_sim::loadWorldConfig(path);
    mbot_sim::buildWorld(config, &testModel);
  }
  catch (const WorldConfigError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(WorldConfig, ReadsEveryKey)
{
  const WorldConfig c = mbot_sim::loadWorldConfig(kFixtures + "/full.world.yaml");
  EXPECT_EQ(c.map_path, kFixtures + "/room.yaml");  // relative to the world file
  EXPECT_EQ(c.map_data.width, 200u);                // loaded
  EXPECT_DOUBLE_EQ(c.physics_step, 0.005);
  EXPECT_DOUBLE_EQ(c.real_time_factor, 0.0);
  EXPECT_EQ(c.seed, 7u);
  ASSERT_EQ(c.robots.size(), 2u);
  EXPECT_EQ(c.robots[0].name, "leader");
  EXPECT_EQ(c.robots[1].model, "mbot_omni");
  EXPECT_DOUBLE_EQ(c.robots[1].pose.theta, -0.5);
  ASSERT_EQ(c.obstacles.size(), 2u);
  EXPECT_EQ(c.obstacles[0].shape.type, ShapeConfig::Type::BOX);
  EXPECT_DOUBLE_EQ(c.obstacles[0].shape.width, 0.4);
  EXPECT_EQ(c.obstacles[1].name, "obstacle_1");  // unnamed: named by its index
  EXPECT_DOUBLE_EQ(c.obstacles[1].shape.radius, 0.2);
  ASSERT_EQ(c.moving_obstacles.size(), 2u);
  EXPECT_EQ(c.moving_obstacles[0].mode, MovingObstacleConfig::Mode::PING_PONG);
  EXPECT_EQ(c.moving_obstacles[0].waypoints.size(), 3u);
  EXPECT_EQ(c.moving_obstacles[1].mode, MovingObstacleConfig::Mode::LOOP);  // the default
  EXPECT_DOUBLE_EQ(c.noise.odom_angular, 0.03);
  ASSERT_EQ(c.faults.size(), 1u);
  EXPECT_EQ(c.faults[0].robot, "follower_1");
  EXPECT_DOUBLE_EQ(c.faults[0].faults.laser_dropout, 0.1);
  EXPECT_TRUE(c.faults[0].faults.silenced);
  EXPECT_FALSE(c.faults[0].faults.drive_frozen);

  auto world = mbot_sim::buildWorld(c, &testModel);
  EXPECT_EQ(world->robotCount(), 2u);
  EXPECT_EQ(world->obstacles().size(), 4u);
  EXPECT_TRUE(world->faults(world->findRobot("follower_1")).silenced);
}

TEST(WorldConfig, DefaultsWhenOptionalKeysAreMissing)
{
  const WorldConfig c = mbot_sim::loadWorldConfig(kFixtures + "/three_robots.world.yaml");
  EXPECT_EQ(c.robots.size(), 3u);
  EXPECT_EQ(c.robots[0].model, "mbot");
  EXPECT_TRUE(c.obstacles.empty());
  EXPECT_DOUBLE_EQ(c.noise.laser_range, 0.0);
}

struct InvalidCase
{
  std::string file;
  std::string message;  ///< expected substring, after "<file>: "
};

TEST(WorldConfig, EachInvalidFixtureGivesItsMessage)
{
  // What only buildWorld checks (models, robots against walls, obstacles, each other and the map).
  const InvalidCase cases[] = {
      {"invalid_robot_in_wall.world.yaml", "robots[0].pose: robot robot_0 at (7.20, 1.00) overlaps a wall"},
      {"invalid_robot_overlap.world.yaml", "robots[1].pose: robot robot_1 at (2.20, 2.00) overlaps robot robot_0"},
      {"invalid_robot_on_obstacle.world.yaml",
       "robots[0].pose: robot robot_0 at (2.30, 2.00) overlaps obstacle crate_1"},
      {"invalid_robot_outside.world.yaml", "robots[0].pose: robot robot_0 at (20.00, 2.00) is outside the map"},
      {"invalid_model.world.yaml", "robots[0].model: cannot load model \"hovercraft\": no model named hovercraft"},
  };
  for (const auto& c : cases)
  {
    const std::string path = kFixtures + "/" + c.file;
    const std::string message = worldError(path);
    const std::string expected = path + ": " + c.message;
    EXPECT_NE(message.find(expected), std::string::npos)
        << "fixture " << c.file << "\n  got:      " << message << "\n  expected: " << expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}

TEST(WorldConfig, EachCommonInvalidFixtureGivesItsMessageThroughTheSimulator)
{
  // mbot_common's invalid worlds, read and built as stage_node does: the simulator keeps the
  // reader's message for each (the bad map, duplicate names, unknown keys, faults...).
  const auto cases = mbot_common_test::invalidFixtures(kCommonWorlds, ".world.yaml");
  EXPECT_GE(cases.size(), 40u) << "invalid_*.world.yaml in " << kCommonWorlds;
  for (const auto& c : cases)
  {
    ASSERT_FALSE(c.expected.empty()) << c.path << ": no '# expect: ' first line";
    const std::string message = worldError(c.path);
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "fixture " << c.path << "\n  got:      " << message << "\n  expected: " << c.expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}
