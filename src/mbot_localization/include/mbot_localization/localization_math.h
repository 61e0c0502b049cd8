/**
 * @file localization_math.h
 * @brief Planar pose algebra used by localization: mbot_common's angles and SE(2) composition
 *        and inversion, the map -> odom correction, and the pose-with-covariance that a localizer
 *        reports. Free of ROS types.
 *
 * A Pose2D {x, y, theta} is read as the transform "child in parent": `compose(a, b)` is "a then b"
 * (b expressed in a's frame), exactly like tf's `T_parent_child = T_parent_mid * T_mid_child`.
 */
#pragma once

#include <array>

#include <mbot_common/geometry.h>

namespace mbot_localization
{
using mbot_common::angleDiff;       // smallest signed difference a - b [rad], in (-pi, pi]
using mbot_common::compose;         // a * b: pose b (given in a's frame) in a's parent frame
using mbot_common::inverse;         // the parent frame expressed in a's frame
using mbot_common::normalizeAngle;  // wrap to (-pi, pi]
using mbot_common::Pose2D;          // {x, y, theta} [m, m, rad]

/// @brief The map -> odom correction that makes odom_base land on map_base:
///        T_map_odom = T_map_base * inverse(T_odom_base).
inline Pose2D mapToOdom(const Pose2D& map_base, const Pose2D& odom_base)
{
  return compose(map_base, inverse(odom_base));
}

/// @brief A pose estimate with its 3x3 covariance over (x [m], y [m], theta [rad]), row-major.
struct PoseWithCovariance
{
  Pose2D pose;
  std::array<double, 9> covariance{};  ///< [m^2, m^2, rad^2 on the diagonal]
};

}  // namespace mbot_localization
