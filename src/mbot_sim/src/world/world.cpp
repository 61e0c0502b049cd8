/**
 * @file world.cpp
 * @brief World: owns the bodies and sim time, checks run-time requests, and runs a step by
 *        calling the parts (drive.cpp, moving_obstacles.cpp, contacts.cpp, odometry.cpp,
 *        sensors.cpp). See world.h.
 *
 * How a step goes (Impl::step):
 *  1. every robot's drive setpoint approaches its command within the acceleration limits and
 *     becomes the body's velocity (the motors are stiff: the body moves as commanded unless a
 *     contact stops it); moving obstacles get the velocity of their path;
 *  2. collision detection, only where it matters: robot-robot and robot-moving obstacle in one
 *     sweep-and-prune space, each robot against the static quadtree space (walls, obstacles);
 *     static-static and moving-static pairs are never tested;
 *  3. one ODE quick step resolves the contacts; then every robot is put back onto the plane
 *     (z, roll, pitch) - cheaper than a dPlane2D joint per robot;
 *  4. odometry integrates the measured wheel motion; contact pairs that begin are reported;
 *  5. sensors that are due measure and hand their samples to the listener.
 */
#include "mbot_sim/world.h"

#include "bodies.h"
#include "contacts.h"
#include "drive.h"
#include "moving_obstacles.h"
#include "odometry.h"
#include "sensors.h"

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <set>
#include <sstream>
#include <utility>

namespace mbot_sim
{
using mbot_description::RobotModel;
using namespace detail;  // the parts of the world (private headers)

namespace
{
/// ODE is initialised once per World and closed after the last one (ODE counts the calls).
struct OdeLibrary
{
  OdeLibrary()
  {
    dInitODE2(0);
    dAllocateODEDataForThread(dAllocateMaskAll);
  }
  ~OdeLibrary() { dCloseODE(); }
  OdeLibrary(const OdeLibrary&) = delete;
  OdeLibrary& operator=(const OdeLibrary&) = delete;
};

std::string formatPoint(double x, double y)
{
  std::ostringstream out;
  out.setf(std::ios::fixed);
  out.precision(2);
  out << "(" << x << ", " << y << ")";
  return out.str();
}

std::string formatNumber(double v)
{
  std::ostringstream out;
  out << v;
  return out.str();
}

/// The problem with an obstacle's sizes, as the world file reader words it ("" when fine).
std::string checkShapeSizes(const ShapeConfig& shape)
{
  auto positive = [](const std::string& key, double v) {
    return v > 0.0 ? std::string() : key + ": expected a number > 0 [m], got " + formatNumber(v);  // NaN too
  };
  if (shape.type == ShapeConfig::Type::BOX)
  {
    const std::string problem = positive("length", shape.length);
    return problem.empty() ? positive("width", shape.width) : problem;
  }
  return positive("radius", shape.radius);
}

}  // namespace

// =============================================================================================

struct World::Impl
{
  // Declaration order is destruction order reversed: bodies and geoms go before their spaces,
  // and ODE is closed last.
  OdeLibrary ode;
  WorldSettings settings;
  OccupancyMap map_info;  ///< size and origin only (data cleared)
  WorldPtr world;
  SpacePtr static_space;  ///< walls + static obstacles (quadtree: robots query it)
  SpacePtr
      dynamic_space;  ///< robots + moving obstacles (sweep and prune: ~10% faster than a hash space at 1000 robots)
  JointGroupPtr contact_group;
  std::unique_ptr<ContactTracker> contacts;
  Sensors sensors;

  BodyTag wall_tag;
  std::vector<GeomPtr> walls;
  std::vector<std::unique_ptr<Obstacle>> obstacles;
  std::vector<std::unique_ptr<Mover>> movers;
  std::vector<std::unique_ptr<Robot>> robots;  ///< in the order they were added
  std::vector<Robot*> robot_by_id;             ///< nullptr once removed
  std::set<std::string> names{"map"};
  uint32_t next_uid = 1;
  std::vector<BodyCircle> bodies;  ///< for walkers: robots and movers at the start of the step (reused)

