// IMU forward propagation and backward deskewing (FAST-LIO, Xu & Zhang 2021, Sec. III-C; FAST-LIO2,
// Xu et al. 2022, Sec. IV). README "Equations" maps each equation to these functions.
#pragma once

#include <Eigen/Core>
#include <vector>

namespace mbot_lio
{
// One IMU reading: angular rate [rad/s] and specific force [m/s^2] (gravity included, +g on z at
// rest), both in the IMU frame, at time t [s].
struct ImuSample
{
  double t = 0.0;
  Eigen::Vector3d gyro = Eigen::Vector3d::Zero();
  Eigen::Vector3d acc = Eigen::Vector3d::Zero();
};

// Noise densities in the units of the simulator's world file (noise.imu, Allan variance terms).
struct ImuNoise
{
  double gyro_noise_density = 2.6e-4;   // [rad/s/sqrt(Hz)]
  double gyro_random_walk = 2.0e-5;     // [rad/s^2/sqrt(Hz)]
  double accel_noise_density = 2.3e-3;  // [m/s^2/sqrt(Hz)]
  double accel_random_walk = 4.0e-4;    // [m/s^3/sqrt(Hz)]
};

// The state x = (R, p, v, b_g, b_a) of the IMU frame in the world frame. Gravity is fixed (known
// magnitude and direction: the world's -z), not estimated as FAST-LIO does, because the robots start
// level at a known pose.
struct State
{
  Eigen::Matrix3d R = Eigen::Matrix3d::Identity();
  Eigen::Vector3d p = Eigen::Vector3d::Zero();
  Eigen::Vector3d v = Eigen::Vector3d::Zero();
  Eigen::Vector3d bg = Eigen::Vector3d::Zero();
  Eigen::Vector3d ba = Eigen::Vector3d::Zero();
};

// Error state dx = (dtheta, dp, dv, dbg, dba), R = R_hat Exp(dtheta) (right perturbation).
constexpr int kDim = 15;
using Cov = Eigen::Matrix<double, kDim, kDim>;
using ErrorVec = Eigen::Matrix<double, kDim, 1>;
enum : int
{
  kRot = 0,
  kPos = 3,
  kVel = 6,
  kBg = 9,
  kBa = 12
};

// x boxplus dx and x boxminus y (the manifold's operations).
State boxplus(const State& x, const ErrorVec& dx);
ErrorVec boxminus(const State& x, const State& y);

// One interval of constant input [t0, t0 + dt]: the state at its start and the bias-corrected rate
// and world acceleration (gravity added) held over it. Deskewing reads poses inside it.
struct Segment
{
  double t0 = 0.0;
  double dt = 0.0;
  Eigen::Matrix3d R;
  Eigen::Vector3d p, v;
  Eigen::Vector3d omega;    // w_m - b_g, IMU frame
  Eigen::Vector3d a_world;  // R_mid (a_m - b_a) + g
  // pose at t in [t0, t0 + dt]
  void poseAt(double t, Eigen::Matrix3d& R_t, Eigen::Vector3d& p_t) const;
};

// One discrete propagation step (FAST-LIO eq. (3), (7)-(8)): x <- f(x, u, dt), P <- F P F^T + Q.
// gyro, acc: the interval's input (mean of the two bounding samples).
Segment propagateStep(State& x, Cov& P, const Eigen::Vector3d& gyro, const Eigen::Vector3d& acc, double t0, double dt,
                      const ImuNoise& noise, const Eigen::Vector3d& gravity);

// Propagates x, P from t_state to t_end over the samples (sorted by time); the input of an interval
// between samples k and k + 1 is their mean; before the first sample the first, after the last the
// last is held. Returns the segments (empty when t_end <= t_state).
std::vector<Segment> propagate(State& x, Cov& P, double t_state, double t_end, const std::vector<ImuSample>& imu,
                               const ImuNoise& noise, const Eigen::Vector3d& gravity);

// Backward propagation (FAST-LIO eq. (10)-(11)): a point measured at time t in the IMU frame of that
// moment, p_I(t), moved to the IMU frame at t_end: R_e^T (R(t) p_I(t) + p(t) - p_e).
// segments must cover t; times outside are clamped to the first/last segment.
class Deskewer
{
public:
  Deskewer(const std::vector<Segment>& segments, const Eigen::Matrix3d& R_end, const Eigen::Vector3d& p_end);
  Eigen::Vector3d toEnd(const Eigen::Vector3d& p_imu, double t) const;

private:
  const std::vector<Segment>& segs_;
  Eigen::Matrix3d Rt_end_;
  Eigen::Vector3d p_end_;
};
}  // namespace mbot_lio
