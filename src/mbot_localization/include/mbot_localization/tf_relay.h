/**
 * @file tf_relay.h
 * @brief The rule of the fleet tf relay (fleet_tf_relay_node.cpp), without ROS types: which
 *        robot a transform of /tf belongs to.
 */
#pragma once

#include <algorithm>
#include <string>
#include <vector>

namespace mbot_localization
{
/// The robot whose pose a transform places, from its child frame: "robot_3/base_footprint" ->
/// "robot_3" when the frame's own name ("base_footprint") is one of `frames`. "" for any other
/// transform: a frame without a prefix, a nested prefix, or a frame not in `frames` (a wheel).
inline std::string robotOfTransform(const std::string& child_frame, const std::vector<std::string>& frames)
{
  const std::string frame = !child_frame.empty() && child_frame[0] == '/' ? child_frame.substr(1) : child_frame;
  const std::size_t slash = frame.find('/');
  if (slash == std::string::npos || slash == 0 || frame.find('/', slash + 1) != std::string::npos) return "";
  if (std::find(frames.begin(), frames.end(), frame.substr(slash + 1)) == frames.end()) return "";
  return frame.substr(0, slash);
}

}  // namespace mbot_localization
