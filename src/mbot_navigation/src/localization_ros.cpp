#include "mbot_navigation/localization_ros.h"

#include <cmath>
#include <stdexcept>
#include <vector>

#include <ros/param.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2/utils.h>

namespace mbot_navigation
{
namespace localization
{
namespace
{
const char* typeName(const XmlRpc::XmlRpcValue& v)
{
  switch (v.getType())
  {
    case XmlRpc::XmlRpcValue::TypeBoolean: return "a bool";
    case XmlRpc::XmlRpcValue::TypeInt: return "an integer";
    case XmlRpc::XmlRpcValue::TypeDouble: return "a number";
    case XmlRpc::XmlRpcValue::TypeString: return "a string";
    case XmlRpc::XmlRpcValue::TypeArray: return "a list";
    case XmlRpc::XmlRpcValue::TypeStruct: return "a dictionary";
    default: return "an unsupported value";
  }
}
}  // namespace

double StrictParams::getDouble(const std::string& key, double default_value)
{
  known_.insert(key);
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return default_value;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(v);
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
  throw std::runtime_error("parameter " + fullName(key) + ": expected a number, got " + typeName(v));
}

int StrictParams::getInt(const std::string& key, int default_value)
{
  known_.insert(key);
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return default_value;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
  throw std::runtime_error("parameter " + fullName(key) + ": expected an integer, got " + typeName(v));
}

bool StrictParams::getBool(const std::string& key, bool default_value)
{
  known_.insert(key);
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return default_value;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) return static_cast<bool>(v);
  throw std::runtime_error("parameter " + fullName(key) + ": expected true or false, got " + typeName(v));
}

std::string StrictParams::getString(const std::string& key, const std::string& default_value)
{
  known_.insert(key);
  XmlRpc::XmlRpcValue v;
  if (!nh_.getParam(key, v)) return default_value;
  if (v.getType() == XmlRpc::XmlRpcValue::TypeString) return static_cast<std::string>(v);
  throw std::runtime_error("parameter " + fullName(key) + ": expected a string, got " + typeName(v));
}

void StrictParams::checkNoUnknown() const
{
  std::vector<std::string> names;
  if (!ros::param::getParamNames(names)) return;  // no master: nothing to check against
  const std::string prefix = nh_.getNamespace() + "/";
  std::string unknown;
  for (const std::string& name : names)
  {
    if (name.compare(0, prefix.size(), prefix) != 0) continue;
    const std::string key = name.substr(prefix.size(), name.find('/', prefix.size()) - prefix.size());
    if (known_.count(key) == 0 && unknown.find(" " + key + ",") == std::string::npos)
      unknown += " " + key + ",";
  }
  if (unknown.empty()) return;
  std::string known;
  for (const std::string& k : known_) known += (known.empty() ? "" : ", ") + k;
  unknown.pop_back();
  throw std::runtime_error("unknown parameter(s) under " + nh_.getNamespace() + ":" + unknown +
                           " (this node reads: " + known + ")");
}

std::string robotName(StrictParams& params, const ros::NodeHandle& nh)
{
  std::string ns = nh.getNamespace();  // "/robot_0" or "/"
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  return params.getString("robot", ns);
}

std::string prefixedFrame(const std::string& robot, const std::string& frame)
{
  return robot.empty() ? frame : robot + "/" + frame;
}

Pose2D toPose2D(const geometry_msgs::Pose& pose)
{
  Pose2D p;
  p.x = pose.position.x;
  p.y = pose.position.y;
  p.theta = tf2::getYaw(pose.orientation);
  return p;
}

Pose2D toPose2D(const geometry_msgs::Transform& transform)
{
  Pose2D p;
  p.x = transform.translation.x;
  p.y = transform.translation.y;
  p.theta = tf2::getYaw(transform.rotation);
  return p;
}

namespace
{
geometry_msgs::Quaternion yawToQuaternion(double yaw)
{
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, yaw);
  geometry_msgs::Quaternion out;
  out.x = q.x();
  out.y = q.y();
  out.z = q.z();
  out.w = q.w();
  return out;
}
}  // namespace

geometry_msgs::Pose toPoseMsg(const Pose2D& pose)
{
  geometry_msgs::Pose out;
  out.position.x = pose.x;
  out.position.y = pose.y;
  out.orientation = yawToQuaternion(pose.theta);
  return out;
}

geometry_msgs::Transform toTransformMsg(const Pose2D& pose)
{
  geometry_msgs::Transform out;
  out.translation.x = pose.x;
  out.translation.y = pose.y;
  out.rotation = yawToQuaternion(pose.theta);
  return out;
}

LaserScanData toLaserScanData(const sensor_msgs::LaserScan& scan)
{
  LaserScanData out;
  out.ranges = scan.ranges;
  out.angle_min = scan.angle_min;
  out.angle_increment = scan.angle_increment;
  out.range_min = scan.range_min;
  out.range_max = scan.range_max;
  return out;
}

OccupancyGridData toOccupancyGridData(const nav_msgs::OccupancyGrid& grid)
{
  OccupancyGridData out;
  out.width = grid.info.width;
  out.height = grid.info.height;
  out.resolution = grid.info.resolution;
  out.origin_x = grid.info.origin.position.x;
  out.origin_y = grid.info.origin.position.y;
  if (grid.data.size() != static_cast<size_t>(out.width) * out.height)
    throw std::runtime_error("map: " + std::to_string(out.width) + " x " + std::to_string(out.height) +
                             " cells but " + std::to_string(grid.data.size()) + " values");
  if (std::fabs(tf2::getYaw(grid.info.origin.orientation)) > 1e-6)
    throw std::runtime_error("map: a rotated origin (yaw " +
                             std::to_string(tf2::getYaw(grid.info.origin.orientation)) +
                             " rad) is not supported; rotate the image instead");
  out.data = grid.data;
  return out;
}

}  // namespace localization
}  // namespace mbot_navigation