  SensorListener* listener = nullptr;
  long long step_count = 0;

  Impl(const OccupancyMap& map, const WorldSettings& s) : settings(s)
  {
    if (!(settings.physics_step > 0.0 && settings.physics_step <= 0.1))
      throw SimError("physics_step: expected a number in (0, 0.1] [s], got " + std::to_string(settings.physics_step));
    const ImuNoiseConfig& imu = settings.noise.imu;
    if (!(imu.rate > 0.0 && imu.rate <= 10000.0))
      throw SimError("noise.imu.rate: expected a number in (0, 10000] [Hz], got " + std::to_string(imu.rate));
    for (double v : {imu.gyro_noise_density, imu.gyro_random_walk, imu.gyro_bias_init, imu.accel_noise_density,
                     imu.accel_random_walk, imu.accel_bias_init, imu.gyro_quantization, imu.accel_quantization})
      if (!(std::isfinite(v) && v >= 0.0))
        throw SimError("noise.imu: expected finite numbers >= 0, got " + std::to_string(v));
    if (!(std::abs(imu.time_offset) <= 1.0))
      throw SimError("noise.imu.time_offset: expected a number in [-1, 1] [s], got " + std::to_string(imu.time_offset));
    if (std::abs(map.origin_yaw) > 1e-9)
      throw SimError("the map's origin yaw is " + std::to_string(map.origin_yaw) +
                     "; stage_node supports only maps with yaw 0");
    map_info = map;
    map_info.data.clear();

    world.reset(dWorldCreate());
    dWorldSetGravity(world.get(), 0, 0, 0);  // planar: nothing falls
    dWorldSetERP(world.get(), 0.2);
    dWorldSetCFM(world.get(), 1e-6);
    dWorldSetContactSurfaceLayer(world.get(), 0.001);  // [m] resting contacts stay in contact
    dWorldSetQuickStepNumIterations(world.get(), 20);

    // Quadtree over the map (a square root block of side `extent`, ODE takes half sizes) with
    // leaves of about 1 m, for robot-vs-static queries.
    const double size_x = map.width * map.resolution, size_y = map.height * map.resolution;
    const double extent = std::max({size_x, size_y, 1.0}) * 1.02;
    const int depth = std::clamp(static_cast<int>(std::ceil(std::log2(extent))) + 1, 3, 8);
    dVector3 center = {map.origin_x + size_x / 2.0, map.origin_y + size_y / 2.0, kBodyZ, 0};
    dVector3 extents = {extent / 2.0, extent / 2.0, kBodyHeight / 2.0, 0};
    static_space.reset(dQuadTreeSpaceCreate(nullptr, center, extents, depth));
    dynamic_space.reset(dSweepAndPruneSpaceCreate(nullptr, dSAP_AXES_XYZ));
    // Spaces do not destroy their geoms: the owners (unique_ptr) do.
    dSpaceSetCleanup(static_space.get(), 0);
    dSpaceSetCleanup(dynamic_space.get(), 0);
    contact_group.reset(dJointGroupCreate(0));
    contacts = std::make_unique<ContactTracker>(world.get(), contact_group.get());

    wall_tag.kind = BodyTag::Kind::WALL;
    wall_tag.uid = 0;
    wall_tag.name = "map";

    std::vector<uint8_t> occupied(map.data.size());
    for (size_t i = 0; i < map.data.size(); ++i) occupied[i] = map.data[i] == 100 ? 1 : 0;
    sensors.setWalls(
        GridRaycaster(std::move(occupied), map.width, map.height, map.resolution, map.origin_x, map.origin_y));
    if (!(settings.wall_height > 0.0) || !std::isfinite(settings.wall_height))
      throw SimError("wall_height: expected a number > 0 [m], got " + std::to_string(settings.wall_height));
    sensors.setWallHeight(settings.wall_height);

    for (const CellRect& r : mergeOccupiedCells(map))
    {
      GeomPtr g(dCreateBox(static_space.get(), r.width * map.resolution, r.height * map.resolution, kBodyHeight));
      dGeomSetPosition(g.get(), map.origin_x + (r.x + r.width / 2.0) * map.resolution,
                       map.origin_y + (r.y + r.height / 2.0) * map.resolution, kBodyZ);
      dGeomSetCategoryBits(g.get(), kWallBit);
      dGeomSetCollideBits(g.get(), kRobotBit);
      dGeomSetData(g.get(), &wall_tag);
      walls.push_back(std::move(g));
    }
  }

