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
/// Lockstep: zero cmd_vels in a row that must find the robot at rest, each soon after the command
/// before, before its controller counts as holding it still (and is waited for like a driving one).
/// move_base sends one or two when a goal ends or is cancelled (the stop, then its idle cycle) and
/// then nothing; a follower controller that holds its robot still sends one every cycle.
constexpr int kHoldingZeros = 3;
/// [s wall] "soon" for those zeros while sim time runs free (nothing holds it, so many periods of
/// sim time pass between two cycles of a controller); generous for a starved controller, short
/// beside move_base's goals.
constexpr double kHoldingWallGap = 0.5;

/// [s sim] /stage/applied_commands: one message per this much sim time, for all robots together.
constexpr double kAppliedCommandsPeriod = 0.1;

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
