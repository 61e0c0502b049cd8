/**
 * @file test_imu.cpp
 * @brief The simulated IMU (src/world/imu.h): true readings at an off-centre mount at rest,
 *        turning in place and on a circle; timer, stamps and seeds through World; the error
 *        model's statistics (white noise, bias random walk, start bias, quantization) over long
 *        seeded runs.
 */
#include "../src/world/imu.h"
#include "mbot_sim/world.h"

#include <gtest/gtest.h>

#include <cmath>
#include <vector>

using mbot_description::DriveType;
using mbot_description::RobotModel;
using namespace mbot_sim;
using mbot_sim::detail::ImuErrors;
using mbot_sim::detail::kGravity;

namespace
{
constexpr double kPi = 3.14159265358979323846;

/// mbot's numbers with its IMU mount off the centre (as urdf/mbot.urdf: (-0.03, 0.02, 0.10)).
RobotModel imuModel(double mount_x = -0.03, double mount_y = 0.02)
{
  RobotModel m;
  m.name = "mbot";
  m.drive = DriveType::DIFF;
  m.footprint_radius = 0.15;
  for (int i = 0; i < 16; ++i)
    m.footprint.push_back({0.15 * std::cos(2 * kPi * i / 16), 0.15 * std::sin(2 * kPi * i / 16)});
  m.mass = 2.4;
  m.wheel_radius = 0.04;
  m.wheel_separation = 0.22;
  m.wheel_joints = {"left_wheel_joint", "right_wheel_joint"};
  m.limits = mbot_description::Limits{0.5, -0.2, 0.0, 2.0, 1e6, 0.0, 1e6};  // stiff: the twist holds at once
  m.imu.present = true;
  m.imu.xyz[0] = mount_x;
  m.imu.xyz[1] = mount_y;
  m.imu.xyz[2] = 0.10;
  return m;
}

OccupancyMap openMap()
{
  OccupancyMap map;
  map.width = map.height = 400;
  map.resolution = 0.1;
  map.origin_x = map.origin_y = -20.0;
  map.data.assign(400 * 400, 0);
  return map;
}

ImuNoiseConfig noErrors()
{
  ImuNoiseConfig c;
  c.gyro_noise_density = c.gyro_random_walk = c.gyro_bias_init = 0.0;
  c.accel_noise_density = c.accel_random_walk = c.accel_bias_init = 0.0;
  c.gyro_quantization = c.accel_quantization = 0.0;
  return c;
}

struct Recorder : SensorListener
{
  bool wanted = true;
  std::vector<ImuSample> samples;
  bool wantsImu(int) const override { return wanted; }
  void onImu(int, const ImuSample& s) override { samples.push_back(s); }
};

/// A world with one robot at the origin, stepped for `seconds` while commanded `command`.
std::vector<ImuSample> run(const ImuNoiseConfig& imu, double seconds, const Twist2D& command = {},
                           const RobotModel& model = imuModel(), unsigned seed = 3)
{
  WorldSettings settings;
  settings.seed = seed;
  settings.noise.imu = imu;
  World world(openMap(), settings);
  const int id = world.addRobot("robot_0", model, {0.0, 0.0, 0.0});
  Recorder rec;
  world.setListener(&rec);
  const int steps = static_cast<int>(std::lround(seconds / world.physicsStep()));
  for (int i = 0; i < steps; ++i)
  {
    world.setCommand(id, command);
    world.step();
  }
  return rec.samples;
}

double mean(const std::vector<double>& v)
{
  double s = 0.0;
  for (double x : v) s += x;
  return s / v.size();
}

double stddev(const std::vector<double>& v)
{
  const double m = mean(v);
  double s = 0.0;
  for (double x : v) s += (x - m) * (x - m);
  return std::sqrt(s / (v.size() - 1));
}
}  // namespace

TEST(Imu, RateAndStampsOnTheGridInSimTime)
{
  ImuNoiseConfig c = noErrors();
  c.time_offset = 0.002;
  const auto samples = run(c, 10.0);  // 200 Hz over a 100 Hz physics step: two per step
  ASSERT_EQ(samples.size(), 2000u);
  for (size_t i = 0; i < samples.size(); ++i) ASSERT_NEAR(samples[i].stamp, 0.005 * (i + 1) + 0.002, 1e-9) << i;
}