  double time() const { return step_count * settings.physics_step; }

  // ---- lookups ---------------------------------------------------------------------------
  Robot* robotByName(const std::string& name) const
  {
    for (const auto& r : robots)
      if (r->tag.name == name) return r.get();
    return nullptr;
  }

  Robot& robotById(int id) const
  {
    if (id < 0 || id >= static_cast<int>(robot_by_id.size()) || !robot_by_id[id])
      throw SimError("no robot with id " + std::to_string(id));
    return *robot_by_id[id];
  }

  Robot& needRobot(const std::string& name) const
  {
    Robot* r = robotByName(name);
    if (!r) throw SimError("unknown robot \"" + name + "\"");
    return *r;
  }

  void claimName(const std::string& name, const std::string& what) const
  {
    const std::string problem = checkName(name);
    if (!problem.empty()) throw SimError(what + " name: " + problem);
    if (names.count(name)) throw SimError("duplicate name \"" + name + "\": a body of that name exists already");
  }

  bool insideMap(double x, double y) const
  {
    return x >= map_info.origin_x && y >= map_info.origin_y &&
           x <= map_info.origin_x + map_info.width * map_info.resolution &&
           y <= map_info.origin_y + map_info.height * map_info.resolution;
  }

  // ---- placement checks ---------------------------------------------------------------------
  /// The first body an outline at `pose` would overlap (nullptr: none).
  const BodyTag* overlapping(const Outline& outline, const Pose2D& pose, const BodyTag* exclude, bool robot) const
  {
    GeomPtr geom = makeGeom(outline, settings.contact_margin, robot);
    const Pose2D p = outlinePose(outline, pose);
    setGeomPose(geom.get(), p.x, p.y, p.theta);
    const double margin = settings.contact_margin;
    const BodyTag* found = firstOverlap(geom.get(), static_space.get(), exclude, margin, margin);
    return found ? found : firstOverlap(geom.get(), dynamic_space.get(), exclude, margin, margin);
  }

