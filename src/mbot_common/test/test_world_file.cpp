/**
 * @file test_world_file.cpp
 * @brief world_file.h: the valid world fixtures read into the right values, and each
 *        invalid_* fixture of test/fixtures/worlds gives the message of its `# expect:` line
 *        (test_common_world.py checks the Python reader against the same lines).
 */
#include "mbot_common/world_file.h"

#include <gtest/gtest.h>

#include <string>

#include "mbot_common/testing/fixture_cases.h"

using mbot_common::MovingObstacleConfig;
using mbot_common::ShapeConfig;
using mbot_common::WorldConfig;
using mbot_common::WorldConfigError;

namespace
{
const std::string kWorlds = std::string(MBOT_COMMON_FIXTURES) + "/worlds";
}  // namespace

TEST(WorldFile, ReadsEveryKey)
{
  const WorldConfig c = mbot_common::loadWorldConfig(kWorlds + "/valid_full.world.yaml");
  EXPECT_EQ(c.file, kWorlds + "/valid_full.world.yaml");
  EXPECT_EQ(c.map, "room.yaml");
  EXPECT_EQ(c.map_path, kWorlds + "/room.yaml");  // relative to the world file
  EXPECT_EQ(c.map_data.width, 20u);
  EXPECT_EQ(c.map_data.height, 16u);
  EXPECT_DOUBLE_EQ(c.map_data.resolution, 0.5);
  EXPECT_EQ(c.map_data.at(0, 0), 100);  // the wall
  EXPECT_EQ(c.map_data.at(1, 1), 0);    // inside
  EXPECT_DOUBLE_EQ(c.physics_step, 0.005);
  EXPECT_DOUBLE_EQ(c.real_time_factor, 0.0);
  EXPECT_EQ(c.seed, 7u);
  ASSERT_EQ(c.robots.size(), 2u);
  EXPECT_EQ(c.robots[0].name, "leader");
  EXPECT_EQ(c.robots[0].model, "mbot");
  EXPECT_DOUBLE_EQ(c.robots[0].pose.x, 1.0);
  EXPECT_DOUBLE_EQ(c.robots[0].pose.theta, 0.5);
  EXPECT_EQ(c.robots[1].model, "mbot_omni");
  EXPECT_DOUBLE_EQ(c.robots[1].pose.theta, -0.5);
  EXPECT_EQ(c.robots[1].key, "robots[1]");
  ASSERT_EQ(c.obstacles.size(), 2u);
  EXPECT_EQ(c.obstacles[0].name, "crate_1");
  EXPECT_EQ(c.obstacles[0].shape.type, ShapeConfig::Type::BOX);
  EXPECT_DOUBLE_EQ(c.obstacles[0].shape.length, 0.5);
  EXPECT_DOUBLE_EQ(c.obstacles[0].shape.width, 0.4);
  EXPECT_DOUBLE_EQ(c.obstacles[0].pose.theta, 0.3);
  EXPECT_EQ(c.obstacles[1].name, "obstacle_1");  // unnamed: named by its index
  EXPECT_EQ(c.obstacles[1].shape.type, ShapeConfig::Type::CYLINDER);
  EXPECT_DOUBLE_EQ(c.obstacles[1].shape.radius, 0.2);
  ASSERT_EQ(c.moving_obstacles.size(), 2u);
  EXPECT_EQ(c.moving_obstacles[0].name, "person_1");
  EXPECT_EQ(c.moving_obstacles[0].mode, MovingObstacleConfig::Mode::PING_PONG);
  ASSERT_EQ(c.moving_obstacles[0].waypoints.size(), 3u);
  EXPECT_DOUBLE_EQ(c.moving_obstacles[0].waypoints[2].y, 7.0);
  EXPECT_DOUBLE_EQ(c.moving_obstacles[0].speed, 0.6);
  EXPECT_EQ(c.moving_obstacles[1].name, "moving_obstacle_1");
  EXPECT_EQ(c.moving_obstacles[1].mode, MovingObstacleConfig::Mode::LOOP);  // the default
  EXPECT_DOUBLE_EQ(c.moving_obstacles[0].yielding, 0.5);
  EXPECT_DOUBLE_EQ(c.moving_obstacles[0].personal_radius, 1.2);
  EXPECT_DOUBLE_EQ(c.moving_obstacles[1].yielding, 1.0);  // the defaults
  EXPECT_DOUBLE_EQ(c.moving_obstacles[1].personal_radius, 0.8);
  EXPECT_DOUBLE_EQ(c.noise.laser_range, 0.01);
  EXPECT_DOUBLE_EQ(c.noise.odom_linear, 0.02);
  EXPECT_DOUBLE_EQ(c.noise.odom_angular, 0.03);
  EXPECT_DOUBLE_EQ(c.noise.imu.rate, 400.0);
  EXPECT_DOUBLE_EQ(c.noise.imu.gyro_noise_density, 0.001);
  EXPECT_DOUBLE_EQ(c.noise.imu.gyro_random_walk, 0.0001);
  EXPECT_DOUBLE_EQ(c.noise.imu.gyro_bias_init, 0.002);
  EXPECT_DOUBLE_EQ(c.noise.imu.accel_noise_density, 0.01);
  EXPECT_DOUBLE_EQ(c.noise.imu.accel_random_walk, 0.001);
  EXPECT_DOUBLE_EQ(c.noise.imu.accel_bias_init, 0.03);
  EXPECT_DOUBLE_EQ(c.noise.imu.gyro_quantization, 0.0002);
  EXPECT_DOUBLE_EQ(c.noise.imu.accel_quantization, 0.002);
  EXPECT_DOUBLE_EQ(c.noise.imu.time_offset, -0.004);
  ASSERT_EQ(c.faults.size(), 1u);
  EXPECT_EQ(c.faults[0].robot, "follower_1");
  EXPECT_DOUBLE_EQ(c.faults[0].faults.laser_dropout, 0.1);
  EXPECT_DOUBLE_EQ(c.faults[0].faults.sensor_latency, 0.05);
  EXPECT_DOUBLE_EQ(c.faults[0].faults.sensor_jitter, 0.01);
  EXPECT_DOUBLE_EQ(c.faults[0].faults.odom_drift, 0.02);
  EXPECT_FALSE(c.faults[0].faults.drive_frozen);
  EXPECT_TRUE(c.faults[0].faults.silenced);
}