TEST(Imu, AtRestReadsGravityPlusTheStartBias)
{
  ImuNoiseConfig c;  // the consumer MEMS defaults, without the random walk (the bias stays put)
  c.gyro_random_walk = c.accel_random_walk = 0.0;
  const auto samples = run(c, 20.0);
  ASSERT_EQ(samples.size(), 4000u);
  const ImuErrors same_seed(c, 3, 0);  // robot 0 of seed 3: the same start bias
  for (int axis = 0; axis < 3; ++axis)
  {
    std::vector<double> w, f;
    for (const auto& s : samples)
    {
      w.push_back(s.angular_velocity[axis]);
      f.push_back(s.linear_acceleration[axis]);
    }
    const double n = std::sqrt(static_cast<double>(samples.size()));
    const double w_sigma = c.gyro_noise_density * std::sqrt(c.rate),
                 f_sigma = c.accel_noise_density * std::sqrt(c.rate);
    EXPECT_NEAR(mean(w), same_seed.gyroBias()[axis], 4.0 * w_sigma / n + c.gyro_quantization) << axis;
    const double gravity = axis == 2 ? kGravity : 0.0;
    EXPECT_NEAR(mean(f), gravity + same_seed.accelBias()[axis], 4.0 * f_sigma / n + c.accel_quantization) << axis;
  }
  EXPECT_GT(std::abs(same_seed.gyroBias()[2]), 1e-4);  // a bias is there to be found
}

TEST(Imu, TurningInPlaceGyroZIsTheRateAndTheOffsetMountFeelsCentripetal)
{
  const double w = 1.5, px = -0.03, py = 0.02;
  const auto samples = run(noErrors(), 3.0, Twist2D{0.0, 0.0, w});
  ASSERT_EQ(samples.size(), 600u);
  for (size_t i = 10; i < samples.size(); ++i)  // after the first step's start
  {
    const ImuSample& s = samples[i];
    ASSERT_NEAR(s.angular_velocity[0], 0.0, 1e-12);
    ASSERT_NEAR(s.angular_velocity[1], 0.0, 1e-12);
    ASSERT_NEAR(s.angular_velocity[2], w, 1e-6) << i;
    ASSERT_NEAR(s.linear_acceleration[0], -w * w * px, 1e-4) << i;  // towards the centre
    ASSERT_NEAR(s.linear_acceleration[1], -w * w * py, 1e-4) << i;
    ASSERT_NEAR(s.linear_acceleration[2], kGravity, 1e-12);
  }
}

TEST(Imu, DrivingACircleAccelYIsVTimesW)
{
  const double v = 0.4, w = 0.8;
  // At the centre: the centripetal v * w along y. Off the centre it adds -w^2 p.
  for (const auto& mount : std::vector<std::pair<double, double>>{{0.0, 0.0}, {-0.03, 0.02}})
  {
    const auto samples = run(noErrors(), 4.0, Twist2D{v, 0.0, w}, imuModel(mount.first, mount.second));
    ASSERT_EQ(samples.size(), 800u);
    for (size_t i = 10; i < samples.size(); ++i)
    {
      const ImuSample& s = samples[i];
      ASSERT_NEAR(s.angular_velocity[2], w, 1e-6) << i;
      ASSERT_NEAR(s.linear_acceleration[0], -w * w * mount.first, 1e-4) << i;
      ASSERT_NEAR(s.linear_acceleration[1], v * w - w * w * mount.second, 1e-4) << i;
    }
  }
}

TEST(Imu, SpeedingUpTangentialAccelerationAtTheMount)
{
  // A stiff model reaches the twist in one step: that step's samples read dv/dt = v / dt.
  RobotModel m = imuModel(0.1, 0.0);
  m.limits.acc_lim_theta = 2.0;  // the turn rate ramps at 2 rad/s^2: alpha x p = 0.2 m/s^2 along y
  const auto samples = run(noErrors(), 0.4, Twist2D{0.0, 0.0, 1.0}, m);
  ASSERT_GE(samples.size(), 60u);
  for (size_t i = 4; i < 60; ++i)
  {
    const double wz = samples[i].angular_velocity[2];
    ASSERT_GT(wz, 0.0);
    ASSERT_LT(wz, 1.0);
    ASSERT_NEAR(samples[i].linear_acceleration[1], 2.0 * 0.1, 1e-3) << i;
    ASSERT_NEAR(samples[i].linear_acceleration[0], -wz * wz * 0.1, 2e-3) << i;
  }
}