  // ---- bodies ------------------------------------------------------------------------------
  int addRobot(const std::string& name, const RobotModel& model, const Pose2D& pose)
  {
    claimName(name, "robot");
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
      throw SimError("robot " + name + ": the pose is not finite");
    if (!insideMap(pose.x, pose.y))
      throw SimError("robot " + name + " at " + formatPoint(pose.x, pose.y) + " is outside the map");
    auto robot = std::make_unique<Robot>();
    robot->model = model;
    robot->outline = outlineOf(model);
    if (robot->outline.is_box ? robot->outline.half_length <= 0.0 : robot->outline.radius <= 0.0)
      throw SimError("robot " + name + ": model " + model.name + " has no footprint");
    if (const BodyTag* other = overlapping(robot->outline, pose, nullptr, true))
      throw SimError("robot " + name + " at " + formatPoint(pose.x, pose.y) + " overlaps " + other->describe());

    const int id = static_cast<int>(robot_by_id.size());
    robot->id = id;
    robot->tag.kind = BodyTag::Kind::ROBOT;
    robot->tag.uid = next_uid++;
    robot->tag.name = name;
    robot->tag.robot = id;
    robot->start = pose;
    robot->pose = pose;
    robot->rng.seed(settings.seed + static_cast<unsigned>(id));

    // Body: mass from the URDF, inertia of an upright cylinder or box.
    robot->body.reset(dBodyCreate(world.get()));
    dBodySetFiniteRotationMode(robot->body.get(), 1);  // exact rotation for a constant turn rate
    dMass mass;
    const double kg = model.mass > 0.0 ? model.mass : 1.0;
    if (robot->outline.is_box)
      dMassSetBoxTotal(&mass, kg, 2.0 * robot->outline.half_length, 2.0 * robot->outline.half_width, kBodyHeight);
    else
      dMassSetCylinderTotal(&mass, kg, 3, robot->outline.radius, kBodyHeight);
    dBodySetMass(robot->body.get(), &mass);
    robot->geom = makeGeom(robot->outline, settings.contact_margin, true);
    dGeomSetBody(robot->geom.get(), robot->body.get());
    if (robot->outline.offset_x != 0.0 || robot->outline.offset_y != 0.0)
      dGeomSetOffsetPosition(robot->geom.get(), robot->outline.offset_x, robot->outline.offset_y, 0.0);
    if (robot->outline.offset_yaw != 0.0)
    {
      dMatrix3 r;
      dRFromAxisAndAngle(r, 0, 0, 1, robot->outline.offset_yaw);
      dGeomSetOffsetRotation(robot->geom.get(), r);
    }
    dGeomSetCategoryBits(robot->geom.get(), kRobotBit);
    dGeomSetCollideBits(robot->geom.get(), kRobotBit | kMovingBit | kWallBit);
    dGeomSetData(robot->geom.get(), &robot->tag);
    dSpaceAdd(dynamic_space.get(), robot->geom.get());
    placeBody(*robot, pose);

    robot->wheel_mounts = wheelMounts(model);
    robot->joints.position.assign(robot->wheel_mounts.size(), 0.0);
    robot->joints.velocity.assign(robot->wheel_mounts.size(), 0.0);

    // Sensor timers: the first measurement one period after the robot appears.
    robot->odom_period = 1.0 / model.odom_rate;
    robot->ground_truth_period = 1.0 / model.ground_truth_rate;
    robot->scan_period = 1.0 / model.laser.rate;
    robot->next_odom = time() + robot->odom_period;
    robot->next_ground_truth = time() + robot->ground_truth_period;
    robot->next_scan = time() + robot->scan_period;
    ScanSpec& spec = robot->scan_spec;
    spec.min_angle = model.laser.min_angle;
    spec.angle_increment = model.laser.angleIncrement();
    spec.beams = model.laser.beams;
    spec.range_min = model.laser.range_min;
    spec.range_max = model.laser.range_max;
    spec.ignore_owner = id;
    robot->scan.ranges.assign(static_cast<size_t>(std::max(0, model.laser.beams)), 0.0f);
    ImuState& imu = robot->imu;
    imu.present = model.imu.present;
    imu.mount = ImuMountFrame(model.imu);
    imu.errors = std::make_unique<ImuErrors>(settings.noise.imu, settings.seed, id);
    imu.start = time();
    imu.bias_time = time();

    names.insert(name);
    robot_by_id.push_back(robot.get());
    robots.push_back(std::move(robot));
    return id;
  }

  void removeRobot(const std::string& name)
  {
    Robot& r = needRobot(name);
    const int id = r.id;
    names.erase(name);
    robot_by_id[id] = nullptr;
    robots.erase(std::find_if(robots.begin(), robots.end(), [&](const auto& p) { return p.get() == &r; }));
  }

