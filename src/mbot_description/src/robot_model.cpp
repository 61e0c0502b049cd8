/**
 * @file robot_model.cpp
 * @brief Reads a robot's geometry from its URDF (urdfdom) and its limits and sensor settings from
 *        its model settings file (mbot_common's strict YAML reader). See robot_model.h.
 */
#include "mbot_description/robot_model.h"

#include <mbot_common/strict_yaml.h>
#include <urdf_parser/urdf_parser.h>
#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <limits>
#include <sstream>
#include <utility>

namespace mbot_description
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr int kCircleVertices = 16;        // a cylinder body becomes a 16-gon, as costmap_2d does
constexpr double kTolerance = 1e-6;        // [m] or [rad]: "equal" for numbers read from files
constexpr double kGroundTolerance = 1e-3;  // [m] a wheel centre may sit this far off its radius

const char* const kRootLink = "base_footprint";
const char* const kBodyLink = "base_link";
const char* const kLaserLink = "base_laser";
const char* const kImuLink = "imu_link";

std::string readFile(const std::string& path, const std::string& what)
{
  std::ifstream in(path);
  if (!in) throw ModelError(path + ": cannot read the " + what + " (missing or unreadable file)");
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string formatNumber(double value)
{
  std::ostringstream out;
  out << value;
  return out.str();
}

// ---------------------------------------------------------------------------------------------
// Model settings (yaml)
// ---------------------------------------------------------------------------------------------

/// Reads one settings file strictly (mbot_common's reader): unknown, duplicate and missing keys
/// and wrong types are errors "<file>: <key>: expected <what>, got <value>".
using SettingsReader = mbot_common::StrictYaml<ModelError>;

/// The number at `map[key]`; `where` is the map's key path ("" at the top level).
double number(const SettingsReader& reader, const YAML::Node& map, const std::string& where, const std::string& key,
              const std::string& unit)
{
  return reader.number(map[key], SettingsReader::join(where, key), "a number " + unit);
}

int integer(const SettingsReader& reader, const YAML::Node& map, const std::string& where, const std::string& key)
{
  const std::string path = SettingsReader::join(where, key);
  const long long value = reader.integer(map[key], path);
  if (value < std::numeric_limits<int>::min() || value > std::numeric_limits<int>::max())
    reader.expected(path, "an integer", map[key]);
  return static_cast<int>(value);
}

std::vector<std::string> textList(const SettingsReader& reader, const YAML::Node& map, const std::string& key)
{
  const YAML::Node node = map[key];
  if (!node.IsDefined() || !node.IsSequence()) reader.expected(key, "a list of strings", node);
  std::vector<std::string> values;
  for (std::size_t i = 0; i < node.size(); ++i) values.push_back(reader.text(node[i], SettingsReader::index(key, i)));
  return values;
}

/// The map at `where` must hold exactly `keys`: no unknown key, none missing.
void expectKeys(const SettingsReader& reader, const YAML::Node& node, const std::string& where,
                const std::vector<std::string>& keys)
{
  reader.checkKeys(node, where, keys, keys);
}

/// What the settings file says; geometry is added from the URDF afterwards.
RobotModel readSettings(const std::string& config_path)
{
  const SettingsReader reader(config_path);
  const YAML::Node root = reader.load();
  expectKeys(reader, root, "", {"drive", "wheel_joints", "limits", "laser", "odom_rate", "ground_truth_rate"});
  // Value checks: each names the key and the rule the value breaks.
  const auto require = [&reader](bool ok, const std::string& key, const std::string& rule, const YAML::Node& value) {
    if (!ok) reader.expected(key, rule, value);
  };

  RobotModel model;
  const std::string drive = reader.text(root["drive"], "drive");
  require(drive == "diff" || drive == "omni", "drive", "diff or omni", root["drive"]);
  model.drive = drive == "diff" ? DriveType::DIFF : DriveType::OMNI;
  const bool diff = model.drive == DriveType::DIFF;

  model.wheel_joints = textList(reader, root, "wheel_joints");
  const std::size_t wheels = diff ? 2 : 4;
  if (model.wheel_joints.size() != wheels)
    reader.fail("wheel_joints", "expected " + std::to_string(wheels) + " joint names for drive " + drive + ", got " +
                                    std::to_string(model.wheel_joints.size()));

  const YAML::Node limits = root["limits"];
  expectKeys(reader, limits, "limits",
             {"max_vel_x", "min_vel_x", "max_vel_y", "max_vel_theta", "acc_lim_x", "acc_lim_y", "acc_lim_theta"});
  Limits& lim = model.limits;
  lim.max_vel_x = number(reader, limits, "limits", "max_vel_x", "[m/s]");
  lim.min_vel_x = number(reader, limits, "limits", "min_vel_x", "[m/s]");
  lim.max_vel_y = number(reader, limits, "limits", "max_vel_y", "[m/s]");
  lim.max_vel_theta = number(reader, limits, "limits", "max_vel_theta", "[rad/s]");
  lim.acc_lim_x = number(reader, limits, "limits", "acc_lim_x", "[m/s^2]");
  lim.acc_lim_y = number(reader, limits, "limits", "acc_lim_y", "[m/s^2]");
  lim.acc_lim_theta = number(reader, limits, "limits", "acc_lim_theta", "[rad/s^2]");
  require(lim.max_vel_x > 0.0, "limits.max_vel_x", "> 0", limits["max_vel_x"]);
  require(lim.min_vel_x <= lim.max_vel_x, "limits.min_vel_x", "<= max_vel_x", limits["min_vel_x"]);
  require(lim.max_vel_theta > 0.0, "limits.max_vel_theta", "> 0", limits["max_vel_theta"]);
  require(lim.acc_lim_x > 0.0, "limits.acc_lim_x", "> 0", limits["acc_lim_x"]);
  require(lim.acc_lim_theta > 0.0, "limits.acc_lim_theta", "> 0", limits["acc_lim_theta"]);
  // A differential drive cannot move sideways: a non-zero value there is a copy-paste slip.
  const std::string sideways = diff ? "0 for drive diff" : "> 0 for drive omni";
  require(diff ? lim.max_vel_y == 0.0 : lim.max_vel_y > 0.0, "limits.max_vel_y", sideways, limits["max_vel_y"]);
  require(diff ? lim.acc_lim_y == 0.0 : lim.acc_lim_y > 0.0, "limits.acc_lim_y", sideways, limits["acc_lim_y"]);

  const YAML::Node laser = root["laser"];
  expectKeys(reader, laser, "laser", {"beams", "min_angle", "max_angle", "range_min", "range_max", "rate"});
  LaserSpec& spec = model.laser;
  spec.beams = integer(reader, laser, "laser", "beams");
  spec.min_angle = number(reader, laser, "laser", "min_angle", "[rad]");
  spec.max_angle = number(reader, laser, "laser", "max_angle", "[rad]");
  spec.range_min = number(reader, laser, "laser", "range_min", "[m]");
  spec.range_max = number(reader, laser, "laser", "range_max", "[m]");
  spec.rate = number(reader, laser, "laser", "rate", "[Hz]");
  require(spec.beams >= 1, "laser.beams", ">= 1", laser["beams"]);
  require(spec.max_angle > spec.min_angle, "laser.max_angle", "> min_angle", laser["max_angle"]);
  require(spec.max_angle - spec.min_angle <= 2.0 * kPi + kTolerance, "laser.max_angle", "max_angle - min_angle <= 2 pi",
          laser["max_angle"]);
  require(spec.range_min > 0.0, "laser.range_min", "> 0", laser["range_min"]);
  require(spec.range_max > spec.range_min, "laser.range_max", "> range_min", laser["range_max"]);
  require(spec.rate > 0.0, "laser.rate", "> 0", laser["rate"]);

  model.odom_rate = number(reader, root, "", "odom_rate", "[Hz]");
  model.ground_truth_rate = number(reader, root, "", "ground_truth_rate", "[Hz]");
  require(model.odom_rate > 0.0, "odom_rate", "> 0", root["odom_rate"]);
  require(model.ground_truth_rate > 0.0, "ground_truth_rate", "> 0", root["ground_truth_rate"]);
  return model;
}

// ---------------------------------------------------------------------------------------------
// Geometry (URDF)
// ---------------------------------------------------------------------------------------------

/// a * b: the pose b (given in frame a) expressed in a's parent frame.
urdf::Pose compose(const urdf::Pose& a, const urdf::Pose& b)
{
  // (urdfdom's Vector3::operator+ is not const, hence the spelled-out sum)
  urdf::Pose out;
  const urdf::Vector3 moved = a.rotation * b.position;
  out.position = urdf::Vector3(a.position.x + moved.x, a.position.y + moved.y, a.position.z + moved.z);
  out.rotation = a.rotation * b.rotation;
  out.rotation.normalize();
  return out;
}

/// Where a link frame sits in base_footprint.
struct LinkPose
{
  urdf::Pose pose;
  bool rigid = true;  ///< every joint between base_footprint and the link is fixed
};

/// A parsed URDF whose root is base_footprint, with errors that name the file.
class UrdfReader
{
public:
  explicit UrdfReader(std::string file) : file_(std::move(file))
  {
    const std::string xml = readFile(file_, "URDF");
    model_ = urdf::parseURDF(xml);
    if (!model_) throw ModelError(file_ + ": not a valid URDF (urdfdom's message is printed above)");
    const urdf::LinkConstSharedPtr root = model_->getRoot();
    if (!root || root->name != kRootLink)
      fail("root link", std::string("expected ") + kRootLink + ", got " + (root ? root->name : "none"));
  }

  [[noreturn]] void fail(const std::string& key, const std::string& message) const
  {
    throw ModelError(file_ + ": " + key + ": " + message);
  }

  const urdf::ModelInterface& model() const { return *model_; }
  const std::string& file() const { return file_; }

  urdf::LinkConstSharedPtr link(const std::string& name) const
  {
    urdf::LinkConstSharedPtr found = model_->getLink(name);
    if (!found) fail("link " + name, "missing; expected a link named " + name);
    return found;
  }

  /// Composes the joint origins from base_footprint down to the link; joints that move are
  /// taken at their zero position.
  LinkPose linkPose(const std::string& name) const
  {
    LinkPose out;
    urdf::LinkConstSharedPtr current = link(name);
    while (current->parent_joint)
    {
      const urdf::Joint& joint = *current->parent_joint;
      out.pose = compose(joint.parent_to_joint_origin_transform, out.pose);
      out.rigid = out.rigid && joint.type == urdf::Joint::FIXED;
      current = link(joint.parent_link_name);
    }
    return out;
  }

  /// The collision geometry of a link and its pose in base_footprint.
  std::pair<urdf::GeometrySharedPtr, urdf::Pose> collision(const std::string& name) const
  {
    const urdf::LinkConstSharedPtr found = link(name);
    if (!found->collision || !found->collision->geometry)
      fail("link " + name, "expected a <collision> with a geometry");
    return {found->collision->geometry, compose(linkPose(name).pose, found->collision->origin)};
  }

private:
  std::string file_;
  urdf::ModelInterfaceSharedPtr model_;
};

double yawOf(const urdf::Rotation& rotation)
{
  double roll = 0.0, pitch = 0.0, yaw = 0.0;
  rotation.getRPY(roll, pitch, yaw);
  return yaw;
}

bool isUpright(const urdf::Rotation& rotation)
{
  double roll = 0.0, pitch = 0.0, yaw = 0.0;
  rotation.getRPY(roll, pitch, yaw);
  return std::abs(roll) < kTolerance && std::abs(pitch) < kTolerance;
}

/// Footprint polygon (counter-clockwise) and circumscribed radius from base_link's collision:
/// an upright cylinder gives a 16-gon with its vertices on the circle, a box its rectangle.
void readFootprint(const UrdfReader& urdf, RobotModel& model)
{
  const auto [geometry, pose] = urdf.collision(kBodyLink);
  const std::string key = std::string("link ") + kBodyLink + " collision";
  if (!isUpright(pose.rotation)) urdf.fail(key, "expected an upright body (roll = pitch = 0) for a planar footprint");

  const double cx = pose.position.x;
  const double cy = pose.position.y;
  model.footprint.clear();
  if (geometry->type == urdf::Geometry::CYLINDER)
  {
    const double r = static_cast<const urdf::Cylinder&>(*geometry).radius;
    for (int i = 0; i < kCircleVertices; ++i)
    {
      const double angle = 2.0 * kPi * i / kCircleVertices;
      model.footprint.push_back({cx + r * std::cos(angle), cy + r * std::sin(angle)});
    }
    model.footprint_radius = std::hypot(cx, cy) + r;
  }
  else if (geometry->type == urdf::Geometry::BOX)
  {
    const urdf::Vector3& size = static_cast<const urdf::Box&>(*geometry).dim;
    const double hx = size.x / 2.0;
    const double hy = size.y / 2.0;
    const double yaw = yawOf(pose.rotation);
    const double c = std::cos(yaw), s = std::sin(yaw);
    const double corners[4][2] = {{hx, -hy}, {hx, hy}, {-hx, hy}, {-hx, -hy}};  // counter-clockwise
    model.footprint_radius = 0.0;
    for (const auto& corner : corners)
    {
      const Point2 p{cx + c * corner[0] - s * corner[1], cy + s * corner[0] + c * corner[1]};
      model.footprint.push_back(p);
      model.footprint_radius = std::max(model.footprint_radius, std::hypot(p.x, p.y));
    }
  }
  else
  {
    urdf.fail(key, "expected a cylinder or a box geometry");
  }
}

/// Wheel radius from the wheels' collision cylinders (or spheres); separation and wheel base
/// from where the wheel joints sit in base_footprint.
void readWheels(const UrdfReader& urdf, const std::string& config_path, RobotModel& model)
{
  double min_x = 0.0, max_x = 0.0, min_y = 0.0, max_y = 0.0;
  model.wheel_frames.clear();
  for (std::size_t i = 0; i < model.wheel_joints.size(); ++i)
  {
    const std::string& name = model.wheel_joints[i];
    const urdf::JointConstSharedPtr joint = urdf.model().getJoint(name);
    if (!joint)
      throw ModelError(config_path + ": wheel_joints[" + std::to_string(i) + "]: no joint named " + name + " in " +
                       urdf.file());
    if (joint->type != urdf::Joint::CONTINUOUS && joint->type != urdf::Joint::REVOLUTE)
      urdf.fail("joint " + name, "expected a continuous joint for a wheel");

    const auto [geometry, pose] = urdf.collision(joint->child_link_name);
    double radius = 0.0;
    if (geometry->type == urdf::Geometry::CYLINDER)
      radius = static_cast<const urdf::Cylinder&>(*geometry).radius;
    else if (geometry->type == urdf::Geometry::SPHERE)
      radius = static_cast<const urdf::Sphere&>(*geometry).radius;
    else
      urdf.fail("link " + joint->child_link_name + " collision", "expected a cylinder or a sphere wheel");
    if (i > 0 && std::abs(radius - model.wheel_radius) > kTolerance)
      urdf.fail("link " + joint->child_link_name + " collision", "expected the same radius as the other wheels (" +
                                                                     formatNumber(model.wheel_radius) + " m), got " +
                                                                     formatNumber(radius));
    model.wheel_radius = radius;

    WheelJointFrame frame;
    frame.parent = joint->parent_link_name;
    frame.child = joint->child_link_name;
    const urdf::Pose& origin = joint->parent_to_joint_origin_transform;
    frame.origin_xyz[0] = origin.position.x;
    frame.origin_xyz[1] = origin.position.y;
    frame.origin_xyz[2] = origin.position.z;
    origin.rotation.getQuaternion(frame.origin_q[0], frame.origin_q[1], frame.origin_q[2], frame.origin_q[3]);
    const double norm =
        std::sqrt(joint->axis.x * joint->axis.x + joint->axis.y * joint->axis.y + joint->axis.z * joint->axis.z);
    if (norm < kTolerance) urdf.fail("joint " + name + " axis", "expected a non-zero axis");
    frame.axis[0] = joint->axis.x / norm;
    frame.axis[1] = joint->axis.y / norm;
    frame.axis[2] = joint->axis.z / norm;
    model.wheel_frames.push_back(frame);

    // The wheel's axle is the joint frame, which is also the wheel link frame.
    const urdf::Vector3 axle = urdf.linkPose(joint->child_link_name).pose.position;
    if (std::abs(axle.z - radius) > kGroundTolerance)
      urdf.fail("joint " + name, "expected the axle at wheel-radius height " + formatNumber(radius) +
                                     " m so the wheel touches the ground, got z = " + formatNumber(axle.z));
    min_x = i == 0 ? axle.x : std::min(min_x, axle.x);
    max_x = i == 0 ? axle.x : std::max(max_x, axle.x);
    min_y = i == 0 ? axle.y : std::min(min_y, axle.y);
    max_y = i == 0 ? axle.y : std::max(max_y, axle.y);
  }
  model.wheel_separation = max_y - min_y;
  model.wheel_base = max_x - min_x;
  if (model.wheel_separation < kTolerance)
    throw ModelError(config_path +
                     ": wheel_joints: expected wheels on both sides (left and right), but they "
                     "all sit at y = " +
                     formatNumber(min_y));
}

/// The 3D lidar is optional (a model without lidar_link has none); it must be level, as the
/// simulator's 2.5D world has no roll or pitch.
void readLidarMount(const UrdfReader& urdf, RobotModel& model)
{
  const char* const link = "lidar_link";
  if (!urdf.model().getLink(link)) return;
  const LinkPose mount = urdf.linkPose(link);
  if (!mount.rigid) urdf.fail(std::string("link ") + link, "expected a chain of fixed joints from base_footprint");
  if (!isUpright(mount.pose.rotation))
    urdf.fail(std::string("link ") + link, "expected a level lidar (roll = pitch = 0)");
  model.lidar.present = true;
  model.lidar.x = mount.pose.position.x;
  model.lidar.y = mount.pose.position.y;
  model.lidar.z = mount.pose.position.z;
  model.lidar.yaw = yawOf(mount.pose.rotation);
}

/// The robot's height: the top of its highest collision box, cylinder or sphere (taken upright).
void readHeight(const UrdfReader& urdf, RobotModel& model)
{
  model.height = 0.0;
  for (const auto& item : urdf.model().links_)
  {
    if (!item.second->collision || !item.second->collision->geometry) continue;
    const auto [geometry, pose] = urdf.collision(item.first);
    double half = 0.0;
    if (geometry->type == urdf::Geometry::BOX)
      half = static_cast<const urdf::Box&>(*geometry).dim.z / 2.0;
    else if (geometry->type == urdf::Geometry::CYLINDER)
      half = static_cast<const urdf::Cylinder&>(*geometry).length / 2.0;
    else if (geometry->type == urdf::Geometry::SPHERE)
      half = static_cast<const urdf::Sphere&>(*geometry).radius;
    model.height = std::max(model.height, pose.position.z + half);
  }
}

void readLaserMount(const UrdfReader& urdf, RobotModel& model)
{
  const LinkPose mount = urdf.linkPose(kLaserLink);
  if (!mount.rigid)
    urdf.fail(std::string("link ") + kLaserLink, "expected a chain of fixed joints from base_footprint");
  if (!isUpright(mount.pose.rotation))
    urdf.fail(std::string("link ") + kLaserLink, "expected a level laser (roll = pitch = 0)");
  model.laser.mount_x = mount.pose.position.x;
  model.laser.mount_y = mount.pose.position.y;
  model.laser.mount_z = mount.pose.position.z;
  model.laser.mount_yaw = yawOf(mount.pose.rotation);
}

/// The IMU is optional (a model without imu_link has none); any fixed orientation is allowed.
void readImuMount(const UrdfReader& urdf, RobotModel& model)
{
  if (!urdf.model().getLink(kImuLink)) return;
  const LinkPose mount = urdf.linkPose(kImuLink);
  if (!mount.rigid) urdf.fail(std::string("link ") + kImuLink, "expected a chain of fixed joints from base_footprint");
  model.imu.present = true;
  model.imu.xyz[0] = mount.pose.position.x;
  model.imu.xyz[1] = mount.pose.position.y;
  model.imu.xyz[2] = mount.pose.position.z;
  mount.pose.rotation.getQuaternion(model.imu.q[0], model.imu.q[1], model.imu.q[2], model.imu.q[3]);
}

void readMass(const UrdfReader& urdf, RobotModel& model)
{
  model.mass = 0.0;
  for (const auto& item : urdf.model().links_)
    if (item.second->inertial) model.mass += item.second->inertial->mass;
  if (model.mass <= 0.0) urdf.fail("inertial", "expected links with a positive total <mass>");
}

}  // namespace

RobotModel loadRobotModelFiles(const std::string& urdf_path, const std::string& config_path)
{
  RobotModel model = readSettings(config_path);
  const UrdfReader urdf(urdf_path);
  model.name = urdf.model().getName();
  readLidarMount(urdf, model);
  readHeight(urdf, model);
  readFootprint(urdf, model);
  readWheels(urdf, config_path, model);
  readLaserMount(urdf, model);
  readImuMount(urdf, model);
  readMass(urdf, model);
  return model;
}

RobotModel loadRobotModel(const std::string& description_dir, const std::string& model)
{
  if (model.empty()) throw ModelError(description_dir + ": model: expected a model name such as mbot");
  RobotModel out =
      loadRobotModelFiles(description_dir + "/urdf/" + model + ".urdf", description_dir + "/config/" + model + ".yaml");
  out.name = model;
  return out;
}

}  // namespace mbot_description
