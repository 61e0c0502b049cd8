/**
 * @file world.h
 * @brief The simulated world, free of ROS: ODE rigid bodies in the plane (robots, static boxes
 *        and cylinders, kinematic moving obstacles, the map walls as merged boxes), drive
 *        kinematics with limits and a watchdog, contacts, odometry, lasers, noise and faults.
 *
 * One World owns sim time: step() advances it by the fixed physics step. Sensors keep their
 * own update timers in sim time (flatland's UpdateTimer idea): after a step, every sensor that
 * is due measures, and the sample (stamped with the sim time of the measurement) goes to the
 * SensorListener, at once or, with a latency fault, a little later (odometry, joint states and
 * scans; ground truth is an oracle and always comes at once).
 *
 * Use:
 * @code
 *   World world(map, settings);
 *   int id = world.addRobot("robot_0", model, {1.0, 2.0, 0.0});
 *   world.setListener(&my_listener);
 *   world.setCommand(id, {0.3, 0.0, 0.2});
 *   for (int i = 0; i < 1000; ++i) world.step();
 * @endcode
 */
#pragma once

#include "mbot_sim/lidar3d.h"

#include <mbot_common/geometry.h>
#include <mbot_common/map_io.h>
#include <mbot_common/world_file.h>
#include <mbot_description/robot_model.h>