TEST(WorldFile, DefaultsWhenOptionalKeysAreMissingOrEmpty)
{
  for (const std::string file : {"valid_minimal.world.yaml", "valid_empty_sections.world.yaml"})
  {
    const WorldConfig c = mbot_common::loadWorldConfig(kWorlds + "/" + file);
    EXPECT_DOUBLE_EQ(c.physics_step, 0.01) << file;
    EXPECT_DOUBLE_EQ(c.real_time_factor, 1.0) << file;
    EXPECT_EQ(c.seed, 0u) << file;
    EXPECT_TRUE(c.robots.empty() && c.obstacles.empty() && c.moving_obstacles.empty() && c.faults.empty()) << file;
    EXPECT_DOUBLE_EQ(c.noise.laser_range, 0.0) << file;
    EXPECT_DOUBLE_EQ(c.noise.imu.rate, 200.0) << file;  // the consumer MEMS defaults
    EXPECT_DOUBLE_EQ(c.noise.imu.gyro_noise_density, 2.6e-4) << file;
  }
  const WorldConfig three = mbot_common::loadWorldConfig(kWorlds + "/valid_three_robots.world.yaml");
  ASSERT_EQ(three.robots.size(), 3u);
  EXPECT_EQ(three.robots[2].name, "robot_2");
  EXPECT_DOUBLE_EQ(three.robots[2].pose.x, 6.0);
  EXPECT_DOUBLE_EQ(three.real_time_factor, 5.0);
}

TEST(WorldFile, EachInvalidFixtureGivesItsMessage)
{
  const auto cases = mbot_common_test::invalidFixtures(kWorlds, ".world.yaml");
  EXPECT_GE(cases.size(), 40u);
  for (const auto& c : cases)
  {
    ASSERT_FALSE(c.expected.empty()) << c.path << ": no '# expect: ' first line";
    std::string message;
    try
    {
      mbot_common::loadWorldConfig(c.path);
    }
    catch (const WorldConfigError& e)
    {
      message = e.what();
    }
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "fixture " << c.path << "\n  got:      " << message << "\n  expected: " << c.expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
}

TEST(WorldFile, NamesAndFaultRanges)
{
  EXPECT_EQ(mbot_common::checkName("fleet/robot_3"), "");
  for (const std::string bad : {"", "3robot", "/robot", "robot/", "a//b", "robot-1", "robot 1"})
    EXPECT_NE(mbot_common::checkName(bad), "") << bad;
  mbot_common::FaultConfig f;
  EXPECT_EQ(mbot_common::checkFaults(f), "");
  f.sensor_jitter = 10.5;
  EXPECT_EQ(mbot_common::checkFaults(f), "sensor_jitter: expected a standard deviation in [0, 10] s, got 10.5");
}

TEST(WorldFile, LidarAndHeights)
{
  const WorldConfig c = mbot_common::loadWorldConfig(kWorlds + "/valid_lidar.world.yaml");
  EXPECT_EQ(c.wall_height, 3.0);
  ASSERT_EQ(c.robots.size(), 3u);
  const mbot_common::LidarConfig& l = c.robots[0].lidar;
  EXPECT_TRUE(l.enabled);
  EXPECT_EQ(l.rate, 20.0);
  EXPECT_EQ(l.points_per_frame, 1000);
  EXPECT_EQ(l.min_elevation, -10.0);
  EXPECT_EQ(l.max_elevation, 45.0);
  EXPECT_EQ(l.range_min, 0.2);
  EXPECT_EQ(l.range_max, 30.0);
  EXPECT_EQ(l.range_noise, 0.01);
  EXPECT_EQ(l.range_quantization, 0.002);
  const mbot_common::LidarConfig defaults;
  EXPECT_TRUE(c.robots[1].lidar.enabled);  // lidar: true: the Mid-360 defaults
  EXPECT_EQ(c.robots[1].lidar.points_per_frame, defaults.points_per_frame);
  EXPECT_EQ(c.robots[1].lidar.range_noise, defaults.range_noise);
  EXPECT_FALSE(c.robots[2].lidar.enabled);
  EXPECT_EQ(c.obstacles.at(0).height, 0.3);
  EXPECT_EQ(c.moving_obstacles.at(0).height, 1.8);
  const WorldConfig m = mbot_common::loadWorldConfig(kWorlds + "/valid_minimal.world.yaml");
  EXPECT_EQ(m.wall_height, 2.5);
}
