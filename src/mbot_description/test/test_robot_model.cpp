// Tests of mbot_robot_model: the numbers it reads from the URDFs and model settings files, and
// the error messages for invalid files (fixtures in test/fixtures/).
#include "mbot_description/robot_model.h"

#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>

using mbot_description::DriveType;
using mbot_description::loadRobotModel;
using mbot_description::loadRobotModelFiles;
using mbot_description::ModelError;
using mbot_description::Point2;
using mbot_description::RobotModel;

namespace
{
const std::string kPackageDir = MBOT_DESCRIPTION_DIR;
const std::string kFixtures = MBOT_FIXTURE_DIR;
constexpr double kPi = 3.14159265358979323846;
constexpr double kEps = 1e-9;

std::string fixture(const std::string& name) { return kFixtures + "/" + name; }

/// Shoelace formula: positive for a counter-clockwise polygon [m^2].
double signedArea(const std::vector<Point2>& polygon)
{
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i)
  {
    const Point2& a = polygon[i];
    const Point2& b = polygon[(i + 1) % polygon.size()];
    twice += a.x * b.y - b.x * a.y;
  }
  return twice / 2.0;
}

/// The ModelError message of `load`, or "" when it does not throw one.
std::string errorOf(const std::function<void()>& load)
{
  try
  {
    load();
  }
  catch (const ModelError& e)
  {
    return e.what();
  }
  return "";
}

/// The ModelError message of loading two fixture files.
std::string fixtureError(const std::string& urdf, const std::string& config)
{
  return errorOf([&] { loadRobotModelFiles(fixture(urdf), fixture(config)); });
}

/// Fails the test unless `message` contains every one of `parts`.
void expectMentions(const std::string& message, const std::vector<std::string>& parts)
{
  ASSERT_FALSE(message.empty()) << "expected a ModelError";
  for (const auto& part : parts)
    EXPECT_NE(message.find(part), std::string::npos) << "\"" << message << "\" does not mention \"" << part << "\"";
}
}  // namespace

// ---- the two robot models of the fleet, against the numbers documented in their URDFs

TEST(RobotModel, MbotMatchesItsUrdf)
{
  const RobotModel m = loadRobotModel(kPackageDir, "mbot");
  EXPECT_EQ(m.name, "mbot");
  EXPECT_EQ(m.drive, DriveType::DIFF);

  // Body: cylinder r = 0.15 m centred on base_footprint, as a 16-gon with vertices on the circle.
  EXPECT_NEAR(m.footprint_radius, 0.15, kEps);
  ASSERT_EQ(m.footprint.size(), 16u);
  for (const Point2& p : m.footprint) EXPECT_NEAR(std::hypot(p.x, p.y), 0.15, kEps);
  EXPECT_NEAR(signedArea(m.footprint), 0.5 * 16 * 0.15 * 0.15 * std::sin(2 * kPi / 16), kEps);

  EXPECT_NEAR(m.wheel_radius, 0.04, kEps);
  EXPECT_NEAR(m.wheel_separation, 0.22, kEps);
  EXPECT_NEAR(m.wheel_base, 0.0, kEps);
  ASSERT_EQ(m.wheel_joints.size(), 2u);
  EXPECT_EQ(m.wheel_joints[0], "left_wheel_joint");
  EXPECT_EQ(m.wheel_joints[1], "right_wheel_joint");
  // The wheels' joint frames as the URDF writes them (the simulator publishes them on /tf).
  ASSERT_EQ(m.wheel_frames.size(), 2u);
  EXPECT_EQ(m.wheel_frames[0].parent, "base_link");
  EXPECT_EQ(m.wheel_frames[0].child, "left_wheel");
  EXPECT_EQ(m.wheel_frames[1].child, "right_wheel");
  EXPECT_NEAR(m.wheel_frames[0].origin_xyz[1], 0.11, kEps);
  EXPECT_NEAR(m.wheel_frames[1].origin_xyz[1], -0.11, kEps);
  EXPECT_NEAR(m.wheel_frames[0].origin_q[3], 1.0, kEps);
  EXPECT_NEAR(m.wheel_frames[0].axis[1], 1.0, kEps);

  EXPECT_NEAR(m.laser.mount_x, 0.05, kEps);
  EXPECT_NEAR(m.laser.mount_y, 0.0, kEps);
  EXPECT_NEAR(m.laser.mount_z, 0.16, kEps);
  EXPECT_NEAR(m.laser.mount_yaw, 0.0, kEps);
  EXPECT_NEAR(m.mass, 2.0 + 2 * 0.1 + 0.05 + 0.15 + 0.265, kEps);
  // the 3D lidar's mount and the robot's height (the top of lidar_link's cylinder)
  EXPECT_TRUE(m.lidar.present);
  EXPECT_NEAR(m.lidar.x, -0.05, kEps);
  EXPECT_NEAR(m.lidar.z, 0.26, kEps);
  EXPECT_NEAR(m.lidar.yaw, 0.0, kEps);
  EXPECT_NEAR(m.height, 0.29, kEps);
  // the IMU's mount: imu_link, off the centre, axes as base_link
  EXPECT_TRUE(m.imu.present);
  EXPECT_NEAR(m.imu.xyz[0], -0.03, kEps);
  EXPECT_NEAR(m.imu.xyz[1], 0.02, kEps);
  EXPECT_NEAR(m.imu.xyz[2], 0.10, kEps);
  EXPECT_NEAR(m.imu.q[3], 1.0, kEps);

  EXPECT_EQ(m.laser.beams, 360);
  EXPECT_NEAR(m.laser.max_angle - m.laser.min_angle, 2 * kPi, 1e-12);
  EXPECT_NEAR(m.laser.angleIncrement(), 2 * kPi / 360, 1e-12);
  EXPECT_DOUBLE_EQ(m.laser.range_min, 0.12);
  EXPECT_DOUBLE_EQ(m.laser.range_max, 8.0);
  EXPECT_DOUBLE_EQ(m.laser.rate, 10.0);
  EXPECT_DOUBLE_EQ(m.odom_rate, 50.0);
  EXPECT_DOUBLE_EQ(m.ground_truth_rate, 50.0);
  EXPECT_DOUBLE_EQ(m.limits.max_vel_y, 0.0);
  EXPECT_GT(m.limits.max_vel_x, 0.0);
}

