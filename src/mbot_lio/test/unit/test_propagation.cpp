// IMU forward propagation against closed-form motion, covariance growth against the noise
// densities, and backward deskewing of a frame taken while turning and driving.
#include <gtest/gtest.h>

#include "mbot_lio/propagation.h"
#include "mbot_lio/so3.h"
#include "synthetic_room.h"

using namespace mbot_lio;
using mbot_lio_test::Pose;

namespace
{
const Eigen::Vector3d kGravity(0.0, 0.0, -9.80665);

std::vector<ImuSample> sampleImu(const mbot_lio_test::Motion& m, double t0, double t1, double rate)
{
  std::vector<ImuSample> out;
  const long n = std::lround((t1 - t0) * rate);
  for (long k = 0; k <= n; ++k) out.push_back(mbot_lio_test::trueImu(m, t0 + k / rate, kGravity));
  return out;
}
}  // namespace

// Constant body rate w and constant world acceleration a: R(t) = R0 Exp(w t),
// p(t) = p0 + v0 t + a t^2 / 2, v(t) = v0 + a t. The IMU reads w and R(t)^T (a - g) exactly.
TEST(Propagation, ConstantRateMatchesClosedForm)
{
  const Eigen::Vector3d w(0.3, -0.2, 1.0), a(0.5, -0.3, 0.2), v0(1.0, 0.0, 0.0), p0(1.0, 2.0, 0.3);
  const Eigen::Matrix3d R0 = expSO3(Eigen::Vector3d(0.1, 0.2, 0.3));
  std::vector<ImuSample> imu;
  for (int k = 0; k <= 200; ++k)
  {
    ImuSample s;
    s.t = k * 0.005;
    s.gyro = w;
    s.acc = (R0 * expSO3(w * s.t)).transpose() * (a - kGravity);
    imu.push_back(s);
  }
  State x;
  x.R = R0;
  x.p = p0;
  x.v = v0;
  Cov P = Cov::Identity() * 1e-6;
  const auto segs = propagate(x, P, 0.0, 1.0, imu, ImuNoise(), kGravity);
  EXPECT_EQ(segs.size(), 200u);
  EXPECT_LT(logSO3((R0 * expSO3(w)).transpose() * x.R).norm(), 1e-9);
  EXPECT_LT((x.p - (p0 + v0 + 0.5 * a)).norm(), 1e-4);
  EXPECT_LT((x.v - (v0 + a)).norm(), 2e-4);
  // the segments' poses between samples follow the same closed form
  Eigen::Matrix3d R_t;
  Eigen::Vector3d p_t;
  segs[77].poseAt(0.3871, R_t, p_t);
  EXPECT_LT(logSO3((R0 * expSO3(w * 0.3871)).transpose() * R_t).norm(), 1e-9);
  EXPECT_LT((p_t - (p0 + v0 * 0.3871 + 0.5 * a * 0.3871 * 0.3871)).norm(), 1e-4);
}

// A bias shifts the estimate as it must: a gyro bias b not in the state turns the estimate by b T.
TEST(Propagation, UnmodelledGyroBiasTurnsTheEstimate)
{
  std::vector<ImuSample> imu;
  for (int k = 0; k <= 200; ++k)
  {
    ImuSample s;
    s.t = k * 0.005;
    s.gyro = Eigen::Vector3d(0, 0, 0.01);
    s.acc = -kGravity;
    imu.push_back(s);
  }
  State x;
  Cov P = Cov::Zero();
  propagate(x, P, 0.0, 1.0, imu, ImuNoise(), kGravity);
  EXPECT_NEAR(logSO3(x.R).z(), 0.01, 1e-12);
  EXPECT_LT(x.p.norm(), 1e-12);
  x = State();
  x.bg = Eigen::Vector3d(0, 0, 0.01);  // the same bias in the state cancels it
  propagate(x, P, 0.0, 1.0, imu, ImuNoise(), kGravity);
  EXPECT_LT(logSO3(x.R).norm(), 1e-12);
}

