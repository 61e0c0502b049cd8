/**
 * @file bodies.h
 * @brief (private to the world) What the simulated world is made of: the ODE handles, a body's
 *        tag and outline, and the state of a robot, a static obstacle and a moving obstacle.
 *        The other parts of the world (drive, odometry, contacts, moving obstacles, sensors)
 *        work on these structs; World (world.cpp) owns them.
 */
#pragma once

#include "imu.h"
#include "mbot_sim/raycast.h"
#include "mbot_sim/world.h"

#include <ode/ode.h>

#include <cstdint>
#include <deque>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <vector>

namespace mbot_sim
{
namespace detail
{
constexpr double kInf = std::numeric_limits<double>::infinity();
// Every body is an upright 1 m tall prism centred 0.5 m above the ground, so contact normals
// between bodies are horizontal.
constexpr double kBodyZ = 0.5;         // [m]
constexpr double kBodyHeight = 1.0;    // [m]
constexpr int kMaxContacts = 4;        // contact points per pair of geoms
constexpr double kTimeEpsilon = 1e-9;  // [s] sensor timers: "due" despite rounding

// Collision categories: robots collide with everything, walls and moving obstacles only with
// robots, so ODE skips the other pairs before any geometry test.
constexpr unsigned long kWallBit = 1;
constexpr unsigned long kRobotBit = 2;
constexpr unsigned long kMovingBit = 4;

// ---- ODE handles that free what they hold ----------------------------------------------------
struct WorldDeleter
{
  void operator()(dxWorld* w) const { dWorldDestroy(w); }
};
struct SpaceDeleter
{
  void operator()(dxSpace* s) const { dSpaceDestroy(s); }
};
struct GeomDeleter
{
  void operator()(dxGeom* g) const { dGeomDestroy(g); }
};
struct BodyDeleter
{
  void operator()(dxBody* b) const { dBodyDestroy(b); }
};
struct JointGroupDeleter
{
  void operator()(dxJointGroup* g) const { dJointGroupDestroy(g); }
};
using WorldPtr = std::unique_ptr<dxWorld, WorldDeleter>;
using SpacePtr = std::unique_ptr<dxSpace, SpaceDeleter>;
using GeomPtr = std::unique_ptr<dxGeom, GeomDeleter>;
using BodyPtr = std::unique_ptr<dxBody, BodyDeleter>;
using JointGroupPtr = std::unique_ptr<dxJointGroup, JointGroupDeleter>;

/// What a geom belongs to; ODE geoms point at it (dGeomSetData).
struct BodyTag
{
  enum class Kind
  {
    WALL,
    OBSTACLE,
    MOVING,
    ROBOT
  };
  Kind kind = Kind::WALL;
  uint32_t uid = 0;  ///< unique per body while the world lives; keys contact pairs
  std::string name;  ///< robot or obstacle name, "map" for the walls
  int robot = -1;    ///< robot id for robots

  std::string describe() const;  ///< "a wall", "robot robot_0", ... for error messages
};

/// A body's outline in the plane, relative to its own frame: a circle or a rectangle, maybe
/// off-centre. The laser sees exactly this; the ODE geom is this grown by the contact margin.
struct Outline
{
  bool is_box = false;
  double radius = 0.0;       ///< circle [m]
  double half_length = 0.0;  ///< box, along its x [m]
  double half_width = 0.0;   ///< box, along its y [m]
  double offset_x = 0.0;     ///< centre in the body frame [m]
  double offset_y = 0.0;
  double offset_yaw = 0.0;  ///< box orientation in the body frame [rad]
};

Outline outlineOf(const ShapeConfig& shape);
/// A robot's outline from its footprint polygon: a rectangle when the polygon is one (a box
/// body), else the smallest circle around the polygon's vertices centred on their mean.
Outline outlineOf(const mbot_description::RobotModel& model);
/// The radius [m] of the circle around an outline's centre that holds all of it.
double reachOf(const Outline& o);
/// The outline's centre and heading in the map frame for a body at `pose`.
Pose2D outlinePose(const Outline& o, const Pose2D& pose);
/// An ODE geom for an outline grown by `margin` [m] (not in any space, no body). Round robots
/// are spheres, round obstacles cylinders (see bodies.cpp).
GeomPtr makeGeom(const Outline& o, double margin, bool robot);
void setGeomPose(dGeomID geom, double x, double y, double yaw);

/// A delayed sample (latency fault): handed to the listener at `release` [s sim time].
template <class Sample>
struct Pending
{
  double release = 0.0;
  Sample sample;
};

struct Robot
{
  int id = -1;
  BodyTag tag;
  mbot_description::RobotModel model;
  Pose2D start;
  Outline outline;
  BodyPtr body;
  GeomPtr geom;