TEST(RobotModel, MbotOmniMatchesItsUrdf)
{
  const RobotModel m = loadRobotModel(kPackageDir, "mbot_omni");
  EXPECT_EQ(m.name, "mbot_omni");
  EXPECT_EQ(m.drive, DriveType::OMNI);

  // Body: box 0.36 x 0.30 m centred on base_footprint.
  ASSERT_EQ(m.footprint.size(), 4u);
  for (const Point2& p : m.footprint)
  {
    EXPECT_NEAR(std::abs(p.x), 0.18, kEps);
    EXPECT_NEAR(std::abs(p.y), 0.15, kEps);
  }
  EXPECT_NEAR(signedArea(m.footprint), 0.36 * 0.30, kEps);
  EXPECT_NEAR(m.footprint_radius, std::hypot(0.18, 0.15), kEps);

  EXPECT_NEAR(m.wheel_radius, 0.04, kEps);
  EXPECT_NEAR(m.wheel_separation, 0.24, kEps);
  EXPECT_NEAR(m.wheel_base, 0.24, kEps);
  EXPECT_EQ(m.wheel_joints.size(), 4u);
  EXPECT_NEAR(m.laser.mount_x, 0.10, kEps);
  EXPECT_NEAR(m.laser.mount_z, 0.16, kEps);
  EXPECT_NEAR(m.mass, 3.0 + 4 * 0.12 + 0.15 + 0.265, kEps);
  EXPECT_TRUE(m.lidar.present);
  EXPECT_NEAR(m.lidar.x, -0.06, kEps);
  EXPECT_NEAR(m.lidar.z, 0.26, kEps);
  EXPECT_NEAR(m.height, 0.29, kEps);
  EXPECT_TRUE(m.imu.present);
  EXPECT_NEAR(m.imu.xyz[0], 0.05, kEps);
  EXPECT_NEAR(m.imu.xyz[2], 0.09, kEps);
  EXPECT_GT(m.limits.max_vel_y, 0.0);
  EXPECT_GT(m.limits.acc_lim_y, 0.0);
}

// ---- the frame chain is composed (rotated base_link, a laser on a mast)