TEST(Imu, NobodyListeningNoSamplesAndAModelWithoutImuHasNone)
{
  WorldSettings settings;
  World world(openMap(), settings);
  world.addRobot("robot_0", imuModel(), {0.0, 0.0, 0.0});
  RobotModel plain = imuModel();
  plain.imu.present = false;
  world.addRobot("robot_1", plain, {2.0, 0.0, 0.0});
  Recorder rec;
  rec.wanted = false;
  world.setListener(&rec);
  for (int i = 0; i < 100; ++i) world.step();
  EXPECT_TRUE(rec.samples.empty());
  rec.wanted = true;
  for (int i = 0; i < 100; ++i) world.step();
  EXPECT_EQ(rec.samples.size(), 200u);  // robot_0 only, from where the timer stands
  EXPECT_NEAR(rec.samples.front().stamp, 1.005, 1e-9);
}

TEST(Imu, LatencyFaultDelaysSamplesKeepingStampsAndOrderSilencedDropsThem)
{
  struct Late : Recorder
  {
    const World* world = nullptr;
    std::vector<double> arrived;
    void onImu(int robot, const ImuSample& s) override
    {
      Recorder::onImu(robot, s);
      arrived.push_back(world->time());
    }
  };
  WorldSettings settings;
  settings.noise.imu = noErrors();
  World world(openMap(), settings);
  world.addRobot("robot_0", imuModel(), {0.0, 0.0, 0.0});
  Late rec;
  rec.world = &world;
  world.setListener(&rec);
  FaultConfig late;
  late.sensor_latency = 0.05;
  late.sensor_jitter = 0.01;
  world.setFaults("robot_0", late);
  for (int i = 0; i < 200; ++i) world.step();
  ASSERT_GT(rec.samples.size(), 380u);  // 400 measured in 2 s, the last ones still on their way
  for (size_t i = 0; i < rec.samples.size(); ++i)
  {
    ASSERT_NEAR(rec.samples[i].stamp, 0.005 * (i + 1), 1e-9) << i;  // stamps: measurement times, in order
    ASSERT_GE(rec.arrived[i], rec.samples[i].stamp + 0.05 - 1e-9) << i;
  }
  FaultConfig silenced;
  silenced.silenced = true;
  world.setFaults("robot_0", silenced);
  const size_t before = rec.samples.size();
  for (int i = 0; i < 100; ++i) world.step();
  EXPECT_EQ(rec.samples.size(), before);
}

TEST(Imu, SameSeedSameSamplesOtherSeedOthers)
{
  const ImuNoiseConfig c;  // the defaults
  const auto a = run(c, 2.0, Twist2D{0.2, 0.0, 0.5}, imuModel(), 11);
  const auto b = run(c, 2.0, Twist2D{0.2, 0.0, 0.5}, imuModel(), 11);
  const auto other = run(c, 2.0, Twist2D{0.2, 0.0, 0.5}, imuModel(), 12);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), other.size());
  int differ = 0;
  for (size_t i = 0; i < a.size(); ++i)
  {
    for (int k = 0; k < 3; ++k)
    {
      ASSERT_EQ(a[i].angular_velocity[k], b[i].angular_velocity[k]);
      ASSERT_EQ(a[i].linear_acceleration[k], b[i].linear_acceleration[k]);
      differ += a[i].angular_velocity[k] != other[i].angular_velocity[k];
    }
  }
  EXPECT_GT(differ, static_cast<int>(a.size()));
}

