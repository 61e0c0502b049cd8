/**
 * @file stage_ros_internal.h
 * @brief (private to stage_node) What the stage_ros*.cpp files share besides the class.
 */
#pragma once

#include <geometry_msgs/Quaternion.h>
#include <mbot_common/geometry.h>

#include <array>

namespace mbot_sim
{
inline geometry_msgs::Quaternion yawToQuaternion(double yaw)
{
  const std::array<double, 4> xyzw = mbot_common::quaternionFromYaw(yaw);
  geometry_msgs::Quaternion q;
  q.x = xyzw[0];
  q.y = xyzw[1];
  q.z = xyzw[2];
  q.w = xyzw[3];
  return q;
}

}  // namespace mbot_sim
