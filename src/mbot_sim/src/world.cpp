/**
 * @file world.cpp
 * @brief The simulation core: ODE bodies in the plane, drive kinematics, contacts, odometry,
 *        lasers, noise and faults. See world.h.
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

#include "mbot_sim/raycast.h"

#include <ode/ode.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <deque>
#include <limits>
#include <random>
#include <set>
#include <sstream>
#include <utility>

namespace mbot_sim
{
using mbot_common::normalizeAngle;
using mbot_description::DriveType;
using mbot_description::RobotModel;

namespace
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

double clamp(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }

/// Move `v` towards `target` by at most `max_change`.
double approach(double v, double target, double max_change) { return v + clamp(target - v, -max_change, max_change); }

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

  std::string describe() const
  {
    switch (kind)
    {
      case Kind::WALL: return "a wall";
      case Kind::OBSTACLE: return "obstacle " + name;
      case Kind::MOVING: return "moving obstacle " + name;
      case Kind::ROBOT: return "robot " + name;
    }
    return name;
  }
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

Outline outlineOf(const ShapeConfig& shape)
{
  Outline o;
  o.is_box = shape.type == ShapeConfig::Type::BOX;
  o.radius = shape.radius;
  o.half_length = shape.length / 2.0;
  o.half_width = shape.width / 2.0;
  return o;
}

/// A robot's outline from its footprint polygon: a rectangle when the polygon is one (a box
/// body), else the smallest circle around the polygon's vertices centred on their mean.
Outline outlineOf(const RobotModel& model)
{
  Outline o;
  const auto& fp = model.footprint;
  if (fp.size() == 4)
  {
    const double ex = fp[1].x - fp[0].x, ey = fp[1].y - fp[0].y;
    const double fx = fp[2].x - fp[1].x, fy = fp[2].y - fp[1].y;
    const double gx = fp[3].x - fp[2].x, gy = fp[3].y - fp[2].y;
    const double le = std::hypot(ex, ey), lf = std::hypot(fx, fy);
    const bool rectangle = le > 1e-6 && lf > 1e-6 && std::abs(ex * fx + ey * fy) < 1e-6 * le * lf &&
                           std::abs(ex + gx) < 1e-6 && std::abs(ey + gy) < 1e-6;
    if (rectangle)
    {
      o.is_box = true;
      o.half_length = le / 2.0;
      o.half_width = lf / 2.0;
      o.offset_yaw = std::atan2(ey, ex);
      o.offset_x = (fp[0].x + fp[2].x) / 2.0;
      o.offset_y = (fp[0].y + fp[2].y) / 2.0;
      return o;
    }
  }
  if (fp.empty())
  {
    o.radius = model.footprint_radius;
    return o;
  }
  for (const auto& p : fp)
  {
    o.offset_x += p.x / fp.size();
    o.offset_y += p.y / fp.size();
  }
  for (const auto& p : fp) o.radius = std::max(o.radius, std::hypot(p.x - o.offset_x, p.y - o.offset_y));
  return o;
}

/// An ODE geom for an outline grown by `margin` [m] (not in any space, no body). Round robots
/// are spheres (their centre is at mid-height of every other body, so in the plane a sphere is
/// the circle): sphere-sphere, sphere-box and sphere-cylinder tests are exact and fast, while
/// ODE's cylinder-cylinder test is an approximate one. Round obstacles are cylinders.
GeomPtr makeGeom(const Outline& o, double margin, bool robot)
{
  if (o.is_box)
    return GeomPtr(dCreateBox(nullptr, 2.0 * (o.half_length + margin), 2.0 * (o.half_width + margin), kBodyHeight));
  if (robot) return GeomPtr(dCreateSphere(nullptr, o.radius + margin));
  return GeomPtr(dCreateCylinder(nullptr, o.radius + margin, kBodyHeight));
}

void setGeomPose(dGeomID geom, double x, double y, double yaw)
{
  dGeomSetPosition(geom, x, y, kBodyZ);
  dMatrix3 r;
  dRFromAxisAndAngle(r, 0, 0, 1, yaw);
  dGeomSetRotation(geom, r);
}

/// The outline's centre and heading in the map frame for a body at `pose`.
Pose2D outlinePose(const Outline& o, const Pose2D& pose)
{
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return Pose2D{pose.x + c * o.offset_x - s * o.offset_y, pose.y + s * o.offset_x + c * o.offset_y,
                pose.theta + o.offset_yaw};
}

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
  RobotModel model;
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
  Twist2D velocity;  ///< robot frame

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
};

struct Obstacle
{
  BodyTag tag;
  ShapeConfig shape;
  Outline outline;
  Pose2D pose;
  GeomPtr geom;
};

/// A kinematic obstacle on a closed route (loop: back to the first waypoint; ping_pong: the
/// waypoints back again). A blind one (yielding 0) is where its speed has carried it along the
/// route (moveTo); a walker (yielding > 0) walks from waypoint to waypoint and gives way
/// (Impl::planWalk).
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

  /// Pose at sim time t.
  void moveTo(double t)
  {
    const double length = cumulative.back();
    double d = std::fmod(config.speed * std::max(0.0, t - start_time), length);
    if (d < cumulative[segment]) segment = 0;
    while (segment + 2 < cumulative.size() && d > cumulative[segment + 1]) ++segment;
    const Point2D& a = route[segment];
    const Point2D& b = route[segment + 1];
    const double seg_len = cumulative[segment + 1] - cumulative[segment];
    const double ux = (b.x - a.x) / seg_len, uy = (b.y - a.y) / seg_len;
    d -= cumulative[segment];
    pose = Pose2D{a.x + ux * d, a.y + uy * d, std::atan2(uy, ux)};
    vx = ux * config.speed;
    vy = uy * config.speed;
  }
};

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
  GridRaycaster grid;
  ShapeSet shapes;

  BodyTag wall_tag;
  std::vector<GeomPtr> walls;
  std::vector<std::unique_ptr<Obstacle>> obstacles;
  std::vector<std::unique_ptr<Mover>> movers;
  std::vector<std::unique_ptr<Robot>> robots;  ///< in the order they were added
  std::vector<Robot*> robot_by_id;             ///< nullptr once removed
  std::set<std::string> names{"map"};
  uint32_t next_uid = 1;

  SensorListener* listener = nullptr;
  long long step_count = 0;
  unsigned long long rays_cast = 0;

  // contact tracking, reused every step (no allocation once warm)
  struct Hit
  {
    uint64_t key;
    const BodyTag* a;
    const BodyTag* b;
    double x, y;
  };
  struct ActivePair
  {
    uint64_t key;
    long long last_step;
  };
  std::vector<Hit> hits;
  std::vector<ActivePair> active_pairs, merged_pairs;

  Impl(const OccupancyMap& map, const WorldSettings& s) : settings(s), shapes(4.0)
  {
    if (!(settings.physics_step > 0.0 && settings.physics_step <= 0.1))
      throw SimError("physics_step: expected a number in (0, 0.1] [s], got " + std::to_string(settings.physics_step));
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

    wall_tag.kind = BodyTag::Kind::WALL;
    wall_tag.uid = 0;
    wall_tag.name = "map";

    std::vector<uint8_t> occupied(map.data.size());
    for (size_t i = 0; i < map.data.size(); ++i) occupied[i] = map.data[i] == 100 ? 1 : 0;
    grid = GridRaycaster(std::move(occupied), map.width, map.height, map.resolution, map.origin_x, map.origin_y);

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
    hits.reserve(256);
    active_pairs.reserve(256);
    merged_pairs.reserve(256);
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

  // ---- overlap queries (placement checks; no contact joints) ------------------------------
  struct OverlapQuery
  {
    dGeomID query = nullptr;
    const BodyTag* exclude = nullptr;
    double query_margin = 0.0;  ///< [m] how much the query geom is grown
    double robot_margin = 0.0;  ///< [m] how much robot geoms are grown
    const BodyTag* found = nullptr;
  };

  static void overlapCallback(void* data, dGeomID a, dGeomID b)
  {
    auto* q = static_cast<OverlapQuery*>(data);
    if (q->found) return;
    if (dGeomIsSpace(a) || dGeomIsSpace(b))
    {
      dSpaceCollide2(a, b, data, &overlapCallback);
      return;
    }
    const dGeomID other = a == q->query ? b : a;
    const auto* tag = static_cast<const BodyTag*>(dGeomGetData(other));
    if (!tag || tag == q->exclude) return;
    dContactGeom contacts[kMaxContacts];
    const int n = dCollide(q->query, other, kMaxContacts, contacts, sizeof(dContactGeom));
    // Geoms are grown by margins; only overlap beyond them is a real overlap of outlines.
    const double allowed = q->query_margin + (tag->kind == BodyTag::Kind::ROBOT ? q->robot_margin : 0.0) + 1e-6;
    for (int i = 0; i < n; ++i)
      if (contacts[i].depth > allowed)
      {
        q->found = tag;
        return;
      }
  }

  /// The first body an outline at `pose` would overlap (nullptr: none).
  const BodyTag* overlapping(const Outline& outline, const Pose2D& pose, const BodyTag* exclude, bool robot) const
  {
    GeomPtr geom = makeGeom(outline, settings.contact_margin, robot);
    const Pose2D p = outlinePose(outline, pose);
    setGeomPose(geom.get(), p.x, p.y, p.theta);
    OverlapQuery q;
    q.query = geom.get();
    q.exclude = exclude;
    q.query_margin = settings.contact_margin;
    q.robot_margin = settings.contact_margin;
    dSpaceCollide2(geom.get(), reinterpret_cast<dGeomID>(static_space.get()), &q, &overlapCallback);
    if (!q.found) dSpaceCollide2(geom.get(), reinterpret_cast<dGeomID>(dynamic_space.get()), &q, &overlapCallback);
    return q.found;
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

    // Wheels: left/right at +-separation/2 (diff: [left, right]); mecanum: [front_left,
    // front_right, rear_left, rear_right] at +-wheel_base/2, +-separation/2 (the order of the
    // model's wheel_joints).
    const double half_sep = model.wheel_separation / 2.0, half_base = model.wheel_base / 2.0;
    if (model.drive == DriveType::DIFF)
      robot->wheel_mounts = {{0.0, half_sep}, {0.0, -half_sep}};
    else
      robot->wheel_mounts = {
          {half_base, half_sep}, {half_base, -half_sep}, {-half_base, half_sep}, {-half_base, -half_sep}};
    robot->wheel_mounts.resize(model.wheel_joints.size());
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

    names.insert(name);
    robot_by_id.push_back(robot.get());
    robots.push_back(std::move(robot));
    return id;
  }

  /// Put a robot's body at `pose`, at rest.
  void placeBody(Robot& r, const Pose2D& pose)
  {
    dBodySetPosition(r.body.get(), pose.x, pose.y, kBodyZ);
    dQuaternion q = {std::cos(pose.theta / 2.0), 0.0, 0.0, std::sin(pose.theta / 2.0)};
    dBodySetQuaternion(r.body.get(), q);
    dBodySetLinearVel(r.body.get(), 0, 0, 0);
    dBodySetAngularVel(r.body.get(), 0, 0, 0);
    r.pose = Pose2D{pose.x, pose.y, normalizeAngle(pose.theta)};
    r.velocity = Twist2D{};
    r.setpoint = Twist2D{};
    r.command = Twist2D{};
    r.command_time = -kInf;
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
    const Pose2D& pose = config.pose;
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
      throw SimError("obstacle " + config.name + ": the pose is not finite");
    if (!insideMap(pose.x, pose.y))
      throw SimError("obstacle " + config.name + " at " + formatPoint(pose.x, pose.y) + " is outside the map");
    auto o = std::make_unique<Obstacle>();
    o->shape = config.shape;
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

  void placeMover(Mover& m)
  {
    dBodySetPosition(m.body.get(), m.pose.x, m.pose.y, kBodyZ);
    dQuaternion q = {std::cos(m.pose.theta / 2.0), 0.0, 0.0, std::sin(m.pose.theta / 2.0)};
    dBodySetQuaternion(m.body.get(), q);
    dBodySetLinearVel(m.body.get(), m.vx, m.vy, 0.0);
    dBodySetAngularVel(m.body.get(), 0, 0, 0);
  }

  // ---- run-time requests -------------------------------------------------------------------
  void setCommand(int id, const Twist2D& c)
  {
    Robot& r = robotById(id);
    const auto& lim = r.model.limits;
    auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };  // NaN must not reach ODE
    r.command.vx = clamp(finite(c.vx), std::min(lim.min_vel_x, 0.0), lim.max_vel_x);
    r.command.vy = r.model.drive == DriveType::OMNI ? clamp(finite(c.vy), -lim.max_vel_y, lim.max_vel_y) : 0.0;
    r.command.wz = clamp(finite(c.wz), -lim.max_vel_theta, lim.max_vel_theta);
    r.command_time = time();
  }

  void teleport(const std::string& name, const Pose2D& pose)
  {
    Robot& r = needRobot(name);
    if (!std::isfinite(pose.x) || !std::isfinite(pose.y) || !std::isfinite(pose.theta))
      throw SimError("robot " + name + ": the pose is not finite");
    if (!insideMap(pose.x, pose.y)) throw SimError("pose " + formatPoint(pose.x, pose.y) + " is outside the map");
    if (const BodyTag* other = overlapping(r.outline, pose, &r.tag, true))
      throw SimError("robot " + name + " at " + formatPoint(pose.x, pose.y) + " would overlap " + other->describe());
    placeBody(r, pose);
  }

  void setFaults(const std::string& name, const FaultConfig& faults)
  {
    Robot& r = needRobot(name);
    const std::string problem = checkFaults(faults);
    if (!problem.empty()) throw SimError(problem);
    r.faults = faults;
    if (faults.drive_frozen) r.setpoint = Twist2D{};
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
    active_pairs.clear();
  }

  // ---- walkers (moving obstacles that give way) ----------------------------------------------
  /// A body a walker keeps its distance from: the circle around its outline.
  struct BodyCircle
  {
    double x, y, radius;
    const Mover* mover;  ///< nullptr for a robot
  };
  std::vector<BodyCircle> bodies;  ///< robots and movers at the start of the step (reused)

  static double reachOf(const Outline& o) { return o.is_box ? std::hypot(o.half_length, o.half_width) : o.radius; }

  void collectBodies()
  {
    bodies.clear();
    for (const auto& r : robots)
    {
      const Pose2D c = outlinePose(r->outline, r->pose);
      bodies.push_back(BodyCircle{c.x, c.y, reachOf(r->outline), nullptr});
    }
    for (const auto& m : movers) bodies.push_back(BodyCircle{m->pose.x, m->pose.y, m->reach, m.get()});
  }

  /// True when the mover's outline at (x, y, yaw) overlaps a wall or a static obstacle.
  bool hitsStatic(Mover& m, double x, double y, double yaw) const
  {
    setGeomPose(m.probe.get(), x, y, yaw);
    OverlapQuery q;
    q.query = m.probe.get();
    dSpaceCollide2(m.probe.get(), reinterpret_cast<dGeomID>(static_space.get()), &q, &overlapCallback);
    return q.found != nullptr;
  }

  /// A step with velocity (vx, vy) is allowed when it brings the walker no closer than kMinGap
  /// to any body it is not already closer to, and into no wall it is not already in.
  bool stepAllowed(Mover& m, double vx, double vy, double dt, bool in_wall) const
  {
    constexpr double kMinGap = 0.05;  // [m] between outlines; contacts begin at the 0.01 m margin
    const double x = m.pose.x + vx * dt, y = m.pose.y + vy * dt;
    for (const BodyCircle& b : bodies)
    {
      if (b.mover == &m) continue;
      const double gap_now = std::hypot(m.pose.x - b.x, m.pose.y - b.y) - m.reach - b.radius;
      const double gap_next = std::hypot(x - b.x, y - b.y) - m.reach - b.radius;
      if (gap_next < kMinGap && gap_next < gap_now - 1e-12) return false;
    }
    if (in_wall || (vx == 0.0 && vy == 0.0)) return true;
    const double yaw = std::hypot(vx, vy) > 1e-9 ? std::atan2(vy, vx) : m.pose.theta;
    return !hitsStatic(m, x, y, yaw);
  }

  /// The walker's velocity for this step (m.vx, m.vy), social-force style: it heads for its next
  /// waypoint at its speed; robots and other movers within personal_radius of its outline push
  /// it away and, when they are ahead, steer it around them (to its right when head-on), both
  /// scaled by `yielding`; then the step is checked: it never closes in on a body nearer than
  /// kMinGap (it stops instead: it cannot be pushed, so it must not walk into anyone) and
  /// never enters a wall (it slides along, or waits).
  void planWalk(Mover& m, double dt)
  {
    const MovingObstacleConfig& c = m.config;
    // 1. The waypoint: reached when within one step, or when a body stands on it and the
    //    walker is next to it (it would wait there for ever).
    Point2D target;
    double dist = 0.0;
    for (size_t guard = 0; guard < m.route.size(); ++guard)
    {
      target = m.route[m.next];
      dist = std::hypot(target.x - m.pose.x, target.y - m.pose.y);
      bool reached = dist <= std::max(c.speed * dt, 1e-3);
      if (!reached && dist <= m.reach + c.personal_radius)
        for (const BodyCircle& b : bodies)
          reached = reached || (b.mover != &m && std::hypot(target.x - b.x, target.y - b.y) < b.radius + m.reach);
      if (!reached) break;
      m.next = m.next + 1 < m.route.size() ? m.next + 1 : 1;  // route.back() == route.front()
    }
    const double ex = dist > 1e-9 ? (target.x - m.pose.x) / dist : 0.0;
    const double ey = dist > 1e-9 ? (target.y - m.pose.y) / dist : 0.0;

    // 2. Social forces, in units of its speed.
    double fx = 0.0, fy = 0.0;
    for (const BodyCircle& b : bodies)
    {
      if (b.mover == &m) continue;
      double nx = m.pose.x - b.x, ny = m.pose.y - b.y;  // from the body to the walker
      const double d = std::hypot(nx, ny);
      if (d < 1e-9) continue;
      nx /= d;
      ny /= d;
      const double gap = d - m.reach - b.radius;
      if (gap >= c.personal_radius) continue;
      const double s = std::min(1.0, (c.personal_radius - gap) / c.personal_radius);  // 0 at the edge
      const double ahead = -(nx * ex + ny * ey);                                      // 1: straight ahead, -1: behind
      const double weight = 0.5 + 0.5 * std::max(0.0, ahead);                         // what is ahead matters more
      fx += 2.0 * s * s * weight * nx;
      fy += 2.0 * s * s * weight * ny;
      if (ahead > 0.0)
      {
        // Around it: the tangent that goes on forwards, preferably on its side (right, as
        // people keep right; the left after it got stuck, e.g. with a wall on its right).
        double tx = -ny, ty = nx;
        if (tx * ex + ty * ey + 0.3 * m.side * (tx * ey - ty * ex) < 0.0)
        {
          tx = -tx;
          ty = -ty;
        }
        fx += 1.5 * s * ahead * tx;
        fy += 1.5 * s * ahead * ty;
      }
    }
    double vx = c.speed * (ex + c.yielding * fx), vy = c.speed * (ey + c.yielding * fy);
    const double v = std::hypot(vx, vy);
    if (v > c.speed)
    {
      vx *= c.speed / v;
      vy *= c.speed / v;
    }

    // 3. The step it may take: as wished; without the part towards bodies it is close to;
    //    sliding along a wall; or none.
    const bool in_wall = hitsStatic(m, m.pose.x, m.pose.y, m.pose.theta);
    double px = vx, py = vy;
    for (const BodyCircle& b : bodies)
    {
      if (b.mover == &m) continue;
      double nx = m.pose.x - b.x, ny = m.pose.y - b.y;
      const double d = std::hypot(nx, ny);
      if (d < 1e-9 || d - m.reach - b.radius > c.personal_radius) continue;
      nx /= d;
      ny /= d;
      const double towards = px * nx + py * ny;  // < 0: closing in
      if (towards < 0.0)
      {
        px -= towards * nx;
        py -= towards * ny;
      }
    }
    const double candidates[5][2] = {{vx, vy}, {px, py}, {px, 0.0}, {0.0, py}, {0.0, 0.0}};
    for (const auto& cand : candidates)
      if (stepAllowed(m, cand[0], cand[1], dt, in_wall))
      {
        m.vx = cand[0];
        m.vy = cand[1];
        break;
      }

    // 4. No headway for a second (a body ahead and no way past on this side): try the other.
    const bool headway = m.vx * ex + m.vy * ey > 0.1 * c.speed;
    m.stuck_time = headway ? 0.0 : m.stuck_time + dt;
    if (m.stuck_time > 1.0)
    {
      m.side = -m.side;
      m.stuck_time = 0.0;
    }
  }

  // ---- the step ----------------------------------------------------------------------------
  static void nearCallback(void* data, dGeomID a, dGeomID b) { static_cast<Impl*>(data)->collide(a, b); }

  void collide(dGeomID a, dGeomID b)
  {
    dContactGeom contacts[kMaxContacts];
    const int n = dCollide(a, b, kMaxContacts, contacts, sizeof(dContactGeom));
    if (n == 0) return;
    const dBodyID body_a = dGeomGetBody(a), body_b = dGeomGetBody(b);
    for (int i = 0; i < n; ++i)
    {
      dContact contact;
      contact.surface.mode = 0;  // frictionless: bodies slide along walls
      contact.surface.mu = 0.0;
      contact.geom = contacts[i];
      // Keep the normal in the plane (bodies are on the ground).
      dReal* nrm = contact.geom.normal;
      const double len = std::hypot(nrm[0], nrm[1]);
      if (len < 1e-9) continue;
      nrm[0] /= len;
      nrm[1] /= len;
      nrm[2] = 0.0;
      const dJointID joint = dJointCreateContact(world.get(), contact_group.get(), &contact);
      dJointAttach(joint, body_a, body_b);
    }
    const auto* ta = static_cast<const BodyTag*>(dGeomGetData(a));
    const auto* tb = static_cast<const BodyTag*>(dGeomGetData(b));
    if (ta->uid > tb->uid) std::swap(ta, tb);
    hits.push_back(
        Hit{(static_cast<uint64_t>(ta->uid) << 32) | tb->uid, ta, tb, contacts[0].pos[0], contacts[0].pos[1]});
  }

  void driveRobot(Robot& r, double dt)
  {
    const auto& lim = r.model.limits;
    Twist2D target;
    if (!r.faults.drive_frozen && time() - r.command_time <= settings.watchdog_timeout + kTimeEpsilon)
      target = r.command;
    if (r.faults.drive_frozen)
      r.setpoint = Twist2D{};
    else
    {
      r.setpoint.vx = approach(r.setpoint.vx, target.vx, lim.acc_lim_x * dt);
      r.setpoint.vy = approach(r.setpoint.vy, target.vy, std::max(lim.acc_lim_y, 0.0) * dt);
      r.setpoint.wz = approach(r.setpoint.wz, target.wz, lim.acc_lim_theta * dt);
    }
    // The robot-frame velocity in the map frame at the middle of the step: a constant
    // twist then moves the robot along the exact chord of its arc.
    const double yaw_mid = r.pose.theta + 0.5 * r.setpoint.wz * dt;
    const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
    dBodySetLinearVel(r.body.get(), c * r.setpoint.vx - s * r.setpoint.vy, s * r.setpoint.vx + c * r.setpoint.vy, 0.0);
    dBodySetAngularVel(r.body.get(), 0.0, 0.0, r.setpoint.wz);
  }

  /// Back onto the plane (z, roll, pitch), then read the true pose and velocity.
  void settleRobot(Robot& r)
  {
    dBodyID b = r.body.get();
    const dReal* p = dBodyGetPosition(b);
    const dReal* q = dBodyGetQuaternion(b);  // w, x, y, z
    // Dropping x and y of the quaternion keeps only the rotation about z.
    const double qn = std::hypot(q[0], q[3]);
    const double qw = qn > 0.0 ? q[0] / qn : 1.0, qz = qn > 0.0 ? q[3] / qn : 0.0;
    const dQuaternion flat = {qw, 0.0, 0.0, qz};
    dBodySetQuaternion(b, flat);
    dBodySetPosition(b, p[0], p[1], kBodyZ);
    const dReal* v = dBodyGetLinearVel(b);
    const dReal* w = dBodyGetAngularVel(b);
    const double vx = v[0], vy = v[1], wz = w[2];
    dBodySetLinearVel(b, vx, vy, 0.0);
    dBodySetAngularVel(b, 0.0, 0.0, wz);

    const double previous_yaw = r.pose.theta;
    r.pose = Pose2D{p[0], p[1], normalizeAngle(2.0 * std::atan2(qz, qw))};
    // The robot-frame velocity over the step: rotate by the heading in the middle of the step,
    // as driveRobot() did, so that an unobstructed robot measures exactly its setpoint.
    const double yaw_mid = previous_yaw + 0.5 * normalizeAngle(r.pose.theta - previous_yaw);
    const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
    r.velocity = Twist2D{c * vx + s * vy, -s * vx + c * vy, wz};
  }

  /// Odometry from the wheels: they measure the robot's motion along the directions they
  /// drive (a diff drive cannot sense being pushed sideways), plus noise and drift.
  void integrateOdometry(Robot& r, double dt)
  {
    Twist2D m = r.velocity;
    if (r.model.drive == DriveType::DIFF) m.vy = 0.0;

    const double wheel_r = r.model.wheel_radius;
    for (size_t i = 0; i < r.wheel_mounts.size(); ++i)
    {
      const Point2D& w = r.wheel_mounts[i];
      // Rolling speed of the wheel's contact point; mecanum rollers at 45 degrees add the
      // sideways speed with the sign of x*y (front left and rear right: +).
      double rolling = m.vx - m.wz * w.y;
      if (r.model.drive == DriveType::OMNI) rolling -= (w.x * w.y >= 0.0 ? 1.0 : -1.0) * (m.vy + m.wz * w.x);
      const double speed = wheel_r > 0.0 ? rolling / wheel_r : 0.0;
      r.joints.velocity[i] = speed;
      r.joints.position[i] = normalizeAngle(r.joints.position[i] + speed * dt);
    }

    const NoiseConfig& noise = settings.noise;
    const bool moving = std::abs(m.vx) + std::abs(m.vy) + std::abs(m.wz) > 1e-9;
    if (moving)  // encoders of standing wheels do not tick: no noise at rest
    {
      if (noise.odom_linear > 0.0)
      {
        m.vx += noise.odom_linear * r.gauss(r.rng);
        if (r.model.drive == DriveType::OMNI) m.vy += noise.odom_linear * r.gauss(r.rng);
      }
      if (noise.odom_angular > 0.0) m.wz += noise.odom_angular * r.gauss(r.rng);
    }
    m.wz += r.faults.odom_drift;

    const double yaw_mid = r.odom.theta + 0.5 * m.wz * dt;
    const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
    r.odom.x += (c * m.vx - s * m.vy) * dt;
    r.odom.y += (s * m.vx + c * m.vy) * dt;
    r.odom.theta = normalizeAngle(r.odom.theta + m.wz * dt);
    r.odom_twist = m;
  }

  void reportContacts()
  {
    std::sort(hits.begin(), hits.end(), [](const Hit& a, const Hit& b) { return a.key < b.key; });
    const long long release_steps =
        std::max(1LL, static_cast<long long>(std::llround(settings.contact_release / settings.physics_step)));
    merged_pairs.clear();
    size_t i = 0, j = 0;
    while (i < active_pairs.size() || j < hits.size())
    {
      if (j < hits.size() && j > 0 && hits[j].key == hits[j - 1].key)
      {
        ++j;  // the same pair again (several geoms): counted once
        continue;
      }
      if (j >= hits.size() || (i < active_pairs.size() && active_pairs[i].key < hits[j].key))
      {
        if (step_count - active_pairs[i].last_step < release_steps) merged_pairs.push_back(active_pairs[i]);
        ++i;
      }
      else if (i >= active_pairs.size() || hits[j].key < active_pairs[i].key)
      {
        merged_pairs.push_back(ActivePair{hits[j].key, step_count});
        if (listener)
        {
          ContactEvent e;
          e.stamp = time();
          e.body_a = hits[j].a->name;
          e.body_b = hits[j].b->name;
          e.x = hits[j].x;
          e.y = hits[j].y;
          listener->onContact(e);
        }
        ++j;
      }
      else
      {
        merged_pairs.push_back(ActivePair{hits[j].key, step_count});
        ++i;
        ++j;
      }
    }
    std::swap(active_pairs, merged_pairs);
  }

  static bool due(double now, double& next, double period)
  {
    if (now + kTimeEpsilon < next) return false;
    next += period;
    if (next <= now) next = now + period;  // after a long pause of the timer: no burst
    return true;
  }

  /// When a sample measured now reaches the listener (latency fault), keeping the order.
  double releaseTime(Robot& r)
  {
    const FaultConfig& f = r.faults;
    double release = time() + f.sensor_latency;
    if (f.sensor_jitter > 0.0) release += std::abs(f.sensor_jitter * r.gauss(r.rng));
    release = std::max(release, r.last_release);
    r.last_release = release;
    return release;
  }

  bool delayed(const Robot& r) const { return r.faults.sensor_latency > 0.0 || r.faults.sensor_jitter > 0.0; }

  void buildShapes()
  {
    shapes.clear();
    for (const auto& o : obstacles) addShape(o->outline, o->pose, -1);
    for (const auto& m : movers) addShape(m->outline, m->pose, -1);
    for (const auto& r : robots) addShape(r->outline, r->pose, r->id);
  }

  void addShape(const Outline& outline, const Pose2D& pose, int owner)
  {
    const Pose2D p = outlinePose(outline, pose);
    if (outline.is_box)
    {
      OrientedBox b;
      b.x = p.x;
      b.y = p.y;
      b.yaw = p.theta;
      b.half_length = outline.half_length;
      b.half_width = outline.half_width;
      b.owner = owner;
      shapes.addBox(b);
    }
    else
    {
      Circle c;
      c.x = p.x;
      c.y = p.y;
      c.radius = outline.radius;
      c.owner = owner;
      shapes.addCircle(c);
    }
  }

  void measureScan(Robot& r)
  {
    const auto& laser = r.model.laser;
    const double c = std::cos(r.pose.theta), s = std::sin(r.pose.theta);
    ScanSpec& spec = r.scan_spec;
    spec.x = r.pose.x + c * laser.mount_x - s * laser.mount_y;
    spec.y = r.pose.y + s * laser.mount_x + c * laser.mount_y;
    spec.yaw = r.pose.theta + laser.mount_yaw;
    castScan(grid, shapes, spec, r.scan.ranges);
    rays_cast += static_cast<unsigned long long>(spec.beams);
    r.scan.stamp = time();

    const double sigma = settings.noise.laser_range;
    const double dropout = r.faults.laser_dropout;
    if (sigma <= 0.0 && dropout <= 0.0) return;
    const float inf = std::numeric_limits<float>::infinity();
    const float invalid = std::numeric_limits<float>::quiet_NaN();
    for (float& range : r.scan.ranges)
    {
      // A dropped beam measured nothing: NaN (REP-117 "invalid"), not +Inf, which would claim
      // that nothing is in range and make costmaps clear real obstacles.
      if (dropout > 0.0 && r.uniform(r.rng) < dropout)
      {
        range = invalid;
        continue;
      }
      if (sigma > 0.0 && std::isfinite(range))
      {
        const double noisy = range + sigma * r.gauss(r.rng);
        if (noisy > laser.range_max)
          range = inf;
        else if (noisy < laser.range_min)
          range = -inf;
        else
          range = static_cast<float>(noisy);
      }
    }
  }

  void runSensors(Robot& r, bool& shapes_built)
  {
    const double now = time();
    if (due(now, r.next_ground_truth, r.ground_truth_period) && listener)
    {
      GroundTruthSample gt;
      gt.stamp = now;
      gt.pose = r.pose;
      gt.twist = r.velocity;
      listener->onGroundTruth(r.id, gt);
    }
    const bool silenced = r.faults.silenced;
    if (due(now, r.next_odom, r.odom_period) && !silenced)
    {
      OdometrySample odom;
      odom.stamp = now;
      odom.pose = r.odom;
      odom.twist = r.odom_twist;
      r.joints.stamp = now;
      if (delayed(r))
      {
        const double release = releaseTime(r);
        r.pending_odom.push_back({release, odom});
        r.pending_joints.push_back({release, r.joints});
      }
      else if (listener)
      {
        listener->onOdometry(r.id, odom);
        listener->onJointState(r.id, r.joints);
      }
    }
    if (due(now, r.next_scan, r.scan_period) && !silenced)
    {
      if (!shapes_built)
      {
        buildShapes();
        shapes_built = true;
      }
      measureScan(r);
      if (delayed(r))
        r.pending_scans.push_back({releaseTime(r), r.scan});
      else if (listener)
        listener->onScan(r.id, r.scan);
    }
    releasePending(r, r.pending_odom, &SensorListener::onOdometry);
    releasePending(r, r.pending_joints, &SensorListener::onJointState);
    releasePending(r, r.pending_scans, &SensorListener::onScan);
  }

  template <class Sample>
  void releasePending(Robot& r, std::deque<Pending<Sample>>& queue, void (SensorListener::*deliver)(int, const Sample&))
  {
    while (!queue.empty() && queue.front().release <= time() + kTimeEpsilon)
    {
      if (listener && !r.faults.silenced) (listener->*deliver)(r.id, queue.front().sample);
      queue.pop_front();
    }
  }

  void step()
  {
    const double dt = settings.physics_step;
    for (auto& r : robots) driveRobot(*r, dt);
    if (std::any_of(movers.begin(), movers.end(), [](const auto& m) { return m->walker(); })) collectBodies();
    for (auto& m : movers)
    {
      if (m->walker()) planWalk(*m, dt);
      dBodySetLinearVel(m->body.get(), m->vx, m->vy, 0.0);
    }

    hits.clear();
    dSpaceCollide(dynamic_space.get(), this, &nearCallback);
    for (auto& r : robots)
      dSpaceCollide2(r->geom.get(), reinterpret_cast<dGeomID>(static_space.get()), this, &nearCallback);

    dWorldQuickStep(world.get(), dt);
    dJointGroupEmpty(contact_group.get());
    ++step_count;

    for (auto& r : robots)
    {
      settleRobot(*r);
      integrateOdometry(*r, dt);
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
    reportContacts();

    bool shapes_built = false;
    for (auto& r : robots) runSensors(*r, shapes_built);
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
void World::teleport(const std::string& name, const Pose2D& pose) { impl_->teleport(name, pose); }
void World::setFaults(const std::string& name, const FaultConfig& faults) { impl_->setFaults(name, faults); }
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
Pose2D World::odometry(int robot) const { return impl_->robotById(robot).odom; }
const FaultConfig& World::faults(int robot) const { return impl_->robotById(robot).faults; }

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
unsigned long long World::raysCast() const { return impl_->rays_cast; }

// =============================================================================================

std::vector<CellRect> mergeOccupiedCells(const OccupancyMap& map)
{
  std::vector<CellRect> rects;
  std::vector<uint8_t> taken(map.data.size(), 0);
  auto free_cell = [&](unsigned x, unsigned y) {
    const size_t i = static_cast<size_t>(y) * map.width + x;
    return map.data[i] == 100 && !taken[i];
  };
  for (unsigned y = 0; y < map.height; ++y)
  {
    for (unsigned x = 0; x < map.width; ++x)
    {
      if (!free_cell(x, y)) continue;
      CellRect r{x, y, 0, 1};
      while (x + r.width < map.width && free_cell(x + r.width, y)) ++r.width;
      while (y + r.height < map.height)
      {
        bool whole_run = true;
        for (unsigned k = 0; k < r.width && whole_run; ++k) whole_run = free_cell(x + k, y + r.height);
        if (!whole_run) break;
        ++r.height;
      }
      for (unsigned yy = y; yy < y + r.height; ++yy)
        for (unsigned xx = x; xx < x + r.width; ++xx) taken[static_cast<size_t>(yy) * map.width + xx] = 1;
      rects.push_back(r);
    }
  }
  return rects;
}

ObstacleConfig obstacleFromRequest(const std::string& name, const std::string& shape, double length, double width,
                                   double radius, const Pose2D& pose)
{
  ObstacleConfig o;
  o.name = name;
  o.pose = pose;
  // The world file reader's words: a box has a size, a cylinder a radius, and not the other.
  if (shape == "box")
  {
    if (radius != 0.0) throw SimError("obstacle " + name + ": radius: a box has a size [length, width], not a radius");
    o.shape.type = ShapeConfig::Type::BOX;
    o.shape.length = length;
    o.shape.width = width;
  }
  else if (shape == "cylinder")
  {
    if (length != 0.0 || width != 0.0)
      throw SimError("obstacle " + name + ": length, width: a cylinder has a radius, not a size");
    o.shape.type = ShapeConfig::Type::CYLINDER;
    o.shape.radius = radius;
  }
  else
  {
    throw SimError("obstacle " + name + ": shape: expected box or cylinder, got \"" + shape + "\"");
  }
  return o;
}

std::unique_ptr<World> buildWorld(const WorldConfig& config, const ModelLoader& load_model, double watchdog_timeout)
{
  auto fail = [&](const std::string& key, const std::string& problem) -> WorldConfigError {
    return WorldConfigError(config.file + ": " + key + ": " + problem);
  };
  WorldSettings settings;
  settings.physics_step = config.physics_step;
  settings.seed = config.seed;
  settings.noise = config.noise;
  settings.watchdog_timeout = watchdog_timeout;
  std::unique_ptr<World> world;
  try
  {
    world = std::make_unique<World>(config.map_data, settings);
  }
  catch (const SimError& e)
  {
    throw fail("map", e.what());
  }

  for (const auto& o : config.obstacles)
  {
    try
    {
      world->addObstacle(o);
    }
    catch (const SimError& e)
    {
      throw fail(o.key, e.what());
    }
  }
  for (const auto& m : config.moving_obstacles)
  {
    try
    {
      world->addMovingObstacle(m);
    }
    catch (const SimError& e)
    {
      throw fail(m.key, e.what());
    }
  }
  for (const auto& r : config.robots)
  {
    RobotModel model;
    try
    {
      model = load_model(r.model);
    }
    catch (const std::exception& e)
    {
      throw fail(r.key + ".model", "cannot load model \"" + r.model + "\": " + e.what());
    }
    try
    {
      world->addRobot(r.name, model, r.pose);
    }
    catch (const SimError& e)
    {
      throw fail(r.key + ".pose", e.what());
    }
  }
  for (const auto& f : config.faults)
  {
    try
    {
      world->setFaults(f.robot, f.faults);
    }
    catch (const SimError& e)
    {
      throw fail(f.key, e.what());
    }
  }
  return world;
}

}  // namespace mbot_sim
