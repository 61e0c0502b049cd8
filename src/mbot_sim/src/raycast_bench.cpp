/**
 * @file raycast_bench.cpp
 * @brief Ray casting benchmark: 360-beam, 8 m scans from random free poses (seeded) in a
 *        20 x 20 m room (0.05 m cells, outer walls and a few interior walls) with 10 robots
 *        (circles, r = 0.15 m) moving around; then the same room tiled 3 x 3 (60 x 60 m) with
 *        1000 robots. Prints one JSON line:
 *        {"rays_per_second": X, "beams": 360, "range_max": 8.0, ...}
 *
 * Each frame moves the robots, rebuilds the ShapeSet (timed) and casts 10 scans (room) or 100
 * scans (1000 robots: their 10 Hz lasers over one 100 Hz physics step) (timed). Besides
 * "rays_per_second" (wall time, std::chrono::steady_clock), "cpu_rays_per_second" uses the
 * process CPU time: on a machine busy with other work it shows the speed of the code itself.
 *
 * Then the 3D lidar (lidar3d.h): a Mid-360-like lidar (defaults: 20000 points per 0.1 s frame,
 * 40 m, noise and quantization on) riding a wandering robot through the room (2.5 m walls, the
 * 10 robots as 0.3 m prisms, two boxes), cast step by step (0.01 s) as the simulator does:
 * "lidar": {"points_per_second", "cpu_points_per_second", ...}, rays cast per second.
 *
 *   raycast_bench [--seconds S]   S: timed work per scenario [s], default 2 (at least 1)
 *   raycast_bench --lidar-only    only the 3D lidar scenario (for perf record)
 *   raycast_bench --scans N       only the room, exactly N scans (rounded up to whole frames):
 *                                 the same work on every run, for instruction counts, e.g.
 *     valgrind --tool=callgrind --toggle-collect='mbot_sim::castScan*' raycast_bench --scans 2000
 *                                 (instructions per ray = the collected count / (N * 360))
 */
#include "mbot_sim/lidar3d.h"
#include "mbot_sim/raycast.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <random>
#include <string>
#include <vector>

namespace
{
using mbot_sim::Circle;
using mbot_sim::GridRaycaster;
using mbot_sim::ScanSpec;
using mbot_sim::ShapeSet;

constexpr double kResolution = 0.05;   // [m]
constexpr double kRoomSize = 20.0;     // [m]
constexpr double kWall = 0.1;          // wall thickness [m]
constexpr double kRobotRadius = 0.15;  // [m]
constexpr int kBeams = 360;
constexpr double kRangeMax = 8.0;  // [m]
constexpr double kSpeed = 0.5;     // robot speed [m/s]
constexpr double kFrameDt = 0.1;   // sim time between shape rebuilds [s] (a 10 Hz laser)

/// An occupancy grid being drawn, in metres.
struct Canvas
{
  unsigned size_x;
  unsigned size_y;
  std::vector<uint8_t> cells;

  Canvas(double width, double height)
      : size_x(static_cast<unsigned>(std::lround(width / kResolution))),
        size_y(static_cast<unsigned>(std::lround(height / kResolution))),
        cells(static_cast<size_t>(size_x) * size_y, 0)
  {}

  /// Mark every cell whose centre is within half a wall thickness of segment a-b [m].
  void wall(double ax, double ay, double bx, double by)
  {
    const double half = 0.5 * kWall;
    const int x0 = std::max(0, static_cast<int>((std::min(ax, bx) - half) / kResolution) - 1);
    const int x1 = std::min<int>(size_x - 1, static_cast<int>((std::max(ax, bx) + half) / kResolution) + 1);
    const int y0 = std::max(0, static_cast<int>((std::min(ay, by) - half) / kResolution) - 1);
    const int y1 = std::min<int>(size_y - 1, static_cast<int>((std::max(ay, by) + half) / kResolution) + 1);
    const double dx = bx - ax;
    const double dy = by - ay;
    const double len2 = dx * dx + dy * dy;
    for (int y = y0; y <= y1; ++y)
      for (int x = x0; x <= x1; ++x)
      {
        const double cx = (x + 0.5) * kResolution;
        const double cy = (y + 0.5) * kResolution;
        const double s = std::clamp(((cx - ax) * dx + (cy - ay) * dy) / len2, 0.0, 1.0);
        if (std::hypot(cx - ax - s * dx, cy - ay - s * dy) <= half + 1e-9)
          cells[static_cast<size_t>(y) * size_x + x] = 1;
      }
  }