  void addObstacle(const ObstacleConfig& config)
  {
    claimName(config.name, "obstacle");
    const std::string size_problem = checkShapeSizes(config.shape);
    if (!size_problem.empty()) throw SimError("obstacle " + config.name + ": " + size_problem);
    if (!(config.height > 0.0) || !std::isfinite(config.height))
      throw SimError("obstacle " + config.name + ": height: expected a number > 0 [m], got " +
                     formatNumber(config.height));
    const Pose2D& pose = config.pose;
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
      throw SimError("obstacle " + config.name + ": the pose is not finite");
    if (!insideMap(pose.x, pose.y))
      throw SimError("obstacle " + config.name + " at " + formatPoint(pose.x, pose.y) + " is outside the map");
    auto o = std::make_unique<Obstacle>();
    o->shape = config.shape;
    o->height = config.height;
    o->outline = outlineOf(config.shape);
    o->pose = config.pose;
    o->tag.kind = BodyTag::Kind::OBSTACLE;
    o->tag.name = config.name;
    // A static obstacle may touch walls and other obstacles, but not a robot.
    const BodyTag* other = overlapping(o->outline, o->pose, nullptr, false);
    if (other && other->kind == BodyTag::Kind::ROBOT)
      throw SimError("obstacle " + config.name + " at " + formatPoint(config.pose.x, config.pose.y) + " overlaps " +
                     other->describe());
    o->tag.uid = next_uid++;
    o->geom = makeGeom(o->outline, 0.0, false);
    setGeomPose(o->geom.get(), o->pose.x, o->pose.y, o->pose.theta);
    dGeomSetCategoryBits(o->geom.get(), kWallBit);
    dGeomSetCollideBits(o->geom.get(), kRobotBit);
    dGeomSetData(o->geom.get(), &o->tag);
    dSpaceAdd(static_space.get(), o->geom.get());
    names.insert(config.name);
    obstacles.push_back(std::move(o));
  }

  /// Between steps nothing else points at an obstacle: contact joints and hits live for one
  /// step, contact pairs are keyed by uid (never reused), and the laser's shapes are rebuilt
  /// from `obstacles` at every scan. So destroying the geom (it leaves its space) is enough.
  void removeObstacle(const std::string& name)
  {
    const auto it =
        std::find_if(obstacles.begin(), obstacles.end(), [&](const auto& o) { return o->tag.name == name; });
    if (it != obstacles.end())
    {
      names.erase(name);
      obstacles.erase(it);
      return;
    }
    if (name == "map") throw SimError("\"map\" is the walls, not an obstacle");
    if (robotByName(name)) throw SimError("\"" + name + "\" is a robot, not an obstacle");
    for (const auto& m : movers)
      if (m->tag.name == name)
        throw SimError("\"" + name + "\" is a moving obstacle; only static obstacles can be removed");
    throw SimError("unknown obstacle \"" + name + "\"");
  }

  void addMovingObstacle(const MovingObstacleConfig& config)
  {
    claimName(config.name, "moving obstacle");
    if (config.waypoints.size() < 2)
      throw SimError("moving obstacle " + config.name + ": expected at least 2 waypoints");
    if (!(config.speed > 0.0)) throw SimError("moving obstacle " + config.name + ": expected a speed > 0");
    if (!(config.yielding >= 0.0 && config.yielding <= 1.0))
      throw SimError("moving obstacle " + config.name + ": expected a yielding in [0, 1]");
    if (!(config.personal_radius > 0.0))
      throw SimError("moving obstacle " + config.name + ": expected a personal_radius > 0 [m]");
    auto m = std::make_unique<Mover>();
    m->config = config;
    m->outline = outlineOf(config.shape);
    m->tag.kind = BodyTag::Kind::MOVING;
    m->tag.name = config.name;
    m->route = config.waypoints;
    if (config.mode == MovingObstacleConfig::Mode::PING_PONG)
      for (size_t i = config.waypoints.size() - 1; i-- > 0;) m->route.push_back(config.waypoints[i]);
    else
      m->route.push_back(config.waypoints.front());
    m->cumulative.push_back(0.0);
    for (size_t i = 1; i < m->route.size(); ++i)
    {
      const double len = std::hypot(m->route[i].x - m->route[i - 1].x, m->route[i].y - m->route[i - 1].y);
      if (len < 1e-9) throw SimError("moving obstacle " + config.name + ": two equal waypoints in a row");
      m->cumulative.push_back(m->cumulative.back() + len);
    }
    m->start_time = time();
    m->moveTo(time());
    const BodyTag* other = overlapping(m->outline, m->pose, nullptr, false);
    if (other && other->kind == BodyTag::Kind::ROBOT)
      throw SimError("moving obstacle " + config.name + " starts overlapping " + other->describe());
    m->tag.uid = next_uid++;
    m->body.reset(dBodyCreate(world.get()));
    dBodySetKinematic(m->body.get());  // infinite mass: robots cannot push it
    m->geom = makeGeom(m->outline, 0.0, false);
    dGeomSetBody(m->geom.get(), m->body.get());
    m->reach = reachOf(m->outline);
    m->probe = makeGeom(m->outline, 0.0, false);
    dGeomSetCategoryBits(m->geom.get(), kMovingBit);
    dGeomSetCollideBits(m->geom.get(), kRobotBit);
    dGeomSetData(m->geom.get(), &m->tag);
    dSpaceAdd(dynamic_space.get(), m->geom.get());
    placeMover(*m);
    names.insert(config.name);
    movers.push_back(std::move(m));
  }

