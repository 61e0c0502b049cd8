// The synthetic scene of the tests and the benchmark: a 2.5D room (floor z = 0, four walls 2.5 m
// high, no ceiling), a Mid-360-like scan pattern, rays cast analytically, and IMU readings from a
// smooth motion by central differences.
#pragma once

#include <Eigen/Core>
#include <cmath>
#include <functional>
#include <random>
#include <vector>

#include "mbot_lio/propagation.h"
#include "mbot_lio/so3.h"

namespace mbot_lio_test
{
struct Pose
{
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
};
using Motion = std::function<Pose(double)>;  // the IMU frame's pose in the world at time t

struct Room
{
  double x0 = -5.0, x1 = 5.0, y0 = -4.0, y1 = 4.0, height = 2.5;

  // Ray from o (inside) along unit d: the hit on the floor or a wall; false if the ray leaves
  // over the walls (no return, as in the simulator's world without ceiling).
  bool cast(const Eigen::Vector3d& o, const Eigen::Vector3d& d, Eigen::Vector3d& hit) const
  {
    double t = 1e9;
    if (d.x() > 1e-12) t = std::min(t, (x1 - o.x()) / d.x());
    if (d.x() < -1e-12) t = std::min(t, (x0 - o.x()) / d.x());
    if (d.y() > 1e-12) t = std::min(t, (y1 - o.y()) / d.y());
    if (d.y() < -1e-12) t = std::min(t, (y0 - o.y()) / d.y());
    if (d.z() < -1e-12) t = std::min(t, -o.z() / d.z());
    hit = o + t * d;
    return hit.z() <= height;
  }
  // distance of a point near the surfaces to the closest of them
  double distance(const Eigen::Vector3d& q) const
  {
    double best = std::abs(q.z());
    for (double w : {q.x() - x0, q.x() - x1, q.y() - y0, q.y() - y1}) best = std::min(best, std::abs(w));
    return best;
  }
};

// A frame as a sensor gives it: points in the lidar frame, each with its time after the stamp.
struct SynthFrame
{
  double stamp = 0.0;
  std::vector<Eigen::Vector3d> points;
  std::vector<double> times;
};

// Point i of n in frame number f: a low-discrepancy pattern over 360 deg x [-7, 52] deg elevation.
inline Eigen::Vector3d patternDirection(long i, long n, long f)
{
  const double u = std::fmod((i + f * n) * 0.6180339887498949, 1.0);
  const double w = std::fmod((i + f * n) * 0.7548776662466927, 1.0);
  const double az = 2.0 * M_PI * u;
  const double el = (-7.0 + 59.0 * w) * M_PI / 180.0;
  return Eigen::Vector3d(std::cos(el) * std::cos(az), std::cos(el) * std::sin(az), std::sin(el));
}

// A frame of n points over [stamp, stamp + period), each cast from the lidar's pose at its time
// (IMU pose from motion, then the mount imu_T_lidar); range noise sd range_sd.
inline SynthFrame makeFrame(const Room& room, const Motion& motion, const Eigen::Matrix3d& R_il,
                            const Eigen::Vector3d& p_il, double stamp, double period, long n, long frame_index,
                            double range_sd, std::mt19937& rng)
{
  std::normal_distribution<double> noise(0.0, 1.0);
  SynthFrame f;
  f.stamp = stamp;
  for (long i = 0; i < n; ++i)
  {
    const double dt = period * double(i) / double(n);
    const Pose imu = motion(stamp + dt);
    const Eigen::Matrix3d R_wl = imu.R * R_il;
    const Eigen::Vector3d o = imu.R * p_il + imu.p;
    const Eigen::Vector3d d_l = patternDirection(i, n, frame_index);
    Eigen::Vector3d hit;
    if (!room.cast(o, R_wl * d_l, hit)) continue;
    const double r = (hit - o).norm() + (range_sd > 0 ? range_sd * noise(rng) : 0.0);
    f.points.push_back(d_l * r);
    f.times.push_back(dt);
  }
  return f;
}

// The IMU's true reading at t: body rate and specific force R^T (a - g), by central differences.
inline mbot_lio::ImuSample trueImu(const Motion& motion, double t, const Eigen::Vector3d& gravity)
{
  const double h = 1e-4;
  const Pose a = motion(t - h), b = motion(t), c = motion(t + h);
  mbot_lio::ImuSample s;
  s.t = t;
  s.gyro = mbot_lio::logSO3(a.R.transpose() * c.R) / (2.0 * h);
  const Eigen::Vector3d acc_world = (c.p - 2.0 * b.p + a.p) / (h * h);
  s.acc = b.R.transpose() * (acc_world - gravity);
  return s;
}

// A level robot's IMU pose: position (x, y, z) and yaw.
inline Pose levelPose(double x, double y, double z, double yaw)
{
  Pose p;
  p.R = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.p = Eigen::Vector3d(x, y, z);
  return p;
}
}  // namespace mbot_lio_test
