/**
 * @file test_lidar3d.cpp
 * @brief The 3D lidar core (lidar3d.h): rays against brute-force geometry on hand-made 2.5D
 *        worlds, floor and wall hits at known distances, a ray above a low box, the scan
 *        pattern's field and times, deskew-ready point times, noise and quantization.
 */
#include "mbot_sim/lidar3d.h"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <random>
#include <set>
#include <stdexcept>
#include <vector>

namespace
{
using mbot_sim::castRay3D;
using mbot_sim::castRay3DBruteForce;
using mbot_sim::GridRaycaster;
using mbot_sim::LidarFrame;
using mbot_sim::LidarPattern;
using mbot_sim::LidarScanner;
using mbot_sim::LidarSpec;
using mbot_sim::PlanarPose;
using mbot_sim::Prism;
using mbot_sim::PrismQuery;
using mbot_sim::RayHit;
using mbot_sim::Scene25D;
using mbot_sim::Surface;

constexpr double kPi = 3.14159265358979323846;
double deg(double d) { return d * kPi / 180.0; }

/// A w x h grid of 0.1 m cells from (0, 0) with a one-cell wall all round and `extra` cells.
GridRaycaster room(unsigned w, unsigned h, const std::vector<std::pair<int, int>>& extra = {})
{
  std::vector<uint8_t> cells(static_cast<size_t>(w) * h, 0);
  for (unsigned x = 0; x < w; ++x) cells[x] = cells[static_cast<size_t>(h - 1) * w + x] = 1;
  for (unsigned y = 0; y < h; ++y) cells[static_cast<size_t>(y) * w] = cells[static_cast<size_t>(y) * w + w - 1] = 1;
  for (const auto& c : extra) cells[static_cast<size_t>(c.second) * w + c.first] = 1;
  return GridRaycaster(cells, w, h, 0.1, 0.0, 0.0);
}

Prism box(double x, double y, double yaw, double hl, double hw, double height, int owner = -1)
{
  Prism p;
  p.is_box = true;
  p.x = x;
  p.y = y;
  p.yaw = yaw;
  p.half_length = hl;
  p.half_width = hw;
  p.height = height;
  p.owner = owner;
  p.intensity = 150.0f;
  return p;
}

Prism cylinder(double x, double y, double r, double height, int owner = -1)
{
  Prism p;
  p.x = x;
  p.y = y;
  p.radius = r;
  p.height = height;
  p.owner = owner;
  p.intensity = 200.0f;
  return p;
}

RayHit cast(const Scene25D& scene, double x, double y, double z, double azimuth, double elevation, double max_range,
            int owner = -1)
{
  PrismQuery q;
  q.prepare(scene, x, y, max_range, owner);
  return castRay3D(scene, q, x, y, z, std::cos(azimuth), std::sin(azimuth), elevation, max_range);
}

TEST(Lidar3d, FloorAtKnownDistance)
{
  const GridRaycaster grid = room(200, 200);  // 20 m: the walls are far
  const Scene25D scene(&grid, 2.5);
  // From 0.5 m up, 30 deg down: the floor 1.0 m along the ray, 0.866 m away horizontally.
  const RayHit hit = cast(scene, 10.0, 10.0, 0.5, 0.3, deg(-30.0), 40.0);
  EXPECT_EQ(hit.surface, Surface::kFloor);
  EXPECT_NEAR(hit.range, 1.0, 1e-9);
  // 7 deg down from 0.2 m: 0.2 / sin(7 deg) = 1.641 m
  const RayHit low = cast(scene, 10.0, 10.0, 0.2, 2.0, deg(-7.0), 40.0);
  EXPECT_EQ(low.surface, Surface::kFloor);
  EXPECT_NEAR(low.range, 0.2 / std::sin(deg(7.0)), 1e-9);
  // beyond max_range: no return
  EXPECT_TRUE(std::isinf(cast(scene, 10.0, 10.0, 0.5, 0.3, deg(-30.0), 0.9).range));
}

TEST(Lidar3d, WallAtKnownDistance)
{
  const GridRaycaster grid = room(100, 60);  // inner faces at x = 0.1 and x = 9.9
  const Scene25D scene(&grid, 2.5);
  for (double e : {0.0, 10.0, 20.0, -3.0})  // 20 deg up: 1.96 m up at the wall
  {
    const RayHit hit = cast(scene, 5.9, 3.0, 0.5, 0.0, deg(e), 40.0);
    EXPECT_EQ(hit.surface, Surface::kWall) << e;
    EXPECT_NEAR(hit.range, 4.0 / std::cos(deg(e)), 1e-9) << e;
  }
  // 45 deg up from 0.5 m: at the wall (4 m) the ray is 4.5 m up, over the 2.5 m wall: no return
  EXPECT_TRUE(std::isinf(cast(scene, 5.9, 3.0, 0.5, 0.0, deg(45.0), 40.0).range));
  // the same wall 4.5 m high is hit at 4 / cos(45 deg)
  const Scene25D tall(&grid, 4.6);
  EXPECT_NEAR(cast(tall, 5.9, 3.0, 0.5, 0.0, deg(45.0), 40.0).range, 4.0 * std::sqrt(2.0), 1e-9);
}

TEST(Lidar3d, RayAboveLowBoxHitsWallBehind)
{
  const GridRaycaster grid = room(100, 60);  // wall face at x = 9.9
  Scene25D scene(&grid, 2.5);
  scene.addPrism(box(7.15, 3.0, 0.0, 0.25, 0.5, 0.3));  // x 6.9..7.4, 0.3 m high
  // level from 0.5 m: over the box, the wall at 4 m
  RayHit hit = cast(scene, 5.9, 3.0, 0.5, 0.0, 0.0, 40.0);
  EXPECT_EQ(hit.surface, Surface::kWall);
  EXPECT_NEAR(hit.range, 4.0, 1e-9);
  // 5 deg down: 0.5 - 4 tan 5 = 0.15 m up at the wall, still over the box at 1..1.5 m
  hit = cast(scene, 5.9, 3.0, 0.5, 0.0, deg(-5.0), 40.0);
  EXPECT_EQ(hit.surface, Surface::kWall);
  EXPECT_NEAR(hit.range, 4.0 / std::cos(deg(-5.0)), 1e-9);
  // 10 deg down: lands on the box's top (0.3 m) at 0.2 / tan 10 = 1.134 m
  hit = cast(scene, 5.9, 3.0, 0.5, 0.0, deg(-10.0), 40.0);
  EXPECT_EQ(hit.surface, Surface::kPrism);
  EXPECT_NEAR(hit.range, (0.2 / std::tan(deg(10.0))) / std::cos(deg(10.0)), 1e-9);
  // 20 deg down: the box's front face at 1 m, 0.136 m up
  hit = cast(scene, 5.9, 3.0, 0.5, 0.0, deg(-20.0), 40.0);
  EXPECT_EQ(hit.surface, Surface::kPrism);
  EXPECT_NEAR(hit.range, 1.0 / std::cos(deg(20.0)), 1e-9);
  // a robot's own body is not seen
  scene.addPrism(cylinder(5.9, 3.0, 0.2, 0.6, 7));
  EXPECT_NEAR(cast(scene, 5.9, 3.0, 0.5, 0.0, 0.0, 40.0, 7).range, 4.0, 1e-9);
  EXPECT_NEAR(cast(scene, 5.9, 3.0, 0.5, 0.0, 0.0, 40.0, -1).range, 0.0, 1e-9);  // inside it
}

TEST(Lidar3d, AgreesWithBruteForce)
{
  // Walls, an inner wall block, boxes and cylinders of several heights; random rays.
  std::vector<std::pair<int, int>> block;
  for (int x = 30; x < 36; ++x)
    for (int y = 20; y < 24; ++y) block.emplace_back(x, y);
  const GridRaycaster grid = room(80, 50, block);
  Scene25D scene(&grid, 2.0);
  scene.addPrism(box(2.0, 1.2, 0.4, 0.3, 0.15, 0.4));
  scene.addPrism(box(5.5, 3.5, -0.9, 0.5, 0.2, 1.2));
  scene.addPrism(cylinder(1.5, 3.5, 0.25, 1.7));
  scene.addPrism(cylinder(6.5, 1.2, 0.4, 0.25));
  scene.addPrism(cylinder(4.0, 4.2, 0.3, 3.0));  // taller than the walls
  std::mt19937 rng(42);
  std::uniform_real_distribution<double> ux(0.3, 7.7), uy(0.3, 4.7), uz(0.05, 1.9), ua(-kPi, kPi),
      ue(deg(-60.0), deg(60.0));
  const double step = 5e-4;
  int compared = 0, hits = 0;
  std::set<int> surfaces;
  for (int i = 0; i < 1500; ++i)
  {
    const double x = ux(rng), y = uy(rng), z = uz(rng), a = ua(rng), e = ue(rng);
    if (grid.occupiedAt(x, y)) continue;
    bool inside = false;
    for (const Prism& p : scene.prisms())
      inside = inside || std::hypot(x - p.x, y - p.y) < (p.is_box ? std::hypot(p.half_length, p.half_width) : p.radius);
    if (inside) continue;
    const RayHit fast = cast(scene, x, y, z, a, e, 12.0);
    const RayHit slow = castRay3DBruteForce(scene, x, y, z, std::cos(a), std::sin(a), e, 12.0, step, -1);
    ++compared;
    ASSERT_EQ(std::isinf(fast.range), std::isinf(slow.range)) << "ray " << i;
    if (std::isinf(fast.range)) continue;
    ++hits;
    surfaces.insert(static_cast<int>(fast.surface));
    // the brute force stops at the first step inside: at most one step past the surface
    EXPECT_LE(fast.range, slow.range + 1e-9) << "ray " << i;
    EXPECT_GE(fast.range, slow.range - step - 1e-9) << "ray " << i;
    EXPECT_EQ(fast.surface, slow.surface) << "ray " << i;
  }
  EXPECT_GT(compared, 1000);
  EXPECT_GT(hits, 700);            // most rays hit something; upward ones over the walls do not
  EXPECT_EQ(surfaces.size(), 3u);  // walls, floor and prisms all met
}

TEST(Lidar3d, PatternCoversTheField)
{
  LidarSpec spec;
  const LidarPattern pattern(spec);
  // 2 x 2 deg cells of the field (360 x 59 deg): what share one frame and ten frames hit
  const int az_bins = 180, el_bins = 30;
  std::vector<int> cells(az_bins * el_bins, 0);
  auto coverage = [&]() {
    int hit = 0;
    for (int c : cells) hit += c > 0;
    return static_cast<double>(hit) / cells.size();
  };
  double one = 0.0;
  double az_min = 1e9, az_max = -1e9;
  for (uint64_t n = 0; n < 10u * spec.points_per_frame; ++n)
  {
    double a = 0.0, e = 0.0;
    pattern.direction(n, a, e);
    ASSERT_GE(e, spec.min_elevation - 1e-12);
    ASSERT_LE(e, spec.max_elevation + 1e-12);
    const double w = std::remainder(a, 2.0 * kPi) + kPi;  // [0, 2 pi]
    az_min = std::min(az_min, w);
    az_max = std::max(az_max, w);
    const int ai = std::min(az_bins - 1, static_cast<int>(w / (2.0 * kPi) * az_bins));
    const int ei = std::min(
        el_bins - 1, static_cast<int>((e - spec.min_elevation) / (spec.max_elevation - spec.min_elevation) * el_bins));
    ++cells[ai * el_bins + ei];
    if (n + 1 == static_cast<uint64_t>(spec.points_per_frame)) one = coverage();
  }
  const double ten = coverage();
  std::printf("coverage: one frame %.3f, ten frames %.3f\n", one, ten);
  EXPECT_LT(az_min, 0.01);
  EXPECT_GT(az_max, 2.0 * kPi - 0.01);
  EXPECT_GT(one, 0.5);         // one frame already sees most of the field...
  EXPECT_GT(ten, 0.99);        // ...and ten frames nearly all of it
  EXPECT_GT(ten, one + 0.05);  // integration time fills the gaps: the pattern does not repeat
  // the frames differ (non-repetitive): point 0 and point 0 of the next frame
  double a0, e0, a1, e1;
  pattern.direction(0, a0, e0);
  pattern.direction(static_cast<uint64_t>(spec.points_per_frame), a1, e1);
  EXPECT_GT(std::abs(e1 - e0), 1e-3);
}

TEST(Lidar3d, FramesTimesAndDeskew)
{
  // A closed 8 x 5 m room with 2.5 m walls: every ray returns. The robot drives along +x at
  // 1 m/s while it scans; each point, put back into the world with the pose at its own time,
  // must lie on a wall, the floor or the ceiling-free top of the walls.
  const GridRaycaster grid = room(80, 50);
  Scene25D scene(&grid, 2.5);
  LidarSpec spec;
  spec.points_per_frame = 4000;
  LidarScanner scanner(spec, 0.1, 0.0, 0.3, 0.0, 0.0);
  std::mt19937 rng(1);
  std::vector<LidarFrame> frames;
  const double step = 0.01, v = 1.0, y = 2.5, theta = 0.0;
  PrismQuery q;
  for (int k = 0; k < 25; ++k)
  {
    const double t0 = k * step, t1 = (k + 1) * step;
    const PlanarPose p0{1.0 + v * t0, y, theta}, p1{1.0 + v * t1, y, theta};
    q.prepare(scene, p1.x, p1.y, spec.range_max + 1.0, -1);
    scanner.advance(scene, q, t0, p0, t1, p1, rng, frames);
  }
  ASSERT_EQ(frames.size(), 2u);  // 0.25 s at 10 Hz: frames at 0.0 and 0.1 done
  EXPECT_DOUBLE_EQ(frames[0].stamp, 0.0);
  EXPECT_NEAR(frames[1].stamp, 0.1, 1e-12);
  for (const LidarFrame& f : frames)
  {
    ASSERT_GT(f.points.size(), 1000u);
    float last = -1.0f;
    int on_wall = 0;
    for (const auto& p : f.points)
    {
      ASSERT_GE(p.time, 0.0f);
      ASSERT_LT(p.time, 0.1f);
      ASSERT_GE(p.time, last);
      last = p.time;
      // the lidar at the point's time: x = 1 + v (stamp + time) + 0.1
      const double wx = 1.0 + v * (f.stamp + p.time) + 0.1 + p.x;
      const double wy = y + p.y;
      const double wz = 0.3 + p.z;
      const double to_wall =
          std::min(std::min(std::abs(wx - 0.1), std::abs(wx - 7.9)), std::min(std::abs(wy - 0.1), std::abs(wy - 4.9)));
      ASSERT_TRUE(std::abs(wz) < 1e-4 || to_wall < 1e-4) << wx << " " << wy << " " << wz;
      on_wall += to_wall < 1e-4;
    }
    EXPECT_GT(on_wall, 100);
    // each point along its pattern direction (the scanner walks the pattern without trigonometry)
    const LidarPattern pattern(spec);
    const uint64_t first = static_cast<uint64_t>(std::llround(f.stamp * spec.rate)) * spec.points_per_frame;
    for (const auto& p : f.points)
    {
      double a = 0.0, e = 0.0;
      pattern.direction(first + static_cast<uint64_t>(std::llround(p.time * spec.rate * spec.points_per_frame)), a, e);
      const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
      ASSERT_NEAR(p.z / r, std::sin(e), 1e-6);
      ASSERT_NEAR(p.x / r, std::cos(e) * std::cos(a), 1e-6);
      ASSERT_NEAR(p.y / r, std::cos(e) * std::sin(a), 1e-6);
    }
    EXPECT_LE(f.points.size(), static_cast<size_t>(spec.points_per_frame));
  }
}

TEST(Lidar3d, FramesKeepTheirPhase)
{
  // A lidar switched on at sim time 5.0: frames at 5.0, 5.1, ...; after a pause (restart at
  // 5.23) the next frame starts on the grid, at 5.3.
  const GridRaycaster grid = room(80, 50);
  const Scene25D scene(&grid, 2.5);
  LidarSpec spec;
  spec.points_per_frame = 1000;
  LidarScanner scanner(spec, 0.0, 0.0, 0.3, 0.0, 5.0);
  std::mt19937 rng(1);
  std::vector<LidarFrame> frames;
  PrismQuery q;
  q.prepare(scene, 4.0, 2.5, 50.0, -1);
  const PlanarPose pose{4.0, 2.5, 0.0};
  double t = 5.0;
  for (int k = 0; k < 20; ++k, t += 0.01) scanner.advance(scene, q, t, pose, t + 0.01, pose, rng, frames);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_NEAR(frames[0].stamp, 5.0, 1e-9);
  EXPECT_NEAR(frames[1].stamp, 5.1, 1e-9);
  frames.clear();
  scanner.restart(5.23);
  for (t = 5.23; t < 5.5; t += 0.01) scanner.advance(scene, q, t, pose, t + 0.01, pose, rng, frames);
  ASSERT_EQ(frames.size(), 2u);  // 5.3 and 5.4 (5.5 still open)
  EXPECT_NEAR(frames[0].stamp, 5.3, 1e-9);
  EXPECT_NEAR(frames[1].stamp, 5.4, 1e-9);
  EXPECT_GT(frames[0].points.size(), 500u);
}

TEST(Lidar3d, NoiseAndQuantization)
{
  const GridRaycaster grid = room(100, 60);
  const Scene25D scene(&grid, 2.5);
  LidarSpec spec;
  spec.points_per_frame = 20000;
  spec.range_noise = 0.03;
  spec.range_quantization = 0.002;
  // Only the floor is near when the lidar is high in a big room: compare each floor point's
  // range with the exact one along its direction.
  LidarScanner scanner(spec, 0.0, 0.0, 0.2, 0.0, 0.0);
  std::mt19937 rng(3);
  std::vector<LidarFrame> frames;
  PrismQuery q;
  q.prepare(scene, 5.0, 3.0, 50.0, -1);
  const PlanarPose pose{5.0, 3.0, 0.0};
  scanner.advance(scene, q, 0.0, pose, 0.1, pose, rng, frames);
  ASSERT_EQ(frames.size(), 1u);
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (const auto& p : frames[0].points)
  {
    const double r = std::sqrt(double(p.x) * p.x + double(p.y) * p.y + double(p.z) * p.z);
    const double q_steps = r / spec.range_quantization;
    ASSERT_NEAR(q_steps, std::round(q_steps), 1e-3);
    if (p.z >= 0.0f) continue;      // upward: walls (varied); downward: the floor
    const double sin_e = -p.z / r;  // the direction is exact, only the range is noisy
    const double exact = 0.2 / sin_e;
    if (exact > 2.5) continue;  // keep to the floor, short of the walls (2.9 m away)
    const double err = r - exact;
    sum += err;
    sum2 += err * err;
    ++n;
  }
  ASSERT_GT(n, 300);
  const double mean = sum / n, sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.01);
  EXPECT_NEAR(sd, 0.03, 0.006);
}

TEST(Lidar3d, BadSpecRefused)
{
  LidarSpec spec;
  spec.rate = 0.0;
  EXPECT_THROW(LidarPattern{spec}, std::invalid_argument);
  spec = LidarSpec();
  spec.max_elevation = spec.min_elevation;
  EXPECT_THROW(LidarPattern{spec}, std::invalid_argument);
  spec = LidarSpec();
  spec.range_noise = -0.1;
  EXPECT_THROW(LidarPattern{spec}, std::invalid_argument);
  const GridRaycaster grid = room(10, 10);
  EXPECT_THROW(Scene25D(&grid, 0.0), std::invalid_argument);
  Scene25D scene(&grid, 2.5);
  EXPECT_THROW(scene.addPrism(cylinder(1.0, 1.0, 0.2, -1.0)), std::invalid_argument);
}

}  // namespace
