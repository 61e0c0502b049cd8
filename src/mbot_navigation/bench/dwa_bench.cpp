/**
 * @file dwa_bench.cpp
 * @brief DWA cycle time at default or shipped sampling on a typical local costmap (scripts/bench nav).
 *
 * A 4 x 4 m local costmap at 0.05 m (80 x 80 cells) around the robot, with a wall, a box and a
 * post inflated by the InflationLayer (radius 0.55 m), and a global plan through it. The robot
 * drives at 0.3 m/s; its pose is jittered a little every cycle so that no two cycles are alike.
 * 100 warm-up cycles, then the measured ones, on one thread.
 *
 * Usage: dwa_bench [--omni] [--cycles N] [--config nav_dwa.yaml --description DIR [--model mbot]]
 *   --omni      sample v_y too (dwa_local_planner's defaults: 3 x 10 x 20 samples); without it,
 *               a differential drive (max_vel_y = min_vel_y = 0: 3 x 20 samples)
 *   --cycles N  measured cycles (default 1000)
 *   --config    the shipped settings instead of dwa_local_planner's defaults, as the nav node
 *               builds them: the defaults, then the robot model's limits and footprint radius
 *               (mbot_description package DIR, model mbot unless --model), then the file's
 *               `DWAPlannerROS` keys (config/nav_dwa.yaml: 6 x 20 samples over 1.5 s)
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
#include <stdexcept>
#include <string>
#include <vector>

#include <time.h>

#include "mbot_common/strict_yaml.h"
#include "mbot_description/robot_model.h"
#include "mbot_navigation/local_planner/dwa_model_limits.h"
#include "mbot_navigation/local_planner/dwa_planner.h"
#include "mbot_navigation/costmap/inflation_layer.h"

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
  std::cerr << "dwa_bench: " << msg
            << "\nusage: dwa_bench [--omni] [--cycles N] [--config nav_dwa.yaml --description DIR [--model mbot]]\n";
  return 2;
}

/**
 * The DWA settings the nav node would use with this config file (nav_node.cpp, readDwaConfig):
 * dwa_local_planner's defaults, the robot model's limits, then the `DWAPlannerROS` keys.
 */
DwaConfig shippedConfig(const std::string& path, const std::string& description_dir, const std::string& model_name)
{
  const mbot_description::RobotModel model = mbot_description::loadRobotModel(description_dir, model_name);
  DwaConfig c;
  applyModelLimits(model.limits, c);
  c.footprint_radius = model.footprint_radius;

  const mbot_common::StrictYaml<> yaml(path);
  const YAML::Node dwa = yaml.load()["DWAPlannerROS"];
  if (!dwa) yaml.fail("DWAPlannerROS", "missing (the bench reads the keys from there)");
  const std::vector<std::pair<const char*, double*>> numbers = {
      {"max_vel_trans", &c.max_vel_trans},
      {"min_vel_trans", &c.min_vel_trans},
      {"max_vel_x", &c.max_vel_x},
      {"min_vel_x", &c.min_vel_x},
      {"max_vel_y", &c.max_vel_y},
      {"min_vel_y", &c.min_vel_y},
      {"max_vel_theta", &c.max_vel_theta},
      {"min_vel_theta", &c.min_vel_theta},
      {"acc_lim_x", &c.acc_lim_x},
      {"acc_lim_y", &c.acc_lim_y},
      {"acc_lim_theta", &c.acc_lim_theta},
      {"trans_stopped_vel", &c.trans_stopped_vel},
      {"theta_stopped_vel", &c.theta_stopped_vel},
      {"xy_goal_tolerance", &c.xy_goal_tolerance},
      {"yaw_goal_tolerance", &c.yaw_goal_tolerance},
      {"sim_time", &c.sim_time},
      {"sim_granularity", &c.sim_granularity},
      {"angular_sim_granularity", &c.angular_sim_granularity},
      {"path_distance_bias", &c.path_distance_bias},
      {"goal_distance_bias", &c.goal_distance_bias},
      {"occdist_scale", &c.occdist_scale},
      {"twirling_scale", &c.twirling_scale},
      {"forward_point_distance", &c.forward_point_distance},
      {"oscillation_reset_dist", &c.oscillation_reset_dist},
      {"oscillation_reset_angle", &c.oscillation_reset_angle}};
  const std::vector<std::pair<const char*, int*>> integers = {
      {"vx_samples", &c.vx_samples}, {"vy_samples", &c.vy_samples}, {"vth_samples", &c.vth_samples}};
  const std::vector<std::pair<const char*, bool*>> flags = {{"latch_xy_goal_tolerance", &c.latch_xy_goal_tolerance},
                                                            {"prune_plan", &c.prune_plan}};
  std::vector<std::string> known;
  for (const auto& k : numbers) known.push_back(k.first);
  for (const auto& k : integers) known.push_back(k.first);
  for (const auto& k : flags) known.push_back(k.first);
  yaml.checkKeys(dwa, "DWAPlannerROS", known);
  const std::string where = "DWAPlannerROS.";
  for (const auto& k : numbers)
    if (dwa[k.first]) *k.second = yaml.number(dwa[k.first], where + k.first);
  for (const auto& k : integers)
    if (dwa[k.first]) *k.second = static_cast<int>(yaml.integer(dwa[k.first], where + k.first));
  for (const auto& k : flags)
    if (dwa[k.first]) *k.second = yaml.boolean(dwa[k.first], where + k.first);
  c.validate();
  return c;
}
}  // namespace

int main(int argc, char** argv)
{
  bool omni = false;
  int cycles = 1000;
  std::string config_path, description_dir, model_name = "mbot";
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    if (arg == "--omni")
      omni = true;
    else if (arg == "--config" && i + 1 < argc)
      config_path = argv[++i];
    else if (arg == "--description" && i + 1 < argc)
      description_dir = argv[++i];
    else if (arg == "--model" && i + 1 < argc)
      model_name = argv[++i];
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
  addBox(map, -1.5, 1.1, 0.2, 1.2);       // a wall on the left
  addBox(map, 0.9, -0.9, 1.3, -0.5);      // a box on the right
  addBox(map, 0.75, 0.75, 0.9, 0.9);      // a post ahead, left
  addBox(map, 1.7, -0.1, 2.0, 0.1);       // something at the window's edge
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

  if (!config_path.empty() && description_dir.empty()) return usage("--config needs --description DIR");
  DwaConfig config;  // dwa_local_planner's defaults
  config.footprint_radius = 0.15;
  if (!config_path.empty())
  {
    try
    {
      config = shippedConfig(config_path, description_dir, model_name);
    }
    catch (const std::exception& e)
    {
      std::cerr << "dwa_bench: " << e.what() << "\n";
      return 2;
    }
    omni = config.max_vel_y != config.min_vel_y;
  }
  else if (!omni)
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

  std::fprintf(stderr, "dwa_bench: %s%s, %d cycles, %.1f trajectories per cycle, %d failed cycles\n",
               omni ? "omni" : "diff drive", config_path.empty() ? "" : (", " + config_path).c_str(), cycles,
               static_cast<double>(samples) / cycles, failures);
  std::printf("{\"p50\": %.4f, \"p99\": %.4f, \"wall_p50\": %.4f, \"wall_p99\": %.4f}\n", percentile(times_ms, 0.50),
              percentile(times_ms, 0.99), percentile(wall_ms, 0.50), percentile(wall_ms, 0.99));
  return failures == 0 ? 0 : 1;
}
