// Time per frame of the LIO (not a test): the synthetic room of the tests, a robot driving 1 m/s
// on a 2 m circle, Mid-360-like frames of 20 000 points at 10 Hz, IMU at 200 Hz with noise.
// Prints p50/p95/max of Estimator::addFrame (propagation, deskew, downsampling, update, map
// insertion) over the frames after the first, and the final position error. One thread.
//   rosrun mbot_lio lio_bench [frames] [points_per_frame]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>

#include "mbot_lio/estimator.h"
#include "synthetic_room.h"

using namespace mbot_lio;

int main(int argc, char** argv)
{
  const int frames = argc > 1 ? std::atoi(argv[1]) : 150;
  const long points = argc > 2 ? std::atol(argv[2]) : 20000;
  if (frames < 2 || points < 100)
  {
    std::fprintf(stderr, "usage: lio_bench [frames >= 2] [points_per_frame >= 100]\n");
    return 2;
  }
  const Eigen::Vector3d g(0.0, 0.0, -9.80665);
  const mbot_lio_test::Motion motion = [](double t) {
    return mbot_lio_test::levelPose(2.0 * std::cos(0.5 * t), 2.0 * std::sin(0.5 * t), 0.09, 0.5 * t + M_PI / 2);
  };
  const Eigen::Vector3d p_il(0.0, 0.0, 0.17);
  Options opt;
  opt.imu_p_lidar = p_il;
  Estimator est(opt);
  State x0;
  x0.R = motion(0).R;
  x0.p = motion(0).p;
  x0.v = Eigen::Vector3d(0.0, 1.0, 0.0);
  est.initialize(0.0, x0);
  std::mt19937 rng(5);
  std::normal_distribution<double> n01(0.0, 1.0);
  const mbot_lio_test::Room room;
  long k = 0;
  std::vector<double> ms;
  for (int f = 0; f < frames; ++f)
  {
    const double stamp = 0.1 * f;
    for (; k / 200.0 <= stamp + 0.105; ++k)
    {
      ImuSample s = mbot_lio_test::trueImu(motion, k / 200.0, g);
      for (int a = 0; a < 3; ++a)
      {
        s.gyro[a] += 2.6e-4 * std::sqrt(200.0) * n01(rng);
        s.acc[a] += 2.3e-3 * std::sqrt(200.0) * n01(rng);
      }
      est.addImu(s);
    }
    const auto synth =
        mbot_lio_test::makeFrame(room, motion, Eigen::Matrix3d::Identity(), p_il, stamp, 0.1, points, f, 0.02, rng);
    LidarFrame frame;
    frame.stamp = stamp;
    for (size_t i = 0; i < synth.points.size(); ++i)
    {
      frame.points.push_back(synth.points[i].cast<float>());
      frame.times.push_back(float(synth.times[i]));
    }
    const auto t0 = std::chrono::steady_clock::now();
    est.addFrame(frame);
    const auto t1 = std::chrono::steady_clock::now();
    if (f > 0) ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
  }
  std::sort(ms.begin(), ms.end());
  const auto q = [&](double p) { return ms[std::min(ms.size() - 1, size_t(p * ms.size()))]; };
  const double err = (est.state().p - motion(est.time()).p).norm();
  std::printf(
      "lio_bench: %d frames of %ld points, map %zu points: per frame p50 %.2f ms, p95 %.2f ms, max %.2f ms; "
      "final position error %.4f m\n",
      frames, points, est.map().size(), q(0.5), q(0.95), ms.back(), err);
  return 0;
}
