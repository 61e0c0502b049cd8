#include "mbot_lio/propagation.h"

#include <algorithm>

#include "mbot_lio/so3.h"

namespace mbot_lio
{
State boxplus(const State& x, const ErrorVec& dx)
{
  State y;
  y.R = x.R * expSO3(dx.segment<3>(kRot));
  y.p = x.p + dx.segment<3>(kPos);
  y.v = x.v + dx.segment<3>(kVel);
  y.bg = x.bg + dx.segment<3>(kBg);
  y.ba = x.ba + dx.segment<3>(kBa);
  return y;
}

ErrorVec boxminus(const State& x, const State& y)
{
  ErrorVec d;
  d.segment<3>(kRot) = logSO3(y.R.transpose() * x.R);
  d.segment<3>(kPos) = x.p - y.p;
  d.segment<3>(kVel) = x.v - y.v;
  d.segment<3>(kBg) = x.bg - y.bg;
  d.segment<3>(kBa) = x.ba - y.ba;
  return d;
}

void Segment::poseAt(double t, Eigen::Matrix3d& R_t, Eigen::Vector3d& p_t) const
{
  const double tau = t - t0;
  R_t = R * expSO3(omega * tau);
  p_t = p + v * tau + 0.5 * a_world * tau * tau;
}

Segment propagateStep(State& x, Cov& P, const Eigen::Vector3d& gyro, const Eigen::Vector3d& acc, double t0, double dt,
                      const ImuNoise& noise, const Eigen::Vector3d& gravity)
{
  Segment s;
  s.t0 = t0;
  s.dt = dt;
  s.R = x.R;
  s.p = x.p;
  s.v = x.v;
  s.omega = gyro - x.bg;
  const Eigen::Vector3d a_body = acc - x.ba;
  // The specific force rotated by the mid-interval attitude: second order in w * dt, so a constant
  // rate with a constant world acceleration integrates without a first-order error.
  const Eigen::Matrix3d R_mid = x.R * expSO3(0.5 * s.omega * dt);
  s.a_world = R_mid * a_body + gravity;

  // x_{i+1} = x_i boxplus (dt f(x_i, u_i)), FAST-LIO eq. (3) with the position's second-order term
  x.R = x.R * expSO3(s.omega * dt);
  x.p = x.p + x.v * dt + 0.5 * s.a_world * dt * dt;
  x.v = x.v + s.a_world * dt;

  // P_{i+1} = F_x P_i F_x^T + F_w Q F_w^T, FAST-LIO eq. (8); F_x of the error state (Jr(w dt) ~ I)
  Cov F = Cov::Identity();
  const Eigen::Matrix3d I3 = Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d Ra = R_mid * skew(a_body);
  F.block<3, 3>(kRot, kRot) = expSO3(-s.omega * dt);
  F.block<3, 3>(kRot, kBg) = -I3 * dt;
  F.block<3, 3>(kPos, kVel) = I3 * dt;
  F.block<3, 3>(kPos, kRot) = -0.5 * Ra * dt * dt;
  F.block<3, 3>(kPos, kBa) = -0.5 * R_mid * dt * dt;
  F.block<3, 3>(kVel, kRot) = -Ra * dt;
  F.block<3, 3>(kVel, kBa) = -R_mid * dt;
  P = F * P * F.transpose();
  // white noise integrated over dt: variance density^2 * dt (the sample sd is density * sqrt(rate))
  const double ng = noise.gyro_noise_density, na = noise.accel_noise_density;
  const double kg = noise.gyro_random_walk, ka = noise.accel_random_walk;
  P.block<3, 3>(kRot, kRot).diagonal().array() += ng * ng * dt;
  P.block<3, 3>(kVel, kVel).diagonal().array() += na * na * dt;
  P.block<3, 3>(kBg, kBg).diagonal().array() += kg * kg * dt;
  P.block<3, 3>(kBa, kBa).diagonal().array() += ka * ka * dt;
  return s;
}

std::vector<Segment> propagate(State& x, Cov& P, double t_state, double t_end, const std::vector<ImuSample>& imu,
                               const ImuNoise& noise, const Eigen::Vector3d& gravity)
{
  std::vector<Segment> segs;
  if (imu.empty()) return segs;
  const size_t n = imu.size();
  double t = t_state;
  // k: the last sample at or before t (n = none yet)
  size_t k =
      std::upper_bound(imu.begin(), imu.end(), t, [](double a, const ImuSample& s) { return a < s.t; }) - imu.begin();
  k = (k == 0) ? n : k - 1;
  while (t < t_end - 1e-12)
  {
    double next = t_end;
    Eigen::Vector3d gyro, acc;
    if (k == n)  // before the first sample: hold it
    {
      next = std::min(imu[0].t, t_end);
      gyro = imu[0].gyro;
      acc = imu[0].acc;
    }
    else if (k + 1 == n)  // after the last: hold it
    {
      gyro = imu[k].gyro;
      acc = imu[k].acc;
    }
    else
    {
      next = std::min(imu[k + 1].t, t_end);
      gyro = 0.5 * (imu[k].gyro + imu[k + 1].gyro);
      acc = 0.5 * (imu[k].acc + imu[k + 1].acc);
    }
    if (next > t) segs.push_back(propagateStep(x, P, gyro, acc, t, next - t, noise, gravity));
    t = next;
    k = (k == n) ? 0 : k + 1;
  }
  return segs;
}

Deskewer::Deskewer(const std::vector<Segment>& segments, const Eigen::Matrix3d& R_end, const Eigen::Vector3d& p_end)
    : segs_(segments), Rt_end_(R_end.transpose()), p_end_(p_end)
{}

Eigen::Vector3d Deskewer::toEnd(const Eigen::Vector3d& p_imu, double t) const
{
  if (segs_.empty()) return p_imu;
  auto it = std::upper_bound(segs_.begin(), segs_.end(), t, [](double a, const Segment& s) { return a < s.t0; });
  const Segment& s = (it == segs_.begin()) ? segs_.front() : *(it - 1);
  Eigen::Matrix3d R_t;
  Eigen::Vector3d p_t;
  s.poseAt(std::max(t, s.t0), R_t, p_t);
  return Rt_end_ * (R_t * p_imu + p_t - p_end_);
}
}  // namespace mbot_lio