  /// The benchmark room with its lower-left corner at (ox, oy) [m].
  void room(double ox, double oy)
  {
    const double e = 0.5 * kWall;  // walls run along the inside of the border
    const double s = kRoomSize;
    wall(ox + e, oy + e, ox + s - e, oy + e);
    wall(ox + e, oy + s - e, ox + s - e, oy + s - e);
    wall(ox + e, oy + e, ox + e, oy + s - e);
    wall(ox + s - e, oy + e, ox + s - e, oy + s - e);
    wall(ox + 0.0, oy + 10.0, ox + 8.0, oy + 10.0);     // left room, door from x = 8 to 12
    wall(ox + 12.0, oy + 4.0, ox + 12.0, oy + 16.0);    // central partition
    wall(ox + 14.0, oy + 5.0, ox + 20.0, oy + 5.0);     // right room
    wall(ox + 3.0, oy + 13.5, ox + 7.0, oy + 17.5);     // a diagonal wall
    for (double y = 13.5; y <= 14.5; y += kResolution)  // a 1 x 1 m pillar
      wall(ox + 15.5, oy + y, ox + 16.5, oy + y);
  }
};

struct Pose
{
  double x, y, yaw;
};

struct Robot
{
  double x, y, heading;
};

/// One benchmark scenario: a map, robots wandering in it, a pool of random free sensor poses.
struct Scenario
{
  GridRaycaster grid;
  std::vector<Robot> robots;
  std::vector<Pose> poses;
  std::mt19937 rng;

  Scenario(const Canvas& canvas, int robot_count, unsigned seed)
      : grid(canvas.cells, canvas.size_x, canvas.size_y, kResolution, 0.0, 0.0), rng(seed)
  {
    for (int i = 0; i < robot_count; ++i)
    {
      const Pose p = randomFreePose();
      robots.push_back({p.x, p.y, p.yaw});
    }
    for (int i = 0; i < 4096; ++i) poses.push_back(randomFreePose());
  }

  Pose randomFreePose()
  {
    std::uniform_real_distribution<double> ux(0.0, grid.sizeX() * kResolution);
    std::uniform_real_distribution<double> uy(0.0, grid.sizeY() * kResolution);
    std::uniform_real_distribution<double> uyaw(-M_PI, M_PI);
    for (;;)
    {
      const Pose p{ux(rng), uy(rng), uyaw(rng)};
      if (grid.clearanceAt(p.x, p.y) > 2.0 * kRobotRadius) return p;
    }
  }

  /// True when (x, y) [m] is inside a robot: a sensor there would read nothing but -Inf.
  bool insideRobot(double x, double y) const
  {
    for (const Robot& r : robots)
      if (std::hypot(r.x - x, r.y - y) <= kRobotRadius) return true;
    return false;
  }

