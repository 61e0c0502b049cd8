/**
 * @file odometry.cpp
 * @brief Wheel odometry, sensor noise and the measurement faults (drift, dropout, latency).
 *        See odometry.h.
 */
#include "odometry.h"

#include "drive.h"

#include <algorithm>
#include <cmath>

namespace mbot_sim
{
namespace detail
{
using mbot_common::normalizeAngle;
using mbot_description::DriveType;

void integrateOdometry(Robot& r, const NoiseConfig& noise, double dt)
{
  Twist2D m = r.velocity;
  if (r.model.drive == DriveType::DIFF) m.vy = 0.0;

  const double wheel_r = r.model.wheel_radius;
  for (size_t i = 0; i < r.wheel_mounts.size(); ++i)
  {
    const double rolling = wheelRollingSpeed(r.model.drive, r.wheel_mounts[i], m);
    const double speed = wheel_r > 0.0 ? rolling / wheel_r : 0.0;
    r.joints.velocity[i] = speed;
    r.joints.position[i] = normalizeAngle(r.joints.position[i] + speed * dt);
  }

  const bool moving = std::abs(m.vx) + std::abs(m.vy) + std::abs(m.wz) > 1e-9;
  if (moving)  // encoders of standing wheels do not tick: no noise at rest
  {
    if (noise.odom_linear > 0.0)
    {
      m.vx += noise.odom_linear * r.gauss(r.rng);
      if (r.model.drive == DriveType::OMNI) m.vy += noise.odom_linear * r.gauss(r.rng);
    }
    if (noise.odom_angular > 0.0) m.wz += noise.odom_angular * r.gauss(r.rng);
  }
  m.wz += r.faults.odom_drift;

  const double yaw_mid = r.odom.theta + 0.5 * m.wz * dt;
  const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
  r.odom.x += (c * m.vx - s * m.vy) * dt;
  r.odom.y += (s * m.vx + c * m.vy) * dt;
  r.odom.theta = normalizeAngle(r.odom.theta + m.wz * dt);
  r.odom_twist = m;
}

void addLaserNoise(Robot& r, const NoiseConfig& noise)
{
  const double sigma = noise.laser_range;
  const double dropout = r.faults.laser_dropout;
  if (sigma <= 0.0 && dropout <= 0.0) return;
  const auto& laser = r.model.laser;
  const float inf = std::numeric_limits<float>::infinity();
  const float invalid = std::numeric_limits<float>::quiet_NaN();
  for (float& range : r.scan.ranges)
  {
    // A dropped beam measured nothing: NaN (REP-117 "invalid"), not +Inf, which would claim
    // that nothing is in range and make costmaps clear real obstacles.
    if (dropout > 0.0 && r.uniform(r.rng) < dropout)
    {
      range = invalid;
      continue;
    }
    if (sigma > 0.0 && std::isfinite(range))
    {
      const double noisy = range + sigma * r.gauss(r.rng);
      if (noisy > laser.range_max)
        range = inf;
      else if (noisy < laser.range_min)
        range = -inf;
      else
        range = static_cast<float>(noisy);
    }
  }
}

bool delayed(const Robot& r) { return r.faults.sensor_latency > 0.0 || r.faults.sensor_jitter > 0.0; }

double releaseTime(Robot& r, double now)
{
  const FaultConfig& f = r.faults;
  double release = now + f.sensor_latency;
  if (f.sensor_jitter > 0.0) release += std::abs(f.sensor_jitter * r.gauss(r.rng));
  release = std::max(release, r.last_release);
  r.last_release = release;
  return release;
}

}  // namespace detail
}  // namespace mbot_sim
