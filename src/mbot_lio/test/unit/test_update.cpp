// The iterated point-to-plane update on a synthetic room, and the estimator's answers to bad input.
#include <gtest/gtest.h>

#include <algorithm>

#include "mbot_lio/estimator.h"
#include "mbot_lio/so3.h"
#include "synthetic_room.h"

using namespace mbot_lio;
using mbot_lio_test::Pose;

namespace
{
const Eigen::Vector3d kGravity(0.0, 0.0, -9.80665);

LidarFrame toLidarFrame(const mbot_lio_test::SynthFrame& s)
{
  LidarFrame f;
  f.stamp = s.stamp;
  for (size_t i = 0; i < s.points.size(); ++i)
  {
    f.points.push_back(s.points[i].cast<float>());
    f.times.push_back(float(s.times[i]));
  }
  return f;
}

double angleDeg(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b)
{
  return logSO3(a.transpose() * b).norm() * 180.0 / M_PI;
}

bool mentions(const std::exception& e, const std::string& what)
{
  return std::string(e.what()).find(what) != std::string::npos;
}
}  // namespace

// A pose off by 0.2 m and 5 deg is corrected to within 1 cm and 0.2 deg by one iterated update
// against the room's map (floor and walls, 2 cm range noise).
TEST(Update, CorrectsAPerturbedPoseInARoom)
{
  const mbot_lio_test::Room room;
  const Pose truth = mbot_lio_test::levelPose(0.5, -0.3, 0.3, 0.7);
  const mbot_lio_test::Motion still = [&](double) { return truth; };
  std::mt19937 rng(7);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  const auto mapping = mbot_lio_test::makeFrame(room, still, I, Eigen::Vector3d::Zero(), 0.0, 0.1, 20000, 0, 0.02, rng);
  const auto scan = mbot_lio_test::makeFrame(room, still, I, Eigen::Vector3d::Zero(), 0.0, 0.1, 20000, 1, 0.02, rng);

  Estimator est;
  std::vector<Eigen::Vector3d> world;
  for (const auto& p : mapping.points) world.push_back(truth.R * p + truth.p);
  est.map().add(world);
  std::vector<Eigen::Vector3d> pts;
  for (size_t i = 0; i < scan.points.size(); i += 5) pts.push_back(scan.points[i]);

  State x;
  x.R = truth.R * expSO3(Eigen::Vector3d(1.0, -1.0, 2.0).normalized() * 5.0 * M_PI / 180.0);
  x.p = truth.p + Eigen::Vector3d(0.12, -0.12, 0.1056);  // 0.2 m
  Cov P = Cov::Identity() * 0.01;
  P.block<3, 3>(kRot, kRot) = Eigen::Matrix3d::Identity() * 0.1 * 0.1;
  P.block<3, 3>(kPos, kPos) = Eigen::Matrix3d::Identity() * 0.3 * 0.3;
  est.initialize(0.0, x, P);
  ASSERT_NEAR((est.state().p - truth.p).norm(), 0.2, 1e-3);
  ASSERT_NEAR(angleDeg(est.state().R, truth.R), 5.0, 1e-6);

  const UpdateReport rep = est.update(pts);
  EXPECT_TRUE(rep.converged);
  EXPECT_GT(rep.matches, 2000);
  EXPECT_LT((est.state().p - truth.p).norm(), 0.01);
  EXPECT_LT(angleDeg(est.state().R, truth.R), 0.2);
  const double pos_var = est.covariance().block<3, 3>(kPos, kPos).trace();
  EXPECT_LT(pos_var, 1e-3);  // the update shrank it
}

// An empty map or a scan that matches nothing changes nothing.
TEST(Update, NoMatchesKeepsThePrediction)
{
  Estimator est;
  State x;
  x.p = Eigen::Vector3d(1, 2, 3);
  est.initialize(0.0, x);
  const UpdateReport rep = est.update({Eigen::Vector3d(1, 0, 0)});
  EXPECT_EQ(rep.matches, 0);
  EXPECT_EQ(est.state().p, x.p);
}

