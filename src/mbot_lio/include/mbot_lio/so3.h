// SO(3) helpers: hat, Exp and Log (the manifold operations of FAST-LIO's state, Xu & Zhang 2021, Sec. III).
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cmath>

namespace mbot_lio
{
// [v]x, the matrix of the cross product v x .
inline Eigen::Matrix3d skew(const Eigen::Vector3d& v)
{
  Eigen::Matrix3d m;
  m << 0, -v.z(), v.y(), v.z(), 0, -v.x(), -v.y(), v.x(), 0;
  return m;
}

// Exp: rotation vector -> rotation matrix (Rodrigues).
inline Eigen::Matrix3d expSO3(const Eigen::Vector3d& w)
{
  const double a = w.norm();
  if (a < 1e-12) return Eigen::Matrix3d::Identity() + skew(w);
  return Eigen::AngleAxisd(a, w / a).toRotationMatrix();
}

// Log: rotation matrix -> rotation vector (angle < pi).
inline Eigen::Vector3d logSO3(const Eigen::Matrix3d& R)
{
  const Eigen::AngleAxisd aa(R);
  return aa.angle() * aa.axis();
}
}  // namespace mbot_lio
