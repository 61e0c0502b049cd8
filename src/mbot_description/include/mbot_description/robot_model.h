/**
 * @file robot_model.h
 * @brief One source of truth for a robot's geometry and limits, read from its URDF and its model
 *        settings file. Used by the simulator and the navigation; free of ROS types.
 *
 * Geometry (footprint, wheels, laser mount) comes from `urdf/<model>.urdf` via urdfdom;
 * limits and sensor settings come from `config/<model>.yaml`.
 */
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

namespace mbot_description
{
/// @brief Raised for a missing or invalid URDF or model settings file; the message names the
///        file, the key and what was expected.
class ModelError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

enum class DriveType
{
  DIFF,  ///< differential drive: linear.x and angular.z
  OMNI   ///< holonomic (mecanum): linear.x, linear.y and angular.z
};

/// @brief A point in the robot's base_footprint frame [m].
struct Point2
{
  double x = 0.0;
  double y = 0.0;
};

/// @brief Planar laser settings (model settings file) and mount (URDF).
struct LaserSpec
{
  int beams = 360;                       ///< number of beams
  double min_angle = -3.14159265358979;  ///< first beam [rad]
  double max_angle = 3.14159265358979;   ///< last beam [rad]; for a full circle the beams are
                                         ///< spaced 2*pi/beams and the last is not a repeat
  double range_min = 0.12;               ///< [m]
  double range_max = 8.0;                ///< [m]
  double rate = 10.0;                    ///< [Hz]
  double mount_x = 0.0;                  ///< laser origin in base_footprint [m]
  double mount_y = 0.0;                  ///< [m]
  double mount_z = 0.0;                  ///< [m]
  double mount_yaw = 0.0;                ///< [rad]

  /// @brief Angle between neighbouring beams [rad]: 2*pi/beams for a full circle (the last beam
  ///        is not a repeat of the first), else (max_angle - min_angle) / (beams - 1).
  double angleIncrement() const
  {
    const double span = max_angle - min_angle;
    const double two_pi = 6.283185307179586;
    if (beams < 2) return 0.0;
    if (span >= two_pi - 1e-9) return span / beams;
    return span / (beams - 1);
  }
};

/// @brief 3D lidar mount (URDF link `lidar_link`, optional): a level frame in base_footprint.
struct LidarMount
{
  bool present = false;  ///< the URDF has a lidar_link
  double x = 0.0;        ///< [m]
  double y = 0.0;        ///< [m]
  double z = 0.0;        ///< [m] above the ground
  double yaw = 0.0;      ///< [rad]
};

/// @brief Velocity and acceleration limits, named as dwa_local_planner names them.
struct Limits
{
  double max_vel_x = 0.5;      ///< [m/s]
  double min_vel_x = -0.2;     ///< [m/s] (negative: may back up)
  double max_vel_y = 0.0;      ///< [m/s] (0 for a diff-drive robot)
  double max_vel_theta = 2.0;  ///< [rad/s]
  double acc_lim_x = 1.0;      ///< [m/s^2]
  double acc_lim_y = 0.0;      ///< [m/s^2]
  double acc_lim_theta = 3.0;  ///< [rad/s^2]
};

/// @brief A wheel's joint as the URDF places it: the child link turns about `axis` (in the joint
///        frame) at `origin` in the parent link. The simulator publishes parent -> child on /tf.
struct WheelJointFrame
{
  std::string parent;                         ///< unprefixed parent link (base_link)
  std::string child;                          ///< unprefixed wheel link
  double origin_xyz[3] = {0.0, 0.0, 0.0};     ///< [m]
  double origin_q[4] = {0.0, 0.0, 0.0, 1.0};  ///< rotation x, y, z, w
  double axis[3] = {0.0, 1.0, 0.0};           ///< unit vector
};

/// @brief IMU mount (URDF link `imu_link`, optional): its pose in base_footprint.
struct ImuMount
{
  bool present = false;                ///< the URDF has an imu_link
  double xyz[3] = {0.0, 0.0, 0.0};     ///< [m]
  double q[4] = {0.0, 0.0, 0.0, 1.0};  ///< rotation x, y, z, w (imu_link in base_footprint)
};

/// @brief Everything the simulator and the navigation need to know about one robot model.
struct RobotModel
{
  std::string name;  ///< "mbot" or "mbot_omni"
  DriveType drive = DriveType::DIFF;
  double footprint_radius = 0.0;              ///< radius of the circle around the footprint [m]
  std::vector<Point2> footprint;              ///< footprint polygon in base_footprint, counter-clockwise [m]
  double mass = 0.0;                          ///< total mass [kg] (sum of URDF link masses)
  double wheel_radius = 0.0;                  ///< [m]
  double wheel_separation = 0.0;              ///< distance between left and right wheels [m]
  double wheel_base = 0.0;                    ///< distance between front and rear wheels [m] (0: one axle)
  std::vector<std::string> wheel_joints;      ///< unprefixed URDF joint names of the driven wheels
  std::vector<WheelJointFrame> wheel_frames;  ///< the same joints' frames, in the same order
  LaserSpec laser;
  ImuMount imu;
  Limits limits;
  double odom_rate = 50.0;          ///< [Hz]
  double ground_truth_rate = 50.0;  ///< [Hz]
  LidarMount lidar;
  double height = 0.0;  ///< top of the highest collision geometry above the ground [m]
};

/// @brief Load `<description_dir>/urdf/<model>.urdf` and `<description_dir>/config/<model>.yaml`.
/// @param description_dir the mbot_description package directory
/// @throws ModelError naming the file, key and problem
RobotModel loadRobotModel(const std::string& description_dir, const std::string& model);

/// @brief Load a model from explicit URDF and settings file paths (tests use this).
RobotModel loadRobotModelFiles(const std::string& urdf_path, const std::string& config_path);

}  // namespace mbot_description
