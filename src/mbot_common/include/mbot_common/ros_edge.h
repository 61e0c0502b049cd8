/**
 * @file ros_edge.h
 * @brief The ROS edge that every C++ node shares (map server, nav node, localization): strict
 *        private parameters, the robot's name and frames, and geometry_msgs <-> Pose2D.
 *
 * The one part of mbot_common that uses ROS, the C++ side of mbot_common.params. Like params.py
 * (which imports rospy on use) it is header-only, and mbot_common itself builds nothing with it
 * and depends on no ROS package: only a node that already depends on roscpp, geometry_msgs and
 * tf2 includes it. It lives here, not in a node package, so that the map server, the nav node
 * (mbot_navigation) and the localization nodes (mbot_localization) share it without depending
 * on each other.
 */
#pragma once

#include <cmath>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <ros/node_handle.h>
#include <ros/param.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2/utils.h>

#include "mbot_common/geometry.h"

namespace mbot_common
{
/// @brief Reads a node's private parameters strictly: a value of the wrong type is an error,
///        and checkNoUnknown() reports keys that no get*() call asked for (typos, amcl options
///        that this node does not have). Errors are std::runtime_error naming the parameter.
class StrictParams
{
public:
  explicit StrictParams(const ros::NodeHandle& private_nh) : nh_(private_nh) {}

  double getDouble(const std::string& key, double default_value)  ///< ints are accepted
  {
    XmlRpc::XmlRpcValue v;
    if (!lookUp(key, v)) return default_value;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(v);
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
    throw wrongType(key, "a number", v);
  }

  int getInt(const std::string& key, int default_value)
  {
    XmlRpc::XmlRpcValue v;
    if (!lookUp(key, v)) return default_value;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(v);
    throw wrongType(key, "an integer", v);
  }

  bool getBool(const std::string& key, bool default_value)
  {
    XmlRpc::XmlRpcValue v;
    if (!lookUp(key, v)) return default_value;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeBoolean) return static_cast<bool>(v);
    throw wrongType(key, "true or false", v);
  }

  std::string getString(const std::string& key, const std::string& default_value)
  {
    XmlRpc::XmlRpcValue v;
    if (!lookUp(key, v)) return default_value;
    if (v.getType() == XmlRpc::XmlRpcValue::TypeString) return static_cast<std::string>(v);
    throw wrongType(key, "a string", v);
  }

  /// @throws std::runtime_error listing every private parameter that was never read
  void checkNoUnknown() const
  {
    std::vector<std::string> names;
    if (!ros::param::getParamNames(names)) return;  // no master: nothing to check against
    const std::string prefix = nh_.getNamespace() + "/";
    std::string unknown;
    for (const std::string& name : names)
    {
      if (name.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string key = name.substr(prefix.size(), name.find('/', prefix.size()) - prefix.size());
      if (known_.count(key) == 0 && unknown.find(" " + key + ",") == std::string::npos) unknown += " " + key + ",";
    }
    if (unknown.empty()) return;
    std::string known;
    for (const std::string& k : known_) known += (known.empty() ? "" : ", ") + k;
    unknown.pop_back();
    throw std::runtime_error("unknown parameter(s) under " + nh_.getNamespace() + ":" + unknown +
                             " (this node reads: " + known + ")");
  }

  /// @brief Count `key` as read, e.g. a sub-namespace that another StrictParams reads (and
  ///        checks) on its own. (Added for the nav node's ~global_costmap/ and friends.)
  void markKnown(const std::string& key) { known_.insert(key); }

private:
  /// Marks `key` as read; false when it is not set.
  bool lookUp(const std::string& key, XmlRpc::XmlRpcValue& v)
  {
    known_.insert(key);
    return nh_.getParam(key, v);
  }

  std::runtime_error wrongType(const std::string& key, const std::string& expected, const XmlRpc::XmlRpcValue& v) const
  {
    return std::runtime_error("parameter " + nh_.resolveName(key) + ": expected " + expected + ", got " + typeName(v));
  }

  static const char* typeName(const XmlRpc::XmlRpcValue& v)
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

  ros::NodeHandle nh_;
  std::set<std::string> known_;
};

/// @brief The robot's name from `~robot`, or else from the node's namespace ("/robot_0" ->
///        "robot_0"; "" in the root namespace).
inline std::string robotName(StrictParams& params, const ros::NodeHandle& nh)
{
  std::string ns = nh.getNamespace();  // "/robot_0" or "/"
  while (!ns.empty() && ns.front() == '/') ns.erase(0, 1);
  return params.getString("robot", ns);
}

/// @brief "robot_0" + "odom" -> "robot_0/odom"; no prefix for an empty robot name.
inline std::string prefixedFrame(const std::string& robot, const std::string& frame)
{
  return robot.empty() ? frame : robot + "/" + frame;
}

// ---- geometry_msgs <-> Pose2D. tf2::getYaw (not yawOf) so that a zero quaternion, as in a
// goal whose orientation was never set, still reads as yaw 0 as it always did.

inline Pose2D toPose2D(const geometry_msgs::Pose& pose)
{
  return Pose2D{pose.position.x, pose.position.y, tf2::getYaw(pose.orientation)};
}

inline Pose2D toPose2D(const geometry_msgs::Transform& transform)
{
  return Pose2D{transform.translation.x, transform.translation.y, tf2::getYaw(transform.rotation)};
}

inline geometry_msgs::Quaternion yawToQuaternionMsg(double yaw)
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

inline geometry_msgs::Pose toPoseMsg(const Pose2D& pose)
{
  geometry_msgs::Pose out;
  out.position.x = pose.x;
  out.position.y = pose.y;
  out.orientation = yawToQuaternionMsg(pose.theta);
  return out;
}

inline geometry_msgs::Transform toTransformMsg(const Pose2D& pose)
{
  geometry_msgs::Transform out;
  out.translation.x = pose.x;
  out.translation.y = pose.y;
  out.rotation = yawToQuaternionMsg(pose.theta);
  return out;
}

}  // namespace mbot_common
