/**
 * @file world_file.h
 * @brief A world file (mbot_sim/WORLD_FORMAT.md) as plain structs, and its strict reader, which
 *        also loads the world's map. Free of ROS types; the Python twin is mbot_common.world and
 *        both pass the fixtures in test/fixtures/worlds with the same messages. Poses are
 *        Pose2D {x [m], y [m], theta [rad]} in the map frame.
 */
#pragma once

#include <string>
#include <vector>

#include "mbot_common/geometry.h"
#include "mbot_common/map_io.h"
#include "mbot_common/strict_yaml.h"

namespace mbot_common
{
/// @brief Raised for an invalid world file: `<file>: <key>: expected ..., got ...`.
class WorldConfigError : public ConfigError
{
public:
  using ConfigError::ConfigError;
};

/// @brief Shape of an obstacle: an upright box (length along its own x, width along y) or an
///        upright cylinder.
struct ShapeConfig
{
  enum class Type
  {
    BOX,
    CYLINDER
  };
  Type type = Type::BOX;
  double length = 0.0;  ///< box size along its x [m]
  double width = 0.0;   ///< box size along its y [m]
  double radius = 0.0;  ///< cylinder radius [m]
};

/// @brief A robot's 3D lidar (world file `robots[i].lidar`; a Livox Mid-360-like model in the
///        simulator). Angles in degrees as on a datasheet.
struct LidarConfig
{
  bool enabled = false;               ///< the robot has a lidar (`lidar: true` or a map of the keys)
  double rate = 10.0;                 ///< frames per second [Hz]
  int points_per_frame = 20000;       ///< pattern points per frame
  double min_elevation = -7.0;        ///< [deg]
  double max_elevation = 52.0;        ///< [deg]
  double range_min = 0.1;             ///< [m]
  double range_max = 40.0;            ///< [m]
  double range_noise = 0.02;          ///< [m] Gaussian standard deviation per point
  double range_quantization = 0.001;  ///< [m] ranges are multiples of this (0: exact)
};

/// @brief One robot of the world file.
struct RobotConfig
{
  std::string name;            ///< namespace and frame prefix
  std::string model = "mbot";  ///< mbot_description model name
  Pose2D pose;                 ///< start pose in the map frame
  std::string key;             ///< where it came from in the file, e.g. "robots[1]" (for messages)
  LidarConfig lidar;           ///< off unless the file asks for it
};

/// @brief A static box or cylinder besides the map walls.
struct ObstacleConfig
{
  std::string name;  ///< unique; "obstacle_<i>" when the file gives none
  ShapeConfig shape;
  Pose2D pose;
  std::string key;
  double height = 1.0;  ///< [m] how tall the 3D lidar sees it
};

/// @brief A kinematic body that follows waypoints (people, carts); robots cannot push it. A
///        yielding one (yielding > 0) walks like a person: it slows and steps around robots and
///        other moving obstacles that come within personal_radius, and never walks into them.
struct MovingObstacleConfig
{
  enum class Mode
  {
    LOOP,      ///< after the last waypoint, back to the first
    PING_PONG  ///< after the last waypoint, back along the same path
  };
  std::string name;  ///< unique; "moving_obstacle_<i>" when the file gives none
  ShapeConfig shape;
  std::vector<Point2D> waypoints;  ///< [m]; the first one is the start (at least 2)
  double speed = 0.5;              ///< [m/s]
  Mode mode = Mode::LOOP;
  double yielding = 1.0;         ///< [0, 1] how much it gives way; 0: a blind waypoint follower
  double personal_radius = 0.8;  ///< [m] it reacts to bodies this close to its outline
  std::string key;
  double height = 1.7;  ///< [m] how tall the 3D lidar sees it (a person)
};

/// @brief Every robot's IMU and its errors, per axis, as Allan variance describes them (the
///        world file's noise.imu). Defaults: a consumer MEMS IMU of the order of the TDK
///        InvenSense ICM-20948 datasheet (noise densities, +-250 deg/s and +-2 g 16-bit steps);
///        its random walks and bias spread are typical values, not datasheet figures.
struct ImuNoiseConfig
{
  double rate = 200.0;                  ///< [Hz sim time]
  double gyro_noise_density = 2.6e-4;   ///< white noise [rad/s/sqrt(Hz)]
  double gyro_random_walk = 2.0e-5;     ///< bias random walk [rad/s^2/sqrt(Hz)]
  double gyro_bias_init = 5.0e-3;       ///< std of the start bias [rad/s] (bias instability)
  double accel_noise_density = 2.3e-3;  ///< white noise [m/s^2/sqrt(Hz)]
  double accel_random_walk = 4.0e-4;    ///< bias random walk [m/s^3/sqrt(Hz)]
  double accel_bias_init = 0.05;        ///< std of the start bias [m/s^2]
  double gyro_quantization = 1.33e-4;   ///< output step [rad/s] (0: none)
  double accel_quantization = 6.0e-4;   ///< output step [m/s^2] (0: none)
  double time_offset = 0.0;             ///< stamp minus the true measurement time [s], in [-1, 1]
};

/// @brief Gaussian standard deviations of sensor noise (0 = none), and the IMU's error model.
struct NoiseConfig
{
  double laser_range = 0.0;   ///< [m] per beam
  double odom_linear = 0.0;   ///< [m/s] on the measured linear velocity
  double odom_angular = 0.0;  ///< [rad/s] on the measured angular velocity
  ImuNoiseConfig imu;         ///< fixed at start (not live-tunable)
};

/// @brief Faults of one robot (the fields of mbot_msgs/SetFault).
struct FaultConfig
{
  double laser_dropout = 0.0;   ///< probability [0, 1] that a beam returns NaN (REP-117: invalid)
  double sensor_latency = 0.0;  ///< added delay of odom (and its tf), scan and joint states [s];
                                ///< ground truth is an oracle and is never delayed
  double sensor_jitter = 0.0;   ///< standard deviation of an extra random delay [s]
  double odom_drift = 0.0;      ///< odometry heading drift [rad/s]
  bool drive_frozen = false;    ///< motors fail: the robot ignores cmd_vel and stops
  bool silenced = false;        ///< the robot stops publishing odom, scan, joint states and tf
};

/// @brief Faults given in the world file for the robot `robot`.
struct RobotFaultConfig
{
  std::string robot;
  FaultConfig faults;
  std::string key;
};

/// @brief Everything a world file says. Paths are resolved relative to the world file.
struct WorldConfig
{
  std::string file;               ///< the world file as given (for messages)
  std::string map;                ///< the map entry as written in the file
  std::string map_path;           ///< the map_server yaml: `map` relative to the world file's directory
  OccupancyMap map_data;          ///< the loaded map
  double physics_step = 0.01;     ///< [s]
  double real_time_factor = 1.0;  ///< sim seconds per wall second; 0 = as fast as possible
  double wall_height = 2.5;       ///< [m] the map's walls as the 3D lidar sees them
  unsigned seed = 0;              ///< seed of every random draw
  std::vector<RobotConfig> robots;
  std::vector<ObstacleConfig> obstacles;
  std::vector<MovingObstacleConfig> moving_obstacles;
  NoiseConfig noise;
  std::vector<RobotFaultConfig> faults;
};

/// @brief Read a world file strictly (WORLD_FORMAT.md) and load its map. Checks syntax, types,
///        ranges, unique names and that faults name a robot of the file; not the geometry or the
///        robot models (stage_node's World does that).
/// @throws WorldConfigError `<file>: <key>: <problem>`; a map error is `<file>: map: <its message>`
WorldConfig loadWorldConfig(const std::string& path);

/// @brief Check a robot or body name: a ROS graph name segment (letters, digits, _; not starting
///        with a digit). @return an empty string when valid, else what is wrong.
std::string checkName(const std::string& name);

/// @brief Check one robot's faults. @return an empty string when valid, else the problem with
///        the field name, e.g. "laser_dropout: expected a probability in [0, 1], got 1.5".
std::string checkFaults(const FaultConfig& faults);

}  // namespace mbot_common
