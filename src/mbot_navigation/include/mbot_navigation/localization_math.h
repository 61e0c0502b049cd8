/**
 * @file localization_math.h
 * @brief Planar pose algebra used by localization: angles, composition and inversion of
 *        SE(2) poses, and the pose-with-covariance that a localizer reports. Free of ROS types.
 *
 * A Pose2D {x, y, theta} is read as the transform "child in parent": `compose(a, b)` is "a then b"
 * (b expressed in a's frame), exactly like tf's `T_parent_child = T_parent_mid * T_mid_child`.
 */
#pragma once

#include <array>
#include <cmath>

#include "mbot_navigation/costmap_2d.h"  // Pose2D, shared by the whole package

namespace mbot_navigation
{
namespace localization
{
/// @brief Wrap an angle [rad] to (-pi, pi].
inline double normalizeAngle(double a)
{
  a = std::remainder(a, 2.0 * M_PI);  // in [-pi, pi]
  return a <= -M_PI ? a + 2.0 * M_PI : a;
}

/// @brief Smallest signed difference a - b [rad], in (-pi, pi].
inline double angleDiff(double a, double b) { return normalizeAngle(a - b); }

/// @brief a * b: pose b (given in a's frame) expressed in a's parent frame.
inline Pose2D compose(const Pose2D& a, const Pose2D& b)
{
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  Pose2D out;
  out.x = a.x + c * b.x - s * b.y;
  out.y = a.y + s * b.x + c * b.y;
  out.theta = normalizeAngle(a.theta + b.theta);
  return out;
}

/// @brief inverse(a): the parent frame expressed in a's frame.
inline Pose2D invert(const Pose2D& a)
{
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  Pose2D out;
  out.x = -c * a.x - s * a.y;
  out.y = s * a.x - c * a.y;
  out.theta = normalizeAngle(-a.theta);
  return out;
}

/// @brief The map -> odom correction that makes odom_base land on map_base:
///        T_map_odom = T_map_base * inverse(T_odom_base).
inline Pose2D mapToOdom(const Pose2D& map_base, const Pose2D& odom_base)
{
  return compose(map_base, invert(odom_base));
}

/// @brief A pose estimate with its 3x3 covariance over (x [m], y [m], theta [rad]), row-major.
struct PoseWithCovariance
{
  Pose2D pose;
  std::array<double, 9> covariance{};  ///< [m^2, m^2, rad^2 on the diagonal]
};

}  // namespace localization
}  // namespace mbot_navigation