// The map's two trees (main + recent, the ikd-tree's stand-in) answer as one: k nearest against a
// brute-force search after batches that leave points in both trees, and one point per voxel.
TEST(LocalMap, NearestOfBothTreesMatchesBruteForce)
{
  LocalMap map(1e-4, 500, 0.3);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> u(-5.0, 5.0);
  std::vector<Eigen::Vector3d> all;
  for (int batch = 0; batch < 6; ++batch)  // ends with 1500 points in the main tree, 300 in the recent
  {
    std::vector<Eigen::Vector3d> pts;
    for (int i = 0; i < 300; ++i) pts.emplace_back(u(rng), u(rng), u(rng));
    ASSERT_EQ(map.add(pts), pts.size());
    all.insert(all.end(), pts.begin(), pts.end());
  }
  ASSERT_EQ(map.size(), all.size());
  std::vector<Eigen::Vector3d> nb;
  std::vector<float> d2;
  for (int q = 0; q < 200; ++q)
  {
    const Eigen::Vector3d p(u(rng), u(rng), u(rng));
    ASSERT_TRUE(map.nearest(p, 5, nb, d2));
    std::vector<double> brute;
    for (const auto& a : all) brute.push_back((a - p).squaredNorm());
    std::sort(brute.begin(), brute.end());
    for (int j = 0; j < 5; ++j) EXPECT_NEAR(d2[j], brute[j], 1e-4 * (1.0 + brute[j])) << "query " << q;
  }
  LocalMap coarse(0.5);
  EXPECT_EQ(
      coarse.add({Eigen::Vector3d(0.1, 0.1, 0.1), Eigen::Vector3d(0.2, 0.2, 0.2), Eigen::Vector3d(0.6, 0.1, 0.1)}), 2u);
}

// NaN IMU sample, a cloud without per-point times, out-of-order stamps, mismatched times, no IMU:
// each refused with a message naming the problem; the state stays the last good one, and the
// estimator goes on with good input afterwards.
TEST(BadInput, ClearErrorsAndTheLastGoodStateIsKept)
{
  const mbot_lio_test::Room room;
  const Pose truth = mbot_lio_test::levelPose(0.0, 0.0, 0.3, 0.0);
  const mbot_lio_test::Motion still = [&](double) { return truth; };
  std::mt19937 rng(3);
  const Eigen::Matrix3d I = Eigen::Matrix3d::Identity();
  Estimator est;
  EXPECT_THROW(est.addFrame(LidarFrame()), std::invalid_argument);  // before initialize()
  State x0;
  x0.p = truth.p;
  EXPECT_THROW(est.initialize(0.0, x0, Cov::Zero()), std::invalid_argument);  // not invertible
  EXPECT_FALSE(est.initialized());
  est.initialize(0.0, x0);
  for (int k = 0; k <= 24; ++k) est.addImu(mbot_lio_test::trueImu(still, k * 0.005, kGravity));
  est.addFrame(
      toLidarFrame(mbot_lio_test::makeFrame(room, still, I, Eigen::Vector3d::Zero(), 0.0, 0.1, 4000, 0, 0.0, rng)));
  const State good = est.state();
  const double t_good = est.time();

  ImuSample nan_sample = mbot_lio_test::trueImu(still, 0.125, kGravity);
  nan_sample.gyro.y() = std::nan("");
  try
  {
    est.addImu(nan_sample);
    ADD_FAILURE() << "NaN IMU sample accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(mentions(e, "NaN")) << e.what();
  }
  try
  {
    est.addImu(mbot_lio_test::trueImu(still, 0.05, kGravity));
    ADD_FAILURE() << "old IMU stamp accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(mentions(e, "out of order")) << e.what();
  }
  for (int k = 25; k <= 44; ++k) est.addImu(mbot_lio_test::trueImu(still, k * 0.005, kGravity));

  LidarFrame next =
      toLidarFrame(mbot_lio_test::makeFrame(room, still, I, Eigen::Vector3d::Zero(), 0.1, 0.1, 4000, 1, 0.0, rng));
  LidarFrame no_times = next;
  no_times.times.clear();
  try
  {
    est.addFrame(no_times);
    ADD_FAILURE() << "cloud without times accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(mentions(e, "no per-point times")) << e.what();
  }
  LidarFrame short_times = next;
  short_times.times.pop_back();
  try
  {
    est.addFrame(short_times);
    ADD_FAILURE() << "cloud with too few times accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(mentions(e, "point times")) << e.what();
  }
  LidarFrame old = next;
  old.stamp = 0.05;
  try
  {
    est.addFrame(old);
    ADD_FAILURE() << "out-of-order frame accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(mentions(e, "out of order")) << e.what();
  }
  LidarFrame late = next;
  late.stamp = 5.0;
  try
  {
    est.addFrame(late);
    ADD_FAILURE() << "frame beyond the IMU accepted";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_TRUE(mentions(e, "IMU samples end")) << e.what();
  }
  // nothing of the refused input reached the state
  EXPECT_EQ(est.time(), t_good);
  EXPECT_EQ(est.state().p, good.p);
  EXPECT_EQ(est.state().R, good.R);

  const FrameReport rep = est.addFrame(next);
  EXPECT_TRUE(rep.updated);
  EXPECT_LT((est.state().p - truth.p).norm(), 0.01);
  EXPECT_LT(angleDeg(est.state().R, truth.R), 0.2);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