  /// Drive every robot straight on; one that would get close to a wall turns randomly.
  void moveRobots()
  {
    std::uniform_real_distribution<double> uyaw(-M_PI, M_PI);
    for (Robot& r : robots)
    {
      const double nx = r.x + kSpeed * kFrameDt * std::cos(r.heading);
      const double ny = r.y + kSpeed * kFrameDt * std::sin(r.heading);
      if (grid.clearanceAt(nx, ny) > kRobotRadius + kResolution)
      {
        r.x = nx;
        r.y = ny;
      }
      else
      {
        r.heading = uyaw(rng);
      }
    }
  }
};

struct Result
{
  double rays_per_second = 0.0;
  double cpu_rays_per_second = 0.0;  ///< per second of CPU time: robust on a busy machine
  double seconds = 0.0;
  long scans = 0;
  double returns_fraction = 0.0;  ///< share of finite readings (sanity: the work is real)
  double rebuild_us = 0.0;        ///< mean ShapeSet rebuild time per frame [us]
};

/// Per frame: move the robots, rebuild the shape set, cast `scans_per_frame` scans from the
/// next poses of the pool that are not inside a robot. Times the ray casting work (rebuild +
/// scans, not the robots' motion nor picking poses) until it adds up to `min_seconds`, or, when
/// `exact_scans` > 0, until that many scans are cast.
Result run(Scenario& sc, int scans_per_frame, double min_seconds, long exact_scans = 0)
{
  using Clock = std::chrono::steady_clock;
  ShapeSet shapes(4.0);
  std::vector<float> ranges;
  ScanSpec spec;
  spec.beams = kBeams;
  spec.min_angle = -M_PI;
  spec.angle_increment = 2.0 * M_PI / kBeams;
  spec.range_min = 0.05;
  spec.range_max = kRangeMax;

  Result res;
  std::vector<const Pose*> frame_poses;
  long finite = 0;
  long rays = 0;
  size_t next_pose = 0;
  double rebuild_s = 0.0;
  long frames = 0;
  double elapsed = 0.0;
  double cpu_seconds = 0.0;
  while (exact_scans > 0 ? rays < exact_scans * kBeams : elapsed < min_seconds)
  {
    sc.moveRobots();
    frame_poses.clear();
    while (static_cast<int>(frame_poses.size()) < scans_per_frame)
    {
      const Pose& p = sc.poses[next_pose++ % sc.poses.size()];
      if (!sc.insideRobot(p.x, p.y)) frame_poses.push_back(&p);
    }

    const auto start = Clock::now();
    const std::clock_t cpu_start = std::clock();
    shapes.clear();
    for (size_t i = 0; i < sc.robots.size(); ++i)
    {
      Circle c;
      c.x = sc.robots[i].x;
      c.y = sc.robots[i].y;
      c.radius = kRobotRadius;
      c.owner = static_cast<int>(i);
      shapes.addCircle(c);
    }
    const auto rebuilt = Clock::now();
    ++frames;

    for (const Pose* p : frame_poses)
    {
      spec.x = p->x;
      spec.y = p->y;
      spec.yaw = p->yaw;
      mbot_sim::castScan(sc.grid, shapes, spec, ranges);
      rays += kBeams;
      for (float r : ranges) finite += std::isfinite(r) ? 1 : 0;
    }
    const auto end = Clock::now();
    rebuild_s += std::chrono::duration<double>(rebuilt - start).count();
    elapsed += std::chrono::duration<double>(end - start).count();
    cpu_seconds += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
  }
  res.seconds = elapsed;
  res.cpu_rays_per_second = rays / cpu_seconds;
  res.scans = rays / kBeams;
  res.rays_per_second = rays / elapsed;
  res.returns_fraction = static_cast<double>(finite) / rays;
  res.rebuild_us = 1e6 * rebuild_s / frames;
  return res;
}
struct LidarResult
{
  double points_per_second = 0.0;  ///< rays cast per wall second
  double cpu_points_per_second = 0.0;
  double returns_fraction = 0.0;  ///< points kept (hits within range) per ray
  double seconds = 0.0;
  long rays = 0;
};

/// The 3D lidar on robot 0 of the room scenario, stepped at 0.01 s as the simulator does: each
/// step rebuilds the prisms (the robots and two boxes), picks those in reach and casts the
/// points of the step from poses interpolated over it. Timed: the whole step.
LidarResult runLidar(Scenario& sc, double min_seconds)
{
  using Clock = std::chrono::steady_clock;
  mbot_sim::Scene25D scene(&sc.grid, 2.5);
  mbot_sim::LidarSpec spec;
  spec.range_noise = 0.02;
  spec.range_quantization = 0.001;
  mbot_sim::LidarScanner lidar(spec, -0.06, 0.0, 0.26, 0.0, 0.0);
  mbot_sim::PrismQuery near;
  std::mt19937 rng(7);
  std::vector<mbot_sim::LidarFrame> frames;
  const double dt = 0.01;
  double t = 0.0, elapsed = 0.0, cpu = 0.0;
  long rays = 0, kept = 0;
  const Robot& me = sc.robots[0];
  mbot_sim::PlanarPose last{me.x, me.y, me.heading};
  while (elapsed < min_seconds)
  {
    sc.moveRobots();  // one motion per kFrameDt (0.1 s): ten steps, poses interpolated
    const mbot_sim::PlanarPose next{me.x, me.y, me.heading};
    for (int k = 1; k <= 10; ++k)
    {
      const double f = k / 10.0;
      const double turn = std::remainder(next.theta - last.theta, 2.0 * M_PI);
      const mbot_sim::PlanarPose p0{last.x + (f - 0.1) * (next.x - last.x), last.y + (f - 0.1) * (next.y - last.y),
                                    last.theta + (f - 0.1) * turn};
      const mbot_sim::PlanarPose p1{last.x + f * (next.x - last.x), last.y + f * (next.y - last.y),
                                    last.theta + f * turn};
      const auto start = Clock::now();
      const std::clock_t cpu_start = std::clock();
      scene.clearPrisms();
      for (size_t i = 0; i < sc.robots.size(); ++i)
      {
        mbot_sim::Prism prism;
        prism.x = sc.robots[i].x;
        prism.y = sc.robots[i].y;
        prism.radius = kRobotRadius;
        prism.height = 0.3;
        prism.owner = static_cast<int>(i);
        scene.addPrism(prism);
      }
      mbot_sim::Prism box;
      box.is_box = true;
      box.half_length = 0.4;
      box.half_width = 0.3;
      box.height = 0.8;
      box.x = 5.0, box.y = 5.0;
      scene.addPrism(box);
      box.x = 17.0, box.y = 10.0, box.yaw = 0.5;
      scene.addPrism(box);
      near.prepare(scene, p1.x, p1.y, spec.range_max + 1.0, 0);
      frames.clear();
      rays += static_cast<long>(lidar.advance(scene, near, t, p0, t + dt, p1, rng, frames));
      for (const auto& frame : frames) kept += static_cast<long>(frame.points.size());
      elapsed += std::chrono::duration<double>(Clock::now() - start).count();
      cpu += static_cast<double>(std::clock() - cpu_start) / CLOCKS_PER_SEC;
      t += dt;
    }
    last = next;
  }
  LidarResult res;
  res.points_per_second = rays / elapsed;
  res.cpu_points_per_second = rays / cpu;
  res.returns_fraction = static_cast<double>(kept) / rays;
  res.seconds = elapsed;
  res.rays = rays;
  return res;
}
}  // namespace

