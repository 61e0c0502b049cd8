/**
 * @file dwa_bench.cpp
 * @brief DWA cycle time at default sampling on a typical local costmap (scripts/bench nav).
 *
 * A 4 x 4 m local costmap at 0.05 m (80 x 80 cells) around the robot, with a wall, a box and a
 * post inflated by the InflationLayer (radius 0.55 m), and a global plan through it. The robot
 * drives at 0.3 m/s; its pose is jittered a little every cycle so that no two cycles are alike.
 * 100 warm-up cycles, then the measured ones, on one thread.
 *
 * Usage: dwa_bench [--omni] [--cycles N]
 *   --omni      sample v_y too (dwa_local_planner's defaults: 3 x 10 x 20 samples); without it,
 *               a differential drive (max_vel_y = min_vel_y = 0: 3 x 20 samples)
 *   --cycles N  measured cycles (default 1000)
 * Prints {"p50": ms, "p99": ms, "wall_p50": ms, "wall_p99": ms} on stdout, details on stderr.
 * p50 and p99 are the thread's CPU time per cycle, so that other processes on a shared machine
 * do not count; wall_* are the wall-clock times, for comparison.
 */
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include <time.h>

#include "mbot_navigation/dwa_planner.h"
#include "mbot_navigation/inflation_layer.h"

using namespace mbot_navigation;

namespace
{
/// Mark the cells of the world rectangle [x0, x1] x [y0, y1] [m] LETHAL.
void addBox(Costmap2D& map, double x0, double y0, double x1, double y1)
{
  for (double y = y0; y <= y1; y += 0.5 * map.resolution())
    for (double x = x0; x <= x1; x += 0.5 * map.resolution())
    {
      unsigned mx, my;
      if (map.worldToMap(x, y, mx, my)) map.setCost(mx, my, cost::LETHAL);
    }
}

/// CPU time of the calling thread [ms]: unlike wall-clock time, it does not count the time other
/// processes had the core (the machines that run the benches are shared).
double threadCpuMs()
{
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

/// The q-quantile of `values` (nearest rank), sorting them.
double percentile(std::vector<double>& values, double q)
{
  std::sort(values.begin(), values.end());
  const size_t k = static_cast<size_t>(std::ceil(q * values.size()));
  return values[std::min(values.size(), std::max<size_t>(k, 1)) - 1];
}

int usage(const char* msg)
{
  std::cerr << "dwa_bench: " << msg << "\nusage: dwa_bench [--omni] [--cycles N]\n";
  return 2;
}
}  // namespace

int main(int argc, char** argv)
{
  bool omni = false;
  int cycles = 1000;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--omni")
      omni = true;
    else if (arg == "--cycles" && i + 1 < argc)
    {
      char* end = nullptr;
      cycles = static_cast<int>(std::strtol(argv[++i], &end, 10));
      if (*end != '\0' || cycles < 1) return usage("--cycles expects a positive integer");
    }
    else
      return usage(("unknown argument '" + arg + "'").c_str());
  }

  // The robot at the centre of its rolling window.
  const Pose2D robot{0.0, 0.0, 0.1};
  Costmap2D map(80, 80, 0.05, -2.0, -2.0);
  addBox(map, -1.5, 1.1, 0.2, 1.2);    // a wall on the left
  addBox(map, 0.9, -0.9, 1.3, -0.5);   // a box on the right
  addBox(map, 0.75, 0.75, 0.9, 0.9);   // a post ahead, left
  addBox(map, 1.7, -0.1, 2.0, 0.1);    // something at the window's edge
  InflationLayerConfig inflation_config;  // move_base's defaults: 0.55 m, scaling 10
  InflationLayer inflation(inflation_config);
  inflation.onFootprintChanged(0.15);  // mbot's footprint radius (URDF)
  inflation.inflate(map);

  // A global plan from behind the window to beyond it, bending between the obstacles.
  std::vector<Pose2D> plan;
  for (double x = -3.0; x <= 4.0; x += 0.05)
  {
    const double y = x < 0.0 ? 0.0 : 0.25 * std::sin(0.8 * x);
    plan.push_back(Pose2D{x, y, 0.0});
  }

  DwaConfig config;  // dwa_local_planner's defaults
  config.footprint_radius = 0.15;
  if (!omni)
  {
    config.max_vel_y = 0.0;
    config.min_vel_y = 0.0;
  }
  DwaPlanner planner(config);
  planner.setPlan(plan);

  std::mt19937 rng(7);
  std::uniform_real_distribution<double> jitter(-0.03, 0.03);
  std::vector<double> times_ms;  // CPU time of this thread per cycle
  std::vector<double> wall_ms;   // wall-clock time per cycle
  times_ms.reserve(cycles);
  wall_ms.reserve(cycles);
  int failures = 0;
  long samples = 0;
  const int warmup = 100;
  for (int i = 0; i < warmup + cycles; ++i)
  {
    const Pose2D pose{robot.x + jitter(rng), robot.y + jitter(rng), robot.theta + jitter(rng)};
    const Twist2D velocity{0.3 + jitter(rng), omni ? jitter(rng) : 0.0, 10.0 * jitter(rng)};
    Twist2D cmd;
    const auto t0 = std::chrono::steady_clock::now();
    const double cpu0 = threadCpuMs();
    const LocalPlanResult result = planner.computeVelocityCommands(pose, velocity, map, cmd);
    const double cpu1 = threadCpuMs();
    const auto t1 = std::chrono::steady_clock::now();
    if (i < warmup) continue;
    times_ms.push_back(cpu1 - cpu0);
    wall_ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
    failures += result.ok ? 0 : 1;
    samples += result.samples;
  }

  std::fprintf(stderr, "dwa_bench: %s, %d cycles, %.1f trajectories per cycle, %d failed cycles\n",
               omni ? "omni" : "diff drive", cycles, static_cast<double>(samples) / cycles, failures);
  std::printf("{\"p50\": %.4f, \"p99\": %.4f, \"wall_p50\": %.4f, \"wall_p99\": %.4f}\n",
              percentile(times_ms, 0.50), percentile(times_ms, 0.99), percentile(wall_ms, 0.50),
              percentile(wall_ms, 0.99));
  return failures == 0 ? 0 : 1;
}
