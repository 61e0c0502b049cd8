/**
 * @file imu.h
 * @brief (private to the world) Each robot's IMU: the true angular rate and specific force at
 *        its mount (URDF imu_link) from the body's planar motion, and the error model real IMUs
 *        are described by (Allan variance): per axis a start bias, a bias random walk, white
 *        noise and quantization. Its random draws come from its own generator, so an IMU that
 *        measures (or not) never changes the other sensors' noise.
 */
#pragma once

#include "mbot_sim/world.h"

#include <array>
#include <deque>
#include <memory>
#include <random>
#include <utility>

namespace mbot_sim
{
namespace detail
{
constexpr double kGravity = 9.80665;  // [m/s^2] standard gravity

/// The error model of one IMU (gyro and accelerometer, three axes each), discretised at the
/// IMU's sample period: white sample sigma = density * sqrt(rate), bias step sigma = random
/// walk * sqrt(dt); the start bias is drawn once (bias instability as a spread of turn-on biases).
class ImuErrors
{
public:
  /// Seeded by the world's seed and the robot id, a stream apart from the robot's other noise.
  ImuErrors(const ImuNoiseConfig& config, unsigned world_seed, int robot);

  /// One sample: the bias walks one sample period, then white noise and quantization.
  void apply(const std::array<double, 3>& gyro, const std::array<double, 3>& accel, ImuSample& out);
  /// The bias walks over `dt` [s] without a sample (an IMU nobody listened to).
  void walk(double dt);

  const std::array<double, 3>& gyroBias() const { return gyro_bias_; }
  const std::array<double, 3>& accelBias() const { return accel_bias_; }
  const ImuNoiseConfig& config() const { return config_; }
  double period() const { return 1.0 / config_.rate; }
  double gauss() { return gauss_(rng_); }  ///< for the latency fault's jitter

private:
  ImuNoiseConfig config_;
  std::mt19937 rng_;
  std::normal_distribution<double> gauss_{0.0, 1.0};
  std::array<double, 3> gyro_bias_{};
  std::array<double, 3> accel_bias_{};
};

/// Where an IMU sits on its robot (from the URDF) and what it measures without errors.
struct ImuMountFrame
{
  std::array<double, 3> offset{};  ///< imu_link origin in base_footprint [m]
  /// Rotation imu_link -> base_footprint (rows: base axes); a reading in the IMU frame is R^T v.
  std::array<std::array<double, 3>, 3> rotation{{{1.0, 0.0, 0.0}, {0.0, 1.0, 0.0}, {0.0, 0.0, 1.0}}};

  explicit ImuMountFrame(const mbot_description::ImuMount& mount = {});

  /// True angular rate [rad/s] and specific force [m/s^2] in the IMU frame for a planar body
  /// with robot-frame velocity (vx, vy), yaw rate wz, their time derivatives (ax_dot, ay_dot:
  /// dv/dt in the robot frame; alpha: dwz/dt).
  void measure(const Twist2D& v, double dvx, double dvy, double alpha, std::array<double, 3>& gyro,
               std::array<double, 3>& accel) const;
};

/// A robot's IMU: mount, errors, timer and the motion of the step before (for the derivatives).
struct ImuState
{
  bool present = false;  ///< the robot's URDF has an imu_link
  ImuMountFrame mount;
  std::unique_ptr<ImuErrors> errors;
  double start = 0.0;                                ///< [s] the timer's grid: measurements at start + k * period
  long long k = 1;                                   ///< the next measurement's index
  double bias_time = 0.0;                            ///< [s] the bias has walked up to this time
  Twist2D last_velocity;                             ///< robot-frame velocity after the step before
  double last_time = -1.0;                           ///< [s] time of that step (< 0: none yet, e.g. after a teleport)
  double last_release = 0.0;                         ///< [s] latency fault: samples leave in order
  std::deque<std::pair<double, ImuSample>> pending;  ///< (release time, sample) held by a latency fault
};

}  // namespace detail
}  // namespace mbot_sim
