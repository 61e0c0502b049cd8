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

#include <algorithm>
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
/// @brief What checkNoUnknown() does with a key that nobody read.
enum class UnknownKeys
{
  ERROR,  ///< stop the node (the localization nodes, the map server: a typo is never missed)
  WARN,   ///< warn and go on, as move_base does (the nav node: a drop-in for move_base)
};

/// @brief Levenshtein distance: single-character insertions, deletions and substitutions.
inline size_t editDistance(const std::string& a, const std::string& b)
{
  std::vector<size_t> row(b.size() + 1);
  for (size_t j = 0; j <= b.size(); ++j) row[j] = j;
  for (size_t i = 1; i <= a.size(); ++i)
  {
    size_t diagonal = row[0];  // the distance of a[0, i-1) to b[0, j-1)
    row[0] = i;
    for (size_t j = 1; j <= b.size(); ++j)
    {
      const size_t substitute = diagonal + (a[i - 1] == b[j - 1] ? 0 : 1);
      diagonal = row[j];
      row[j] = std::min({row[j] + 1, row[j - 1] + 1, substitute});
    }
  }
  return row[b.size()];
}

/// @brief The word of `words` nearest to `word` by edit distance ("" when `words` is empty).
inline std::string nearestWord(const std::string& word, const std::set<std::string>& words)
{
  std::string best;
  size_t best_distance = 0;
  for (const std::string& w : words)
  {
    const size_t d = editDistance(word, w);
    if (best.empty() || d < best_distance)
    {
      best = w;
      best_distance = d;
    }
  }
  return best;
}

/// @brief Reads a node's private parameters strictly: a value of the wrong type is an error,
///        and checkNoUnknown() reports keys that no get*() call asked for (typos, amcl options
///        that this node does not have), as an error or as warnings (UnknownKeys). Errors are
///        std::runtime_error naming the parameter.
class StrictParams
{
public:
  explicit StrictParams(const ros::NodeHandle& private_nh, UnknownKeys unknown = UnknownKeys::ERROR)
      : nh_(private_nh), unknown_mode_(unknown)
  {}

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

  /**
   * @brief Report the private parameters that were never read (nor marked known).
   * @return with UnknownKeys::WARN, one line per such key, naming the nearest known key:
   *         "unknown parameter /ns/max_vel_xx (ignored; did you mean max_vel_x?)"
   * @throws std::runtime_error listing them all, with UnknownKeys::ERROR
   */
  std::vector<std::string> checkNoUnknown() const
  {
    std::vector<std::string> names;
    if (!ros::param::getParamNames(names)) return {};  // no master: nothing to check against
    const std::string prefix = nh_.getNamespace() + "/";
    std::vector<std::string> unknown_keys;
    for (const std::string& name : names)
    {
      if (name.compare(0, prefix.size(), prefix) != 0) continue;
      const std::string key = name.substr(prefix.size(), name.find('/', prefix.size()) - prefix.size());
      if (known_.count(key) == 0 && std::find(unknown_keys.begin(), unknown_keys.end(), key) == unknown_keys.end())
        unknown_keys.push_back(key);
    }
    std::vector<std::string> warnings;
    if (unknown_keys.empty()) return warnings;
    if (unknown_mode_ == UnknownKeys::WARN)
    {
      for (const std::string& key : unknown_keys)
      {
        const std::string nearest = nearestWord(key, known_);
        warnings.push_back("unknown parameter " + prefix + key + " (ignored" +
                           (nearest.empty() ? std::string() : "; did you mean " + nearest + "?") + ")");
      }
      return warnings;
    }
    std::string unknown, known;
    for (const std::string& k : unknown_keys) unknown += " " + k + ",";
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
  UnknownKeys unknown_mode_;
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