int main(int argc, char** argv)
{
  double seconds = 2.0;
  long exact_scans = 0;
  bool lidar_only = false;
  for (int i = 1; i < argc; ++i)
  {
    if (std::strcmp(argv[i], "--seconds") == 0 && i + 1 < argc)
      seconds = std::max(1.0, std::atof(argv[++i]));
    else if (std::strcmp(argv[i], "--scans") == 0 && i + 1 < argc)
      exact_scans = std::max(1L, std::atol(argv[++i]));
    else if (std::strcmp(argv[i], "--lidar-only") == 0)
      lidar_only = true;
    else
    {
      std::fprintf(stderr, "usage: %s [--seconds S | --scans N | --lidar-only]\n", argv[0]);
      return 2;
    }
  }

  // The room with 10 robots: the headline number.
  Canvas room(kRoomSize, kRoomSize);
  room.room(0.0, 0.0);
  Scenario small(room, 10, 1);
  auto print_lidar = [](const LidarResult& l) {
    std::printf(
        "\"lidar\": {\"points_per_second\": %.0f, \"cpu_points_per_second\": %.0f, \"returns_fraction\": %.3f, "
        "\"rays\": %ld, \"seconds\": %.3f, \"points_per_frame\": 20000, \"rate\": 10}",
        l.points_per_second, l.cpu_points_per_second, l.returns_fraction, l.rays, l.seconds);
  };
  if (lidar_only)
  {
    runLidar(small, 0.2);
    const LidarResult l = runLidar(small, seconds);
    std::printf("{");
    print_lidar(l);
    std::printf("}\n");
    return 0;
  }
  if (exact_scans > 0)
  {
    const Result r = run(small, 10, 0.0, exact_scans);
    std::printf(
        "{\"rays\": %ld, \"rays_per_second\": %.0f, \"cpu_rays_per_second\": %.0f, "
        "\"returns_fraction\": %.3f}\n",
        r.scans * kBeams, r.rays_per_second, r.cpu_rays_per_second, r.returns_fraction);
    return 0;
  }
  run(small, 10, 0.2);  // warm up caches and the CPU clock
  const Result a = run(small, 10, seconds);

  // The room tiled 3 x 3 (60 x 60 m) with 1000 robots: a scan must only visit nearby buckets.
  Canvas big(3 * kRoomSize, 3 * kRoomSize);
  for (int j = 0; j < 3; ++j)
    for (int i = 0; i < 3; ++i) big.room(i * kRoomSize, j * kRoomSize);
  Scenario large(big, 1000, 2);
  const Result b = run(large, 100, seconds);
  Scenario lidar_room(room, 10, 3);
  runLidar(lidar_room, 0.2);
  const LidarResult l = runLidar(lidar_room, seconds);

  // One JSON line (scripts/bench reads the last line starting with '{').
  std::printf("{\"rays_per_second\": %.0f, \"beams\": %d, \"range_max\": %.1f, ", a.rays_per_second, kBeams, kRangeMax);
  std::printf(
      "\"cpu_rays_per_second\": %.0f, \"ns_per_ray\": %.2f, \"scans\": %ld, "
      "\"seconds\": %.3f, ",
      a.cpu_rays_per_second, 1e9 / a.rays_per_second, a.scans, a.seconds);
  std::printf(
      "\"map\": \"room 20x20 m, 0.05 m cells\", \"robots\": 10, "
      "\"returns_fraction\": %.3f, \"shape_rebuild_us\": %.2f, ",
      a.returns_fraction, a.rebuild_us);
  std::printf(
      "\"large_map\": {\"rays_per_second\": %.0f, \"cpu_rays_per_second\": %.0f, "
      "\"scans\": %ld, \"seconds\": %.3f, \"map\": \"room tiled 3x3, 60x60 m\", "
      "\"robots\": 1000, \"returns_fraction\": %.3f, \"shape_rebuild_us\": %.2f}, ",
      b.rays_per_second, b.cpu_rays_per_second, b.scans, b.seconds, b.returns_fraction, b.rebuild_us);
  print_lidar(l);
  std::printf("}\n");
  return 0;
}
