/**
 * @file sim_bench.cpp
 * @brief Simulator benchmark without ROS: N wandering robots, each with its 360-beam 10 Hz laser,
 *        physics at 100 Hz, as fast as possible on one thread. Prints one JSON line:
 *        {"robots": N, "sim_seconds": S, "wall_seconds": W, "rtf": S/W, "rays_per_second": ...,
 *         "peak_rss_mb": ..., "cpu_seconds": C, "rtf_cpu": S/C, "load_seconds": L,
 *         "rtf_with_loading": S/(L+W)}  (C: CPU time of the process; it differs from W when the
 *        core is shared. W is the stepping alone; L is what comes before it: reading the robot
 *        model and the map, building the world and placing the robots, timed from main(), so
 *        rtf_with_loading is the figure of a whole run, as Stage's benchmark times its runs.)
 *
 *   sim_bench --robots 100 --map maps/bench_room.yaml --seconds 20
 *   sim_bench --robots 10 --lidar 10 --seconds 20   the first 10 robots also carry the 3D lidar
 *                                                   (world file defaults: 20000 points at 10 Hz)
 *
 * With --lidar K the line also has "lidar_robots": K, "lidar_rays_per_second" (3D rays cast per
 * wall second of stepping), "lidar_rays_per_cpu_second" and "lidar_points" (points in the
 * frames handed to the listener, as stage_node would publish them).
 *
 * Every robot wanders: it drives at 0.4 m/s and, when its own scan shows an obstacle ahead,
 * stops and turns towards the freer side until the way is clear. Robots start at random free
 * poses (seeded) with clearance around them.
 */
#include "mbot_sim/world.h"

#include <mbot_description/robot_model.h>

#include <sys/resource.h>

#include <chrono>
#include <ctime>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <random>
#include <string>
#include <vector>

namespace
{
constexpr double kPi = 3.14159265358979323846;

struct Options
{
  int robots = 10;
  std::string map = std::string(MBOT_MAPS_DIR) + "/bench_room.yaml";
  double seconds = 20.0;  ///< [s sim time]
  unsigned seed = 1;
  std::string model = "mbot";
  std::string description = MBOT_DESCRIPTION_DIR;
  double physics_step = 0.01;  ///< [s]
  double speed = 0.4;          ///< [m/s] wander speed
  double clearance = 0.2;      ///< [m] free space around each start pose, beyond the footprint
  int lidar = 0;               ///< robots with the 3D lidar (the first ones)
};

void usage()
{
  std::cerr << "usage: sim_bench [--robots N] [--map MAP.yaml] [--seconds S] [--seed K] [--model mbot]\n"
               "                 [--description MBOT_DESCRIPTION_DIR] [--physics-step DT] [--lidar K]\n";
}

Options parse(int argc, char** argv)
{
  Options o;
  for (int i = 1; i < argc; ++i)
  {
    const std::string arg = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc)
      {
        std::cerr << "sim_bench: " << arg << ": expected a value\n";
        usage();
        std::exit(2);
      }
      return argv[++i];
    };
    try
    {
      if (arg == "--robots")
        o.robots = std::stoi(value());
      else if (arg == "--map")
        o.map = value();
      else if (arg == "--seconds")
        o.seconds = std::stod(value());
      else if (arg == "--seed")
        o.seed = static_cast<unsigned>(std::stoul(value()));
      else if (arg == "--model")
        o.model = value();
      else if (arg == "--description")
        o.description = value();
      else if (arg == "--physics-step")
        o.physics_step = std::stod(value());
      else if (arg == "--lidar")
        o.lidar = std::stoi(value());
      else if (arg == "--help" || arg == "-h")
      {
        usage();
        std::exit(0);
      }
      else
      {
        std::cerr << "sim_bench: unknown option " << arg << "\n";
        usage();
        std::exit(2);
      }
    }
    catch (const std::logic_error&)
    {
      std::cerr << "sim_bench: " << arg << ": not a number\n";
      std::exit(2);
    }
  }
  if (o.robots < 1 || !(o.seconds > 0.0) || o.lidar < 0 || o.lidar > o.robots)
  {
    std::cerr << "sim_bench: expected --robots >= 1, --seconds > 0 and --lidar in [0, robots]\n";
    std::exit(2);
  }
  return o;
}

/// Wander on the robot's own scan: go straight while the sector ahead is clear, else turn in
/// place towards the side with more room (and keep that turn until clear, so it does not dither).
class Wanderer : public mbot_sim::SensorListener
{
public:
  Wanderer(mbot_sim::World& world, const mbot_description::RobotModel& model, double speed)
      : world_(world), range_max_(model.laser.range_max), speed_(speed)
  {
    // Which beams look ahead, left and right: fixed by the model, so classified once.
    const double inc = model.laser.angleIncrement();
    for (int i = 0; i < model.laser.beams; ++i)
    {
      const double angle = std::remainder(model.laser.min_angle + i * inc + model.laser.mount_yaw, 2.0 * kPi);
      if (std::abs(angle) < 0.6) ahead_.push_back(i);
      if (angle > 0.2 && angle < 1.6) left_.push_back(i);
      if (angle < -0.2 && angle > -1.6) right_.push_back(i);
    }
  }