TEST(RobotModel, ComposesTheJointChain)
{
  const RobotModel m = loadRobotModelFiles(fixture("valid_offset.urdf"), fixture("valid_offset.yaml"));
  EXPECT_EQ(m.name, "offset_bot");

  // Box 0.4 x 0.2 turned +90 deg and shifted 0.1 m forward: x in [0, 0.2], y in [-0.2, 0.2].
  ASSERT_EQ(m.footprint.size(), 4u);
  double min_x = 1e9, max_x = -1e9, min_y = 1e9, max_y = -1e9;
  for (const Point2& p : m.footprint)
  {
    min_x = std::min(min_x, p.x);
    max_x = std::max(max_x, p.x);
    min_y = std::min(min_y, p.y);
    max_y = std::max(max_y, p.y);
  }
  EXPECT_NEAR(min_x, 0.0, kEps);
  EXPECT_NEAR(max_x, 0.2, kEps);
  EXPECT_NEAR(min_y, -0.2, kEps);
  EXPECT_NEAR(max_y, 0.2, kEps);
  EXPECT_NEAR(signedArea(m.footprint), 0.4 * 0.2, kEps);  // positive: counter-clockwise
  EXPECT_NEAR(m.footprint_radius, std::hypot(0.2, 0.2), kEps);

  EXPECT_NEAR(m.wheel_separation, 0.24, kEps);
  EXPECT_NEAR(m.wheel_base, 0.0, kEps);
  EXPECT_NEAR(m.wheel_radius, 0.04, kEps);

  EXPECT_NEAR(m.laser.mount_x, 0.1, kEps);
  EXPECT_NEAR(m.laser.mount_y, 0.05, kEps);
  EXPECT_NEAR(m.laser.mount_z, 0.2, kEps);
  EXPECT_NEAR(m.laser.mount_yaw, kPi / 2 - 0.5, kEps);
  EXPECT_NEAR(m.mass, 1.6, kEps);
  EXPECT_FALSE(m.imu.present);  // no imu_link: no IMU

  // Settings come from the fixture, not from the defaults in robot_model.h.
  EXPECT_DOUBLE_EQ(m.limits.max_vel_x, 0.7);
  EXPECT_DOUBLE_EQ(m.limits.max_vel_theta, 1.25);
  EXPECT_DOUBLE_EQ(m.limits.acc_lim_theta, 4.0);
  EXPECT_EQ(m.laser.beams, 180);
  EXPECT_NEAR(m.laser.angleIncrement(), 3.0 / 179, 1e-12);  // not a full circle: ends included
  EXPECT_DOUBLE_EQ(m.laser.range_max, 4.5);
  EXPECT_DOUBLE_EQ(m.odom_rate, 20.0);
  EXPECT_DOUBLE_EQ(m.ground_truth_rate, 10.0);
}

// ---- each invalid input gives a ModelError that names the file and the key

TEST(RobotModelErrors, MissingFiles)
{
  expectMentions(errorOf([] { loadRobotModel(kPackageDir, "no_such_model"); }),
                 {"config/no_such_model.yaml", "missing"});
  expectMentions(fixtureError("nowhere.urdf", "valid_offset.yaml"), {"nowhere.urdf", "URDF"});
}

TEST(RobotModelErrors, UnknownKey)
{
  expectMentions(fixtureError("valid_offset.urdf", "invalid_unknown_key.yaml"),
                 {"invalid_unknown_key.yaml", "limits.max_speed", "unknown key", "max_vel_x"});
}

TEST(RobotModelErrors, WrongType)
{
  expectMentions(fixtureError("valid_offset.urdf", "invalid_wrong_type.yaml"),
                 {"invalid_wrong_type.yaml", "laser.beams", "expected an integer", "\"many\""});
  expectMentions(fixtureError("valid_offset.urdf", "invalid_quoted_number.yaml"),
                 {"invalid_quoted_number.yaml", "limits.max_vel_x", "expected a number [m/s]", "\"0.7\""});
  expectMentions(fixtureError("valid_offset.urdf", "invalid_drive.yaml"),
                 {"invalid_drive.yaml", "drive", "expected diff or omni", "\"tank\""});
}

TEST(RobotModelErrors, MissingKey)
{
  expectMentions(fixtureError("valid_offset.urdf", "invalid_missing_key.yaml"),
                 {"invalid_missing_key.yaml", "odom_rate", "missing key"});
}

TEST(RobotModelErrors, WheelJointNotInUrdf)
{
  expectMentions(fixtureError("valid_offset.urdf", "invalid_wheel_joint.yaml"),
                 {"invalid_wheel_joint.yaml", "wheel_joints[1]", "wheel_c_joint", "valid_offset.urdf"});
}

TEST(RobotModelErrors, UrdfWithoutBaseLink)
{
  expectMentions(fixtureError("invalid_no_base_link.urdf", "valid_offset.yaml"),
                 {"invalid_no_base_link.urdf", "base_link", "missing"});
}

TEST(RobotModelErrors, NotAUrdf)
{
  expectMentions(fixtureError("invalid_not_xml.urdf", "valid_offset.yaml"),
                 {"invalid_not_xml.urdf", "not a valid URDF"});
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