// White noise only, at rest: yaw variance N_g^2 T, vertical velocity N_a^2 T, vertical
// position N_a^2 T^3 / 3 (integrated white noise), from a zero start covariance.
TEST(Propagation, CovarianceGrowsWithTheNoiseDensities)
{
  ImuNoise n;
  n.gyro_noise_density = 1e-3;
  n.accel_noise_density = 1e-2;
  n.gyro_random_walk = 0.0;
  n.accel_random_walk = 0.0;
  std::vector<ImuSample> imu;
  for (int k = 0; k <= 400; ++k)
  {
    ImuSample s;
    s.t = k * 0.005;
    s.acc = -kGravity;
    imu.push_back(s);
  }
  State x;
  Cov P = Cov::Zero();
  const double T = 2.0;
  propagate(x, P, 0.0, T, imu, n, kGravity);
  EXPECT_NEAR(P(kRot + 2, kRot + 2), 1e-6 * T, 1e-6 * T * 0.01);
  EXPECT_NEAR(P(kVel + 2, kVel + 2), 1e-4 * T, 1e-4 * T * 0.01);
  EXPECT_NEAR(P(kPos + 2, kPos + 2), 1e-4 * T * T * T / 3.0, 1e-4 * T * T * T / 3.0 * 0.02);
  // tilt noise leaks into horizontal velocity through gravity: larger than the accelerometer's alone
  EXPECT_GT(P(kVel, kVel), 1e-4 * T * 1.01);
}

// Past the last sample the last input is held; before the first, the first.
TEST(Propagation, HoldsTheInputOutsideTheSamples)
{
  std::vector<ImuSample> imu(2);
  imu[0].t = 0.1;
  imu[1].t = 0.2;
  for (auto& s : imu)
  {
    s.gyro = Eigen::Vector3d(0, 0, 1.0);
    s.acc = -kGravity + Eigen::Vector3d(1.0, 0, 0);
  }
  State x;
  Cov P = Cov::Zero();
  const auto segs = propagate(x, P, 0.0, 0.3, imu, ImuNoise(), kGravity);
  ASSERT_EQ(segs.size(), 3u);
  EXPECT_NEAR(segs[1].t0, 0.1, 1e-12);
  EXPECT_NEAR(logSO3(x.R).z(), 0.3, 1e-12);
}

// A frame taken while turning at 2 rad/s and driving 1.1 m/s: each point moved to the frame's end
// time lies on the room's surfaces; the same points placed with the end pose alone do not.
TEST(Deskew, TurningFrameRecoversTheWalls)
{
  const mbot_lio_test::Room room;
  const mbot_lio_test::Motion motion = [](double t) {
    return mbot_lio_test::levelPose(-1.0 + 1.0 * t, 0.5 * t, 0.3, 0.4 + 2.0 * t);
  };
  const Eigen::Matrix3d R_il = expSO3(Eigen::Vector3d(0.0, 0.05, 0.1));
  const Eigen::Vector3d p_il(0.05, 0.0, 0.2);
  std::mt19937 rng(1);
  const double stamp = 1.0;
  const auto frame = mbot_lio_test::makeFrame(room, motion, R_il, p_il, stamp, 0.1, 5000, 0, 0.0, rng);
  ASSERT_GT(frame.points.size(), 2000u);  // rays above the walls give no return

  const Pose start = motion(stamp);
  State x;
  x.R = start.R;
  x.p = start.p;
  x.v = Eigen::Vector3d(1.0, 0.5, 0.0);
  Cov P = Cov::Zero();
  const double t_end = stamp + frame.times.back();
  const auto segs = propagate(x, P, stamp, t_end, sampleImu(motion, 0.9, 1.2, 200.0), ImuNoise(), kGravity);
  const Pose end = motion(t_end);
  EXPECT_LT((x.p - end.p).norm(), 1e-4);
  EXPECT_LT(logSO3(end.R.transpose() * x.R).norm(), 1e-6);

  Deskewer deskew(segs, x.R, x.p);
  double worst = 0.0, worst_naive = 0.0;
  for (size_t i = 0; i < frame.points.size(); ++i)
  {
    const Eigen::Vector3d q = R_il * frame.points[i] + p_il;  // in the IMU frame at the point's time
    const Eigen::Vector3d at_end = deskew.toEnd(q, stamp + frame.times[i]);
    worst = std::max(worst, room.distance(x.R * at_end + x.p));
    worst_naive = std::max(worst_naive, room.distance(x.R * q + x.p));
  }
  EXPECT_LT(worst, 1e-3);
  EXPECT_GT(worst_naive, 0.3);  // 0.2 rad of turn over a frame: metres at the far walls
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