  // drive
  Twist2D command;              ///< last command, clamped to the limits
  double command_time = -kInf;  ///< [s] when it came
  Twist2D setpoint;             ///< what the motors drive now (acceleration-limited)

  // true state after the last step
  Pose2D pose;
  Twist2D velocity;     ///< robot frame
  bool at_rest = true;  ///< the drive stands still and nothing pushes it (settleRobot)

  // odometry
  Pose2D odom;
  Twist2D odom_twist;
  std::vector<Point2D> wheel_mounts;  ///< wheel contact points in the robot frame [m]
  JointStateSample joints;

  FaultConfig faults;
  std::mt19937 rng;
  std::normal_distribution<double> gauss{0.0, 1.0};
  std::uniform_real_distribution<double> uniform{0.0, 1.0};

  // sensor timers [s sim time]
  double next_odom = 0.0, next_ground_truth = 0.0, next_scan = 0.0;
  double odom_period = 0.02, ground_truth_period = 0.02, scan_period = 0.1;
  ScanSpec scan_spec;  ///< beam layout; the pose is filled in per scan
  ScanSample scan;

  // samples held back by a latency fault, in release order
  std::deque<Pending<OdometrySample>> pending_odom;
  std::deque<Pending<JointStateSample>> pending_joints;
  std::deque<Pending<ScanSample>> pending_scans;
  double last_release = 0.0;

  // 3D lidar (none unless the world file asks): its pose at the end of the last step, to
  // interpolate each point's pose; frames held back by a latency fault
  std::unique_ptr<LidarScanner> lidar;
  std::mt19937 lidar_rng;         ///< its own noise stream: other sensors' draws do not depend on it
  double lidar_last_time = -1.0;  ///< [s] -1: no motion to interpolate (start, teleport)
  Pose2D lidar_last_pose;
  std::deque<Pending<LidarFrame>> pending_clouds;

  ImuState imu;  ///< its own timer, random stream and latency queue (imu.h)
};

struct Obstacle
{
  BodyTag tag;
  ShapeConfig shape;
  Outline outline;
  Pose2D pose;
  GeomPtr geom;
  double height = 1.0;  ///< [m] for the 3D lidar
};

/// A kinematic obstacle on a closed route (loop: back to the first waypoint; ping_pong: the
/// waypoints back again). A blind one (yielding 0) is where its speed has carried it along the
/// route (moveTo); a walker (yielding > 0) walks from waypoint to waypoint and gives way
/// (planWalk, moving_obstacles.cpp).
struct Mover
{
  BodyTag tag;
  MovingObstacleConfig config;
  Outline outline;
  BodyPtr body;
  GeomPtr geom;
  std::vector<Point2D> route;      ///< closed: route.back() == route.front()
  std::vector<double> cumulative;  ///< path length at each route point [m]
  double start_time = 0.0;         ///< [s] when it left the first waypoint
  size_t segment = 0;              ///< cached: the route segment it is on
  Pose2D pose;
  double vx = 0.0, vy = 0.0;  ///< [m/s] map frame
  // walker only
  size_t next = 1;          ///< the route point it walks to
  double reach = 0.0;       ///< [m] radius of the circle around its outline
  GeomPtr probe;            ///< its outline in no space, to test a next position against walls
  double side = 1.0;        ///< +1: passes bodies on its right, -1: on its left
  double stuck_time = 0.0;  ///< [s] how long it has made no headway

  bool walker() const { return config.yielding > 0.0; }

  /// Pose at sim time t (a blind mover; moving_obstacles.cpp).
  void moveTo(double t);
};

}  // namespace detail
}  // namespace mbot_sim