TEST(ImuErrors, WhiteNoiseSigmaIsDensityTimesRootRate)
{
  ImuNoiseConfig c = noErrors();
  c.rate = 400.0;
  c.gyro_noise_density = 1e-3;
  c.accel_noise_density = 5e-3;
  ImuErrors errors(c, 1, 0);
  std::vector<double> w[3], f[3];
  ImuSample s;
  for (int i = 0; i < 100000; ++i)
  {
    errors.apply({0.0, 0.0, 0.0}, {0.0, 0.0, kGravity}, s);
    for (int k = 0; k < 3; ++k)
    {
      w[k].push_back(s.angular_velocity[k]);
      f[k].push_back(s.linear_acceleration[k]);
    }
  }
  for (int k = 0; k < 3; ++k)
  {
    // 1e5 samples: the sample sd is within 0.5 % of the true one (3 sigma); 2 % is a bound.
    EXPECT_NEAR(stddev(w[k]), 1e-3 * 20.0, 0.02 * 1e-3 * 20.0) << k;
    EXPECT_NEAR(stddev(f[k]), 5e-3 * 20.0, 0.02 * 5e-3 * 20.0) << k;
    EXPECT_NEAR(mean(w[k]), 0.0, 4.0 * 0.02 / std::sqrt(1e5)) << k;
  }
}

TEST(ImuErrors, BiasRandomWalkVarianceGrowsLinearly)
{
  // 600 seeded IMUs x 3 axes for 20 s at 200 Hz: var(bias(T)) = rw^2 T.
  ImuNoiseConfig c = noErrors();
  c.gyro_random_walk = 1e-3;
  c.accel_random_walk = 2e-3;
  const int imus = 600;
  const double times[] = {5.0, 20.0};
  std::vector<double> g[2], a[2];
  ImuSample s;
  for (int n = 0; n < imus; ++n)
  {
    ImuErrors errors(c, 100, n);
    int done = 0;
    for (int t = 0; t < 2; ++t)
    {
      const int until = static_cast<int>(std::lround(times[t] * c.rate));
      for (; done < until; ++done) errors.apply({0.0, 0.0, 0.0}, {0.0, 0.0, 0.0}, s);
      for (int k = 0; k < 3; ++k)
      {
        g[t].push_back(errors.gyroBias()[k]);
        a[t].push_back(errors.accelBias()[k]);
      }
    }
  }
  for (int t = 0; t < 2; ++t)
  {
    // 1800 values: the variance is within 7 % of the truth at 2 sigma; 12 % is the bound.
    const double gv = std::pow(stddev(g[t]), 2), av = std::pow(stddev(a[t]), 2);
    EXPECT_NEAR(gv / (1e-6 * times[t]), 1.0, 0.12) << times[t];
    EXPECT_NEAR(av / (4e-6 * times[t]), 1.0, 0.12) << times[t];
  }
}

TEST(ImuErrors, StartBiasSpreadAndQuantizationSteps)
{
  ImuNoiseConfig c = noErrors();
  c.gyro_bias_init = 0.01;
  c.accel_bias_init = 0.1;
  std::vector<double> g, a;
  for (int n = 0; n < 2000; ++n)
  {
    const ImuErrors errors(c, 5, n);
    for (int k = 0; k < 3; ++k)
    {
      g.push_back(errors.gyroBias()[k]);
      a.push_back(errors.accelBias()[k]);
    }
  }
  EXPECT_NEAR(stddev(g), 0.01, 0.0006);  // 6000 draws: 1 % sd
  EXPECT_NEAR(stddev(a), 0.1, 0.006);

  ImuNoiseConfig q = noErrors();
  q.gyro_noise_density = 1e-3;
  q.accel_noise_density = 1e-2;
  q.gyro_quantization = 1e-3;
  q.accel_quantization = 0.01;
  ImuErrors errors(q, 1, 0);
  ImuSample s;
  int distinct_steps = 0;
  double last = 0.0;
  for (int i = 0; i < 1000; ++i)
  {
    errors.apply({0.0, 0.0, 0.3}, {0.0, 0.0, kGravity}, s);
    for (int k = 0; k < 3; ++k)
    {
      const double gsteps = s.angular_velocity[k] / 1e-3, asteps = s.linear_acceleration[k] / 0.01;
      ASSERT_NEAR(gsteps, std::round(gsteps), 1e-6);
      ASSERT_NEAR(asteps, std::round(asteps), 1e-6);
    }
    distinct_steps += s.angular_velocity[2] != last;
    last = s.angular_velocity[2];
  }
  EXPECT_GT(distinct_steps, 500);  // the noise (sd 0.014 rad/s) spans many steps
}
