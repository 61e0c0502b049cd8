/**
 * @file geometry.h
 * @brief Planar geometry shared by every package: Pose2D {x [m], y [m], theta [rad]},
 *        Twist2D {vx [m/s], vy [m/s], wz [rad/s]}, angle wrapping to (-pi, pi], the yaw of a
 *        quaternion, and SE(2) pose algebra. Header-only, free of ROS types (the Python twin is
 *        mbot_common.geometry).
 *
 * A Pose2D is read as the transform "child in parent" (the pose of a robot in the map is the
 * transform map -> robot). Then `compose(a, b)` is a (+) b: b given in a's frame, expressed in
 * a's parent frame, exactly like tf's `T_parent_child = T_parent_mid * T_mid_child`;
 * `relative(a, b)` = inverse(a) (+) b is b seen from a.
 */
#pragma once

#include <array>
#include <cmath>

namespace mbot_common
{
constexpr double kPi = 3.14159265358979323846;

/// @brief A planar pose: position [m] and heading [rad] (counter-clockwise from the x axis).
struct Pose2D
{
  double x = 0.0;      ///< [m]
  double y = 0.0;      ///< [m]
  double theta = 0.0;  ///< [rad]
};

/// @brief A planar velocity in the body frame (geometry_msgs/Twist linear.x, linear.y, angular.z).
struct Twist2D
{
  double vx = 0.0;  ///< forward [m/s]
  double vy = 0.0;  ///< to the left [m/s] (0 for a diff-drive robot)
  double wz = 0.0;  ///< counter-clockwise [rad/s]
};

/// @brief A point in a plane [m].
struct Point2D
{
  double x = 0.0;  ///< [m]
  double y = 0.0;  ///< [m]
};

/// @brief The angle a [rad] wrapped to (-pi, pi]; NaN for inf or NaN (no direction).
inline double normalizeAngle(double a)
{
  a = std::remainder(a, 2.0 * kPi);  // in [-pi, pi]
  return a <= -kPi ? a + 2.0 * kPi : a;
}

/// @brief The smallest signed difference a - b [rad], in (-pi, pi].
inline double angleDiff(double a, double b) { return normalizeAngle(a - b); }

/// @brief The yaw [rad] (rotation about z, in (-pi, pi]) of the quaternion (qx, qy, qz, qw).
///        It need not be unit length (the formula is scale-free); the zero quaternion has no
///        orientation and gives NaN.
inline double yawOf(double qx, double qy, double qz, double qw)
{
  if (qx == 0.0 && qy == 0.0 && qz == 0.0 && qw == 0.0) return std::nan("");
  // Yaw of the ZYX Euler angles; w^2 + x^2 - y^2 - z^2 = 1 - 2 (y^2 + z^2) for a unit quaternion.
  return normalizeAngle(std::atan2(2.0 * (qw * qz + qx * qy), qw * qw + qx * qx - qy * qy - qz * qz));
}

/// @brief The unit quaternion {x, y, z, w} of a rotation by yaw [rad] about z.
inline std::array<double, 4> quaternionFromYaw(double yaw)
{
  return {0.0, 0.0, std::sin(0.5 * yaw), std::cos(0.5 * yaw)};
}

/// @brief a (+) b: pose b, given in a's frame, expressed in a's parent frame.
inline Pose2D compose(const Pose2D& a, const Pose2D& b)
{
  const double c = std::cos(a.theta), s = std::sin(a.theta);
  return Pose2D{a.x + c * b.x - s * b.y, a.y + s * b.x + c * b.y, normalizeAngle(a.theta + b.theta)};
}

/// @brief The inverse transform of p: p's parent frame expressed in p's frame.
inline Pose2D inverse(const Pose2D& p)
{
  const double c = std::cos(p.theta), s = std::sin(p.theta);
  return Pose2D{-c * p.x - s * p.y, s * p.x - c * p.y, normalizeAngle(-p.theta)};
}

/// @brief The pose of b expressed in a's frame (both given in one frame): inverse(a) (+) b.
inline Pose2D relative(const Pose2D& a, const Pose2D& b) { return compose(inverse(a), b); }

/// @brief The point (x, y) [m], given in pose's frame, expressed in pose's parent frame.
inline Point2D transformPoint(const Pose2D& pose, double x, double y)
{
  const double c = std::cos(pose.theta), s = std::sin(pose.theta);
  return Point2D{pose.x + c * x - s * y, pose.y + s * x + c * y};
}

}  // namespace mbot_common