  void onScan(int robot, const mbot_sim::ScanSample& scan) override
  {
    if (robot >= static_cast<int>(turn_.size())) turn_.resize(robot + 1, 0.0);
    auto range = [&](int i) {
      const float r = scan.ranges[i];
      return std::isfinite(r) ? static_cast<double>(r) : (r > 0 ? range_max_ : 0.0);
    };
    double ahead = range_max_, left = 0.0, right = 0.0;
    for (int i : ahead_) ahead = std::min(ahead, range(i));
    for (int i : left_) left += range(i);
    for (int i : right_) right += range(i);
    mbot_sim::Twist2D cmd;
    if (ahead < 0.6)
    {
      if (turn_[robot] == 0.0) turn_[robot] = left >= right ? 1.5 : -1.5;
      cmd.wz = turn_[robot];
    }
    else
    {
      turn_[robot] = 0.0;
      cmd.vx = speed_;
    }
    world_.setCommand(robot, cmd);
  }

  void onPointCloud(int /*robot*/, const mbot_sim::LidarFrame& frame) override { points += frame.points.size(); }

  unsigned long long points = 0;  ///< 3D lidar points handed over

private:
  mbot_sim::World& world_;
  double range_max_;                       ///< [m]
  double speed_;                           ///< [m/s]
  std::vector<int> ahead_, left_, right_;  ///< beam indices of the three sectors
  std::vector<double> turn_;               ///< [rad/s] the turn a robot is in, 0 when driving
};

double cpuSeconds()
{
  timespec t;
  clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t);
  return t.tv_sec + 1e-9 * t.tv_nsec;
}

double peakRssMb()
{
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  return usage.ru_maxrss / 1024.0;  // ru_maxrss is in KiB on Linux
}

}  // namespace

int main(int argc, char** argv)
{
  const auto load_start = std::chrono::steady_clock::now();  // a whole run: loading, placing, stepping
  const Options opt = parse(argc, argv);
  try
  {
    const mbot_description::RobotModel model = mbot_description::loadRobotModel(opt.description, opt.model);
    const mbot_sim::OccupancyMap map = mbot_sim::loadMap(opt.map);
    mbot_sim::WorldSettings settings;
    settings.physics_step = opt.physics_step;
    settings.seed = opt.seed;
    mbot_sim::World world(map, settings);

    // Random free start poses, seeded.
    std::mt19937 rng(opt.seed);
    std::uniform_real_distribution<double> ux(map.origin_x, map.origin_x + map.width * map.resolution);
    std::uniform_real_distribution<double> uy(map.origin_y, map.origin_y + map.height * map.resolution);
    std::uniform_real_distribution<double> uyaw(-kPi, kPi);
    const double keep_clear = model.footprint_radius + opt.clearance;
    long attempts = 0;
    const long max_attempts = 2000L * opt.robots + 10000;
    for (int i = 0; i < opt.robots; ++i)
    {
      for (;;)
      {
        if (++attempts > max_attempts)
        {
          std::cerr << "sim_bench: placed only " << i << " of " << opt.robots << " robots with " << opt.clearance
                    << " m clearance in " << opt.map << " (use a larger map, e.g. bench_room_3x3.yaml)\n";
          return 1;
        }
        const double x = ux(rng), y = uy(rng);
        if (!world.isFree(x, y, keep_clear)) continue;
        world.addRobot("robot_" + std::to_string(i), model, mbot_sim::Pose2D{x, y, uyaw(rng)});
        break;
      }
    }

    for (int id : world.robotIds())
    {
      if (id >= opt.lidar) break;
      mbot_common::LidarConfig lidar;
      lidar.enabled = true;
      world.setLidar(id, lidar);
    }
    Wanderer wanderer(world, model, opt.speed);
    world.setListener(&wanderer);
    for (int id : world.robotIds()) world.setCommand(id, mbot_sim::Twist2D{opt.speed, 0.0, 0.0});

    const long steps = std::lround(opt.seconds / opt.physics_step);
    const auto start = std::chrono::steady_clock::now();
    const double load = std::chrono::duration<double>(start - load_start).count();
    const double cpu_start = cpuSeconds();
    for (long i = 0; i < steps; ++i) world.step();
    const double wall = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    const double cpu = cpuSeconds() - cpu_start;  // differs from wall when the core is shared

    const double sim = steps * opt.physics_step;
    std::printf(
        "{\"robots\": %d, \"sim_seconds\": %.3f, \"wall_seconds\": %.3f, \"rtf\": %.3f, \"rays_per_second\": %.0f, "
        "\"peak_rss_mb\": %.1f, \"cpu_seconds\": %.3f, \"rtf_cpu\": %.3f, \"load_seconds\": %.3f, "
        "\"rtf_with_loading\": %.3f, \"map\": \"%s\", \"wall_boxes\": %zu, \"lidar_robots\": %d, "
        "\"lidar_rays_per_second\": %.0f, \"lidar_rays_per_cpu_second\": %.0f, \"lidar_points\": %llu}\n",
        opt.robots, sim, wall, sim / wall, world.raysCast() / wall, peakRssMb(), cpu, sim / cpu, load,
        sim / (load + wall), opt.map.c_str(), world.wallBoxCount(), opt.lidar, world.lidarRaysCast() / wall,
        world.lidarRaysCast() / cpu, wanderer.points);
  }
  catch (const std::exception& e)
  {
    std::cerr << "sim_bench: " << e.what() << "\n";
    return 1;
  }
  return 0;
}