  // ---- run-time requests -------------------------------------------------------------------
  void setCommand(int id, const Twist2D& c)
  {
    Robot& r = robotById(id);
    r.command = clampCommand(r.model, c);
    r.command_time = time();
  }

  void teleport(const std::string& name, const Pose2D& pose, bool odometry_follows)
  {
    Robot& r = needRobot(name);
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
      throw SimError("robot " + name + ": the pose is not finite");
    if (!insideMap(pose.x, pose.y)) throw SimError("pose " + formatPoint(pose.x, pose.y) + " is outside the map");
    if (const BodyTag* other = overlapping(r.outline, pose, &r.tag, true))
      throw SimError("robot " + name + " at " + formatPoint(pose.x, pose.y) + " would overlap " + other->describe());
    const Pose2D odom_frame = mbot_common::compose(r.pose, mbot_common::inverse(r.odom));  // in the map
    placeBody(r, pose);
    r.lidar_last_time = -1.0;  // a jump: the lidar's frame restarts
    // A jump, not a motion: no acceleration spike for the IMU.
    r.imu.last_time = -1.0;
    if (odometry_follows)
    {
      r.odom = mbot_common::relative(odom_frame, r.pose);
      r.odom_twist = Twist2D{};
    }
  }

  void setFaults(const std::string& name, const FaultConfig& faults)
  {
    Robot& r = needRobot(name);
    const std::string problem = checkFaults(faults);
    if (!problem.empty()) throw SimError(problem);
    r.faults = faults;
    if (faults.drive_frozen) r.setpoint = Twist2D{};
  }

  void setNoise(const NoiseConfig& noise)
  {
    const auto check = [](const char* field, double value, const char* unit) {
      if (!(std::isfinite(value) && value >= 0.0))
        throw SimError(std::string("noise.") + field + ": expected a standard deviation >= 0 " + unit + ", got " +
                       std::to_string(value));
    };
    check("laser_range", noise.laser_range, "[m]");
    check("odom_linear", noise.odom_linear, "[m/s]");
    check("odom_angular", noise.odom_angular, "[rad/s]");
    const ImuNoiseConfig imu = settings.noise.imu;  // fixed at start: the biases were drawn from it
    settings.noise = noise;
    settings.noise.imu = imu;
  }