#include <functional>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbot_sim
{
// The plain types of the world are mbot_common's: geometry (Pose2D {x, y, theta}, Twist2D
// {vx, vy, wz}), the map (map_io.h) and the world file's structs and reader (world_file.h).
using mbot_common::checkFaults;
using mbot_common::checkName;
using mbot_common::FaultConfig;
using mbot_common::ImuNoiseConfig;
using mbot_common::LidarConfig;
using mbot_common::loadMap;
using mbot_common::loadWorldConfig;
using mbot_common::MapError;
using mbot_common::MovingObstacleConfig;
using mbot_common::NoiseConfig;
using mbot_common::ObstacleConfig;
using mbot_common::OccupancyMap;
using mbot_common::Point2D;
using mbot_common::Pose2D;
using mbot_common::RobotConfig;
using mbot_common::RobotFaultConfig;
using mbot_common::ShapeConfig;
using mbot_common::Twist2D;
using mbot_common::WorldConfig;
using mbot_common::WorldConfigError;

/// @brief Raised by run-time requests that cannot be done (unknown robot, pose inside a wall,
///        duplicate name...); the message says why. The world is unchanged when it is raised.
class SimError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// @brief Odometry: the pose in the robot's odom frame (identity at start and after a reset),
///        integrated from the measured wheel motion, and the measured velocity in the robot frame
///        (exactly zero, without noise, while the robot is at rest; an odom_drift fault still turns).
struct OdometrySample
{
  double stamp = 0.0;  ///< sim time of the measurement [s]
  Pose2D pose;
  Twist2D twist;
};

/// @brief The true pose in the map frame and the true velocity in the robot frame (exactly zero
///        while the robot is at rest: its drive stands still and nothing pushes it).
struct GroundTruthSample
{
  double stamp = 0.0;  ///< [s]
  Pose2D pose;
  Twist2D twist;
};

/// @brief Wheel joint angles, in the order of RobotModel::wheel_joints.
struct JointStateSample
{
  double stamp = 0.0;            ///< [s]
  std::vector<double> position;  ///< [rad]
  std::vector<double> velocity;  ///< [rad/s]
};

/// @brief One laser scan; beam i is at angle min_angle + i * angleIncrement() in the laser frame.
struct ScanSample
{
  double stamp = 0.0;         ///< [s]
  std::vector<float> ranges;  ///< [m]; +Inf: no return within range_max, -Inf: closer than range_min,
                              ///< NaN: no measurement (laser_dropout)
};

/// @brief One IMU sample in the robot's imu_link frame (REP-145: a raw gyro and accelerometer).
struct ImuSample
{
  double stamp = 0.0;                               ///< measurement sim time + noise.imu.time_offset [s]
  double angular_velocity[3] = {0.0, 0.0, 0.0};     ///< [rad/s] with bias, noise, quantization
  double linear_acceleration[3] = {0.0, 0.0, 0.0};  ///< specific force [m/s^2]: +g on z at rest
};

/// @brief Two bodies started touching.
struct ContactEvent
{
  double stamp = 0.0;  ///< sim time of the first step in which they touched [s]
  std::string body_a;  ///< robot or obstacle name, or "map" for the walls
  std::string body_b;
  double x = 0.0;  ///< a contact point in the map frame [m]
  double y = 0.0;
};

/// @brief An obstacle's shape and current pose (for markers).
struct ObstacleState
{
  std::string name;
  ShapeConfig shape;
  Pose2D pose;
  bool moving = false;
};

/// @brief Receives what the sensors measure and the contacts. World::step() calls these; a
///        listener may call World::setCommand() from them, but must not add or remove robots.
class SensorListener
{
public:
  virtual ~SensorListener() = default;
  virtual void onOdometry(int /*robot*/, const OdometrySample& /*sample*/) {}
  virtual void onGroundTruth(int /*robot*/, const GroundTruthSample& /*sample*/) {}
  virtual void onJointState(int /*robot*/, const JointStateSample& /*sample*/) {}
  virtual void onScan(int /*robot*/, const ScanSample& /*sample*/) {}
  /// @brief Asked every step for each robot with an IMU: false and its IMU does not measure
  ///        (nobody listens; its bias still walks), so fleets without IMU users pay nothing.
  virtual bool wantsImu(int /*robot*/) const { return true; }
  virtual void onImu(int /*robot*/, const ImuSample& /*sample*/) {}
  /// @brief Asked every step for each robot with a 3D lidar: false and its lidar does not cast
  ///        (nobody listens), so robots whose points nobody reads cost nothing.
  virtual bool wantsPoints(int /*robot*/) const { return true; }
  /// @brief A finished 3D lidar frame (lidar3d.h): points in the lidar frame, each with its time
  ///        after the stamp (the sim time of the frame's first pattern point).
  virtual void onPointCloud(int /*robot*/, const LidarFrame& /*frame*/) {}
  virtual void onContact(const ContactEvent& /*event*/) {}
};

/// @brief Settings of a World that do not come from the bodies.
struct WorldSettings
{
  double physics_step = 0.01;     ///< [s]
  unsigned seed = 0;              ///< robot i draws its noise from std::mt19937(seed + i)
  NoiseConfig noise;              ///< sensor noise of every robot
  double watchdog_timeout = 0.2;  ///< [s] a robot with no command for this long stops
  /// [m] robots collide this much before their footprints touch, so that a footprint never
  /// enters a wall even in the step in which a contact begins (a fast robot moves 5 mm a step).
  double contact_margin = 0.01;
  /// [s] a pair of bodies counts as separated (and a new touch is reported again) only after
  /// it has not touched for this long; stops flicker when a robot rests against a wall.
  double contact_release = 0.05;
  double wall_height = 2.5;  ///< [m] the map's walls as the 3D lidars see them
};

/// @brief The simulation. Robots are addressed by an id (stable while the robot exists; a
///        removed robot's id is not reused) or by name.
class World
{
public:
  /// @param map the static walls: occupied cells (100) are merged into few rectangles
  /// @throws SimError for a rotated map (origin yaw != 0) or a bad setting
  World(const OccupancyMap& map, const WorldSettings& settings);
  ~World();
  World(const World&) = delete;
  World& operator=(const World&) = delete;

  // ---- bodies ------------------------------------------------------------------------------
  /// @brief Add a robot at `pose` (map frame). Its start pose (for reset) is `pose`.
  /// @throws SimError: duplicate name, invalid name, pose outside the map, overlapping a wall,
  ///         an obstacle or a robot
  int addRobot(const std::string& name, const mbot_description::RobotModel& model, const Pose2D& pose);
  /// @throws SimError: unknown robot
  void removeRobot(const std::string& name);
  /// @brief Add a static box or cylinder, at start or at run time: the laser sees it from the
  ///        next scan on, robots collide with it from the next step on (contacts name it).
  ///        It may touch walls and other obstacles, but no robot.
  /// @throws SimError: duplicate or invalid name, a size <= 0 or NaN, a pose that is not
  ///         finite, a centre outside the map, overlapping a robot
  void addObstacle(const ObstacleConfig& obstacle);
  /// @brief Remove a static obstacle (from the world file or added later); its name is free again.
  /// @throws SimError: unknown obstacle, or the name of a robot, a moving obstacle or the walls
  void removeObstacle(const std::string& name);
  /// @throws SimError: duplicate name, fewer than 2 waypoints, speed <= 0
  void addMovingObstacle(const MovingObstacleConfig& obstacle);

  // ---- run-time requests -------------------------------------------------------------------
  /// @brief The velocity the robot should drive (clamped to its limits, reached within its
  ///        acceleration limits); it stops when no command comes for watchdog_timeout.
  void setCommand(int robot, const Twist2D& command);
  /// @brief Move a robot to `pose` at once, at rest. Its odometry is not changed (a kidnapping:
  ///        the wheels did not turn), or with `odometry_follows` it moves with the robot: the
  ///        odom frame stays where it is in the map, as stage_ros's cmd_pose does with Stage's
  ///        default localization ("gps": odometry = the true pose).
  /// @throws SimError: unknown robot, pose outside the map or overlapping another body
  void teleport(const std::string& name, const Pose2D& pose, bool odometry_follows = false);
  /// @brief Replace all faults of a robot (a default FaultConfig clears them).
  /// @throws SimError: unknown robot, a value out of range
  void setFaults(const std::string& name, const FaultConfig& faults);
  /// @brief Replace the sensor noise of every robot (live tuning); in force from the next step.
  ///        Each robot keeps drawing from its own random stream. noise.imu is not changed (the
  ///        IMU error model is fixed when the robots are made).
  /// @throws SimError: a value that is negative or not finite (the noise is then unchanged)
  void setNoise(const NoiseConfig& noise);
  /// @brief Every robot back to its start pose at rest with its odometry at identity; moving
  ///        obstacles back to their first waypoint. Samples still held back by a latency fault
  ///        are dropped (they were measured before the reset). Sim time goes on.
  void resetPositions();

  // ---- time --------------------------------------------------------------------------------
  /// @brief The listener of sensor samples and contacts (not owned; nullptr: none).
  void setListener(SensorListener* listener);
  /// @brief Advance sim time by one physics step; then sensors that are due measure.
  void step();
  double time() const;         ///< sim time [s]
  double physicsStep() const;  ///< [s]

  // ---- queries -----------------------------------------------------------------------------
  /// @return the robot's id, or -1 when there is no robot of that name
  int findRobot(const std::string& name) const;
  bool hasRobot(int robot) const;
  std::vector<int> robotIds() const;  ///< in the order they were added
  size_t robotCount() const;
  const std::string& robotName(int robot) const;
  const mbot_description::RobotModel& robotModel(int robot) const;
  Pose2D groundTruth(int robot) const;  ///< true pose in the map frame
  Twist2D velocity(int robot) const;    ///< true velocity in the robot frame (exactly 0 at rest)
  Pose2D odometry(int robot) const;     ///< current odometry pose (odom frame)
  /// @brief At rest: its drive stands still and nothing pushes it (see "true zeros"); a robot
  ///        that brakes or is pushed is not.
  bool atRest(int robot) const;
  const FaultConfig& faults(int robot) const;
  const NoiseConfig& noise() const;  ///< the sensor noise in force
  /// @brief True when a circle of `radius` [m] at (x, y) inside the map overlaps no wall,
  ///        obstacle or robot.
  bool isFree(double x, double y, double radius) const;
  /// @brief Static and moving obstacles with their current poses.
  std::vector<ObstacleState> obstacles() const;
  /// @brief Number of rectangles the map walls were merged into.
  size_t wallBoxCount() const;
  /// @brief Laser beams cast since the world was made.
  unsigned long long raysCast() const;

  // ---- 3D lidar ----------------------------------------------------------------------------
  /// @brief Give a robot a 3D lidar at its model's lidar_link (or take it away: enabled false).
  ///        Its first frame starts at the current sim time.
  /// @throws SimError: unknown robot, a model without lidar_link, a setting out of range
  void setLidar(int robot, const LidarConfig& lidar);
  bool hasLidar(int robot) const;
  /// @brief 3D lidar rays cast since the world was made.
  unsigned long long lidarRaysCast() const;

private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

/// @brief The obstacle a run-time request describes (the fields of mbot_msgs/SpawnObstacle):
///        shape "box" with length and width, or "cylinder" with radius; the other shape's
///        sizes must be 0. World::addObstacle() checks the rest (name, sizes > 0, pose).
/// @throws SimError: a shape other than box or cylinder, a size of the other shape given
ObstacleConfig obstacleFromRequest(const std::string& name, const std::string& shape, double length, double width,
                                   double radius, const Pose2D& pose);

/// @brief Loads a robot model by name (e.g. with mbot_description::loadRobotModel).
using ModelLoader = std::function<mbot_description::RobotModel(const std::string& model)>;

/// @brief Build the world a world file describes: map (config.map_data, loaded by the reader),
///        obstacles, moving obstacles, robots, faults. Geometry errors name the file and the key, e.g.
///        `office.world.yaml: robots[1].pose: robot_1 at (1.00, 2.00) overlaps a wall`.
/// @throws WorldConfigError for a map stage_node cannot use (rotated), an unknown model, a body
///         overlapping another
std::unique_ptr<World> buildWorld(const WorldConfig& config, const ModelLoader& load_model,
                                  double watchdog_timeout = 0.2);

/// @brief The rectangles [cells] that cover exactly the occupied cells of `map` (greedy merge:
///        grow each run of cells to the right, then down while the whole run is occupied).
struct CellRect
{
  unsigned x = 0;  ///< first column
  unsigned y = 0;  ///< first row
  unsigned width = 0;
  unsigned height = 0;
};
std::vector<CellRect> mergeOccupiedCells(const OccupancyMap& map);

}  // namespace mbot_sim
