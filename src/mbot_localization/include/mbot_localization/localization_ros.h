/**
 * @file localization_ros.h
 * @brief The ROS edge of the localization nodes: conversions between messages (scans, maps) and
 *        the ROS-free cores, plus the shared node helpers of mbot_common/ros_edge.h.
 */
#pragma once

#include <mbot_common/ros_edge.h>
#include <nav_msgs/OccupancyGrid.h>
#include <sensor_msgs/LaserScan.h>

#include "mbot_localization/likelihood_field.h"
#include "mbot_localization/localization_math.h"
#include "mbot_localization/localization_models.h"

namespace mbot_localization
{
// Strict parameters, the robot's name and frames, and the pose conversions are shared with the
// map server and the nav node (mbot_common/ros_edge.h); the nodes here use them unqualified.
using mbot_common::prefixedFrame;
using mbot_common::robotName;
using mbot_common::StrictParams;
using mbot_common::toPose2D;
using mbot_common::toPoseMsg;
using mbot_common::toTransformMsg;

LaserScanData toLaserScanData(const sensor_msgs::LaserScan& scan);

/// @throws std::runtime_error for a grid whose data does not match its size or whose origin is
///         rotated (not supported by the localization)
OccupancyGridData toOccupancyGridData(const nav_msgs::OccupancyGrid& grid);

}  // namespace mbot_localization
