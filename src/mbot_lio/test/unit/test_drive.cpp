// End to end: a robot drives 20 s around the synthetic room (1 m/s on a 2 m circle, yaw swinging
// about the heading), its IMU read from the true motion with white noise and constant biases the
// estimator does not know, its lidar frames cast from the room at each point's time.
#include <gtest/gtest.h>

#include <cstdio>

#include "mbot_lio/estimator.h"
#include "mbot_lio/so3.h"
#include "synthetic_room.h"

using namespace mbot_lio;
using mbot_lio_test::Pose;

namespace
{
const Eigen::Vector3d kGravity(0.0, 0.0, -9.80665);

Pose circle(double t)
{
  const double r = 2.0, w = 0.5;
  return mbot_lio_test::levelPose(r * std::cos(w * t), r * std::sin(w * t), 0.09,
                                  w * t + M_PI / 2 + 0.5 * std::sin(0.7 * t));
}
}  // namespace

TEST(Drive, LoopInTheRoomStaysWithinTheDriftBound)
{
  const mbot_lio_test::Room room;
  const mbot_lio_test::Motion motion = circle;
  const Eigen::Matrix3d R_il = Eigen::Matrix3d::Identity();
  const Eigen::Vector3d p_il(0.0, 0.0, 0.17);  // mbot_omni: IMU at z 0.09, lidar at 0.26
  Options opt;
  opt.imu_p_lidar = p_il;
  Estimator est(opt);
  State x0;
  const Pose start = circle(0.0);
  x0.R = start.R;
  x0.p = start.p;
  x0.v = Eigen::Vector3d(0.0, 1.0, 0.0);
  est.initialize(0.0, x0);

  std::mt19937 rng(11);
  std::normal_distribution<double> n01(0.0, 1.0);
  const double rate = 200.0;
  const Eigen::Vector3d bg(0.003, -0.002, 0.004), ba(0.03, -0.02, 0.04);
  const double sg = opt.imu.gyro_noise_density * std::sqrt(rate), sa = opt.imu.accel_noise_density * std::sqrt(rate);
  long k_imu = 0;
  double max_err = 0.0, max_ang = 0.0, dead_reckoning_err = 0.0;
  int max_ang_frame = 0;
  State dr = x0;  // IMU alone, for comparison
  Cov dr_P = Cov::Zero();
  std::vector<ImuSample> all_imu;
  const int frames = 200;
  for (int f = 0; f < frames; ++f)
  {
    const double stamp = 0.1 * f;
    while (k_imu / rate <= stamp + 0.105)
    {
      ImuSample s = mbot_lio_test::trueImu(motion, k_imu / rate, kGravity);
      for (int a = 0; a < 3; ++a)
      {
        s.gyro[a] += bg[a] + sg * n01(rng);
        s.acc[a] += ba[a] + sa * n01(rng);
      }
      est.addImu(s);
      all_imu.push_back(s);
      ++k_imu;
    }
    const auto synth = mbot_lio_test::makeFrame(room, motion, R_il, p_il, stamp, 0.1, 4000, f, 0.02, rng);
    LidarFrame frame;
    frame.stamp = stamp;
    for (size_t i = 0; i < synth.points.size(); ++i)
    {
      frame.points.push_back(synth.points[i].cast<float>());
      frame.times.push_back(float(synth.times[i]));
    }
    const FrameReport rep = est.addFrame(frame);
    if (f > 0) EXPECT_TRUE(rep.updated) << "frame " << f;
    const Pose truth = circle(rep.t_end);
    max_err = std::max(max_err, (est.state().p - truth.p).norm());
    const double ang = logSO3(truth.R.transpose() * est.state().R).norm() * 180.0 / M_PI;
    if (ang > max_ang) max_ang_frame = f;
    max_ang = std::max(max_ang, ang);
  }
  const double t_end = est.time();
  propagate(dr, dr_P, 0.0, t_end, all_imu, opt.imu, kGravity);
  dead_reckoning_err = (dr.p - circle(t_end).p).norm();
  const Pose truth = circle(t_end);
  const double final_err = (est.state().p - truth.p).norm();
  const double final_ang = logSO3(truth.R.transpose() * est.state().R).norm() * 180.0 / M_PI;
  std::printf(
      "drive: 20 m in %.1f s, position error max %.4f m, final %.4f m, attitude error max %.3f deg "
      "(frame %d), final %.3f deg; gyro bias z %.5f (true %.5f); IMU alone %.2f m\n",
      t_end, max_err, final_err, max_ang, max_ang_frame, final_ang, est.state().bg.z(), bg.z(), dead_reckoning_err);
  EXPECT_LT(max_err, 0.05);
  EXPECT_LT(max_ang, 1.0);
  EXPECT_NEAR(est.state().bg.z(), bg.z(), 1e-3);  // the yaw-rate bias is observed through the walls
  EXPECT_GT(dead_reckoning_err, 1.0);             // without the lidar the biases take it metres away
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