  void resetPositions()
  {
    for (auto& r : robots)
    {
      placeBody(*r, r->start);
      r->odom = Pose2D{};
      r->odom_twist = Twist2D{};
      std::fill(r->joints.position.begin(), r->joints.position.end(), 0.0);
      std::fill(r->joints.velocity.begin(), r->joints.velocity.end(), 0.0);
      // Samples a latency fault still holds were measured before the reset: delivered later they
      // would put the robot back where it was (old odometry after the new identity).
      r->pending_odom.clear();
      r->pending_joints.clear();
      r->pending_scans.clear();
      r->pending_clouds.clear();
      r->lidar_last_time = -1.0;
      r->imu.pending.clear();
      r->imu.last_time = -1.0;
      r->last_release = time();
    }
    for (auto& m : movers)
    {
      m->start_time = time();
      m->segment = 0;
      m->next = 1;
      m->side = 1.0;
      m->stuck_time = 0.0;
      m->moveTo(time());  // at the first waypoint, facing the second
      placeMover(*m);
    }
    contacts->clear();
  }

  // ---- the step ----------------------------------------------------------------------------
  void step()
  {
    const double dt = settings.physics_step;
    for (auto& r : robots) driveRobot(*r, time(), settings.watchdog_timeout, dt);
    if (std::any_of(movers.begin(), movers.end(), [](const auto& m) { return m->walker(); }))
      collectBodies(robots, movers, bodies);
    for (auto& m : movers)
    {
      if (m->walker()) planWalk(*m, bodies, static_space.get(), dt);
      dBodySetLinearVel(m->body.get(), m->vx, m->vy, 0.0);
    }

    contacts->beginStep();
    contacts->collideWithin(dynamic_space.get());
    for (auto& r : robots) contacts->collideWith(r->geom.get(), static_space.get());

    dWorldQuickStep(world.get(), dt);
    dJointGroupEmpty(contact_group.get());
    ++step_count;

    for (auto& r : robots)
    {
      settleRobot(*r);
      integrateOdometry(*r, settings.noise, dt);
    }
    for (auto& m : movers)
    {
      if (m->walker())
      {
        m->pose.x += m->vx * dt;
        m->pose.y += m->vy * dt;
        if (std::hypot(m->vx, m->vy) > 1e-9) m->pose.theta = std::atan2(m->vy, m->vx);
      }
      else
      {
        m->moveTo(time());
      }
      placeMover(*m);
    }
    // A pair counts as separated (and is reported again) after contact_release without a touch.
    const long long release_steps =
        std::max(1LL, static_cast<long long>(std::llround(settings.contact_release / settings.physics_step)));
    contacts->report(step_count, release_steps, time(), listener);

    sensors.run(time(), settings.noise, listener, robots, obstacles, movers);
  }
};

// =============================================================================================

World::World(const OccupancyMap& map, const WorldSettings& settings) : impl_(std::make_unique<Impl>(map, settings)) {}
World::~World() = default;

int World::addRobot(const std::string& name, const RobotModel& model, const Pose2D& pose)
{
  return impl_->addRobot(name, model, pose);
}
void World::removeRobot(const std::string& name) { impl_->removeRobot(name); }
void World::addObstacle(const ObstacleConfig& obstacle) { impl_->addObstacle(obstacle); }
void World::removeObstacle(const std::string& name) { impl_->removeObstacle(name); }
void World::addMovingObstacle(const MovingObstacleConfig& obstacle) { impl_->addMovingObstacle(obstacle); }
void World::setCommand(int robot, const Twist2D& command) { impl_->setCommand(robot, command); }
void World::teleport(const std::string& name, const Pose2D& pose, bool odometry_follows)
{
  impl_->teleport(name, pose, odometry_follows);
}
void World::setFaults(const std::string& name, const FaultConfig& faults) { impl_->setFaults(name, faults); }
void World::setNoise(const NoiseConfig& noise) { impl_->setNoise(noise); }
void World::resetPositions() { impl_->resetPositions(); }
void World::setListener(SensorListener* listener) { impl_->listener = listener; }
void World::step() { impl_->step(); }
double World::time() const { return impl_->time(); }
double World::physicsStep() const { return impl_->settings.physics_step; }

int World::findRobot(const std::string& name) const
{
  const Robot* r = impl_->robotByName(name);
  return r ? r->id : -1;
}
bool World::hasRobot(int robot) const
{
  return robot >= 0 && robot < static_cast<int>(impl_->robot_by_id.size()) && impl_->robot_by_id[robot];
}
std::vector<int> World::robotIds() const
{
  std::vector<int> ids;
  for (const auto& r : impl_->robots) ids.push_back(r->id);
  return ids;
}
size_t World::robotCount() const { return impl_->robots.size(); }
const std::string& World::robotName(int robot) const { return impl_->robotById(robot).tag.name; }
const RobotModel& World::robotModel(int robot) const { return impl_->robotById(robot).model; }
Pose2D World::groundTruth(int robot) const { return impl_->robotById(robot).pose; }
Twist2D World::velocity(int robot) const { return impl_->robotById(robot).velocity; }
bool World::atRest(int robot) const { return impl_->robotById(robot).at_rest; }
Pose2D World::odometry(int robot) const { return impl_->robotById(robot).odom; }
const FaultConfig& World::faults(int robot) const { return impl_->robotById(robot).faults; }
const NoiseConfig& World::noise() const { return impl_->settings.noise; }

bool World::isFree(double x, double y, double radius) const
{
  if (!impl_->insideMap(x, y)) return false;
  Outline o;
  o.radius = radius;
  return impl_->overlapping(o, Pose2D{x, y, 0.0}, nullptr, true) == nullptr;
}

std::vector<ObstacleState> World::obstacles() const
{
  std::vector<ObstacleState> out;
  for (const auto& o : impl_->obstacles) out.push_back(ObstacleState{o->tag.name, o->shape, o->pose, false});
  for (const auto& m : impl_->movers) out.push_back(ObstacleState{m->tag.name, m->config.shape, m->pose, true});
  return out;
}

size_t World::wallBoxCount() const { return impl_->walls.size(); }
unsigned long long World::raysCast() const { return impl_->sensors.raysCast(); }

void World::setLidar(int robot, const LidarConfig& config)
{
  Robot& r = impl_->robotById(robot);
  if (!config.enabled)
  {
    r.lidar.reset();
    r.pending_clouds.clear();
    return;
  }
  const auto& mount = r.model.lidar;
  if (!mount.present)
    throw SimError("robot " + r.tag.name + ": lidar: model " + r.model.name + " has no lidar_link in its URDF");
  constexpr double kDeg = 3.14159265358979323846 / 180.0;
  LidarSpec spec;
  spec.rate = config.rate;
  spec.points_per_frame = config.points_per_frame;
  spec.min_elevation = config.min_elevation * kDeg;
  spec.max_elevation = config.max_elevation * kDeg;
  spec.range_min = config.range_min;
  spec.range_max = config.range_max;
  spec.range_noise = config.range_noise;
  spec.range_quantization = config.range_quantization;
  if (!(mount.z > 0.0 && mount.z < impl_->settings.wall_height))
    throw SimError("robot " + r.tag.name + ": lidar: its lidar_link (" + formatNumber(mount.z) +
                   " m up) must be above the floor and below the walls' top (wall_height " +
                   formatNumber(impl_->settings.wall_height) + " m)");
  try
  {
    r.lidar = std::make_unique<LidarScanner>(spec, mount.x, mount.y, mount.z, mount.yaw, time());
  }
  catch (const std::invalid_argument& e)
  {
    throw SimError("robot " + r.tag.name + ": lidar: " + e.what());
  }
  std::seed_seq seq{impl_->settings.seed, static_cast<unsigned>(robot), 0x11da7u};
  r.lidar_rng.seed(seq);
  r.lidar_last_time = time();
  r.lidar_last_pose = r.pose;
}

bool World::hasLidar(int robot) const { return static_cast<bool>(impl_->robotById(robot).lidar); }

unsigned long long World::lidarRaysCast() const { return impl_->sensors.lidarRaysCast(); }

// =============================================================================================
}  // namespace mbot_sim
