/**
 * @file localization_ros.h
 * @brief The ROS edge of the map server and the localization nodes: strict parameter reading
 *        and conversions between messages and the ROS-free cores.
 */
#pragma once

#include <set>
#include <string>

#include <geometry_msgs/Pose.h>
#include <geometry_msgs/Transform.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/node_handle.h>
#include <sensor_msgs/LaserScan.h>

#include "mbot_navigation/likelihood_field.h"
#include "mbot_navigation/localization_math.h"
#include "mbot_navigation/localization_models.h"

namespace mbot_navigation
{
namespace localization
{
/// @brief Reads a node's private parameters strictly: a value of the wrong type is an error,
///        and checkNoUnknown() reports keys that no get*() call asked for (typos, amcl options
///        that this node does not have). Errors are std::runtime_error naming the parameter.
class StrictParams
{
public:
  explicit StrictParams(const ros::NodeHandle& private_nh) : nh_(private_nh) {}

  double getDouble(const std::string& key, double default_value);  ///< ints are accepted
  int getInt(const std::string& key, int default_value);
  bool getBool(const std::string& key, bool default_value);
  std::string getString(const std::string& key, const std::string& default_value);

  /// @throws std::runtime_error listing every private parameter that was never read
  void checkNoUnknown() const;

  /// @brief Count `key` as read, e.g. a sub-namespace that another StrictParams reads (and
  ///        checks) on its own. (Added for the nav node's ~global_costmap/ and friends.)
  void markKnown(const std::string& key) { known_.insert(key); }

private:
  std::string fullName(const std::string& key) const { return nh_.resolveName(key); }

  ros::NodeHandle nh_;
  std::set<std::string> known_;
};

/// @brief The robot's name from `~robot`, or else from the node's namespace ("/robot_0" ->
///        "robot_0"; "" in the root namespace).
std::string robotName(StrictParams& params, const ros::NodeHandle& nh);

/// @brief "robot_0" + "odom" -> "robot_0/odom"; no prefix for an empty robot name.
std::string prefixedFrame(const std::string& robot, const std::string& frame);

Pose2D toPose2D(const geometry_msgs::Pose& pose);
Pose2D toPose2D(const geometry_msgs::Transform& transform);
geometry_msgs::Pose toPoseMsg(const Pose2D& pose);
geometry_msgs::Transform toTransformMsg(const Pose2D& pose);

LaserScanData toLaserScanData(const sensor_msgs::LaserScan& scan);

/// @throws std::runtime_error for a grid whose data does not match its size or whose origin is
///         rotated (not supported by the localization)
OccupancyGridData toOccupancyGridData(const nav_msgs::OccupancyGrid& grid);

}  // namespace localization
}  // namespace mbot_navigation
