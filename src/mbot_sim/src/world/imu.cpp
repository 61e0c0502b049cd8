/**
 * @file imu.cpp
 * @brief The IMU's kinematics at its mount and its error model. See imu.h.
 */
#include "imu.h"

#include <cmath>

namespace mbot_sim
{
namespace detail
{
namespace
{
double quantize(double value, double step) { return step > 0.0 ? step * std::round(value / step) : value; }
}  // namespace

ImuErrors::ImuErrors(const ImuNoiseConfig& config, unsigned world_seed, int robot) : config_(config)
{
  std::seed_seq seq{world_seed, static_cast<unsigned>(robot), 0x494d55u};  // "IMU"
  rng_.seed(seq);
  for (int i = 0; i < 3; ++i) gyro_bias_[i] = config_.gyro_bias_init * gauss_(rng_);
  for (int i = 0; i < 3; ++i) accel_bias_[i] = config_.accel_bias_init * gauss_(rng_);
}

void ImuErrors::walk(double dt)
{
  if (!(dt > 0.0)) return;
  const double g = config_.gyro_random_walk * std::sqrt(dt);
  const double a = config_.accel_random_walk * std::sqrt(dt);
  // A random walk over dt in one draw has the same distribution as in many small steps.
  for (int i = 0; i < 3; ++i)
    if (g > 0.0) gyro_bias_[i] += g * gauss_(rng_);
  for (int i = 0; i < 3; ++i)
    if (a > 0.0) accel_bias_[i] += a * gauss_(rng_);
}

void ImuErrors::apply(const std::array<double, 3>& gyro, const std::array<double, 3>& accel, ImuSample& out)
{
  walk(period());
  const double root_rate = std::sqrt(config_.rate);
  const double g_white = config_.gyro_noise_density * root_rate;
  const double a_white = config_.accel_noise_density * root_rate;
  for (int i = 0; i < 3; ++i)
  {
    double w = gyro[i] + gyro_bias_[i];
    if (g_white > 0.0) w += g_white * gauss_(rng_);
    out.angular_velocity[i] = quantize(w, config_.gyro_quantization);
  }
  for (int i = 0; i < 3; ++i)
  {
    double f = accel[i] + accel_bias_[i];
    if (a_white > 0.0) f += a_white * gauss_(rng_);
    out.linear_acceleration[i] = quantize(f, config_.accel_quantization);
  }
}

ImuMountFrame::ImuMountFrame(const mbot_description::ImuMount& mount)
{
  for (int i = 0; i < 3; ++i) offset[i] = mount.xyz[i];
  double x = mount.q[0], y = mount.q[1], z = mount.q[2], w = mount.q[3];
  const double n = std::sqrt(x * x + y * y + z * z + w * w);
  if (n > 0.0)
  {
    x /= n;
    y /= n;
    z /= n;
    w /= n;
  }
  rotation = {{{1 - 2 * (y * y + z * z), 2 * (x * y - z * w), 2 * (x * z + y * w)},
               {2 * (x * y + z * w), 1 - 2 * (x * x + z * z), 2 * (y * z - x * w)},
               {2 * (x * z - y * w), 2 * (y * z + x * w), 1 - 2 * (x * x + y * y)}}};
}

void ImuMountFrame::measure(const Twist2D& v, double dvx, double dvy, double alpha, std::array<double, 3>& gyro,
                            std::array<double, 3>& accel) const
{
  // Acceleration of the robot frame's origin, in the (rotating) robot frame: dv/dt + w x v.
  const double w = v.wz;
  double ax = dvx - w * v.vy;
  double ay = dvy + w * v.vx;
  // At the mount offset p: + alpha x p (tangential) + w x (w x p) (centripetal).
  const double px = offset[0], py = offset[1];
  ax += -alpha * py - w * w * px;
  ay += alpha * px - w * w * py;
  // Specific force = acceleration - gravity; gravity is -g along z, so at rest it reads +g up.
  const std::array<double, 3> f{ax, ay, kGravity};
  const std::array<double, 3> rate{0.0, 0.0, w};
  for (int i = 0; i < 3; ++i)
  {
    gyro[i] = rotation[0][i] * rate[0] + rotation[1][i] * rate[1] + rotation[2][i] * rate[2];
    accel[i] = rotation[0][i] * f[0] + rotation[1][i] * f[1] + rotation[2][i] * f[2];
  }
}

}  // namespace detail
}  // namespace mbot_sim
