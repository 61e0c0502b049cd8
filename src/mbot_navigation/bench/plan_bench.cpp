/**
 * @file plan_bench.cpp
 * @brief Global planner benchmark on the shared inputs (src/mbot_navigation/bench/inputs, see its
 *        README): plan time p50/p95 [ms], mean path length [cells] and mean path cost over the
 *        start/goal pairs.
 *
 *   plan_bench --map map_1000.pgm --pairs pairs_1000.csv [--config nav_move_base.yaml]
 *              [--planner astar] [--json] [--cost-factor X] [--neutral-cost X]
 *              [--heuristic-weight X] [--smoothing-tolerance X] [--smoothing-passes N]
 *              [--no-smooth] [--verify-inflation] [--per-pair] [--only I,J,...] [--repeat N]
 *
 * The map is a raw cost PGM (P5, first row y = 0, no flip) read into a Costmap2D at 0.05 m/cell.
 * --config reads the A* settings from the `GlobalPlanner` section of a nav node config (the
 * shipped one is config/nav_move_base.yaml, which scripts/bench passes); without it the planner
 * runs with AStarConfig's defaults. The A* flags after it override single settings, for tuning.
 *
 * Two timings, one thread, steady_clock, planning only:
 *  - single (the headline, the peers' protocol): one warm-up plan, then one plan per pair, each a
 *    whole planner call as the nav node makes it (whatever it allocates is timed with it);
 *  - fastest of --repeat (default 5; 0 skips it): every pair planned N more times, the fastest
 *    counts. Other processes on a busy machine only ever add time, so the minimum is the best
 *    estimate of what the planner itself needs (but repeating one query also warms the caches).
 * Each returned path is checked afterwards (not timed): it must start and end at the pair's cells
 * and every pose must lie on a passable cell (cost < 253). Path length is the sum of the segment
 * lengths of the returned poses [cells]; path cost is the sum of the map's costs over the cells
 * the polyline through the poses passes through (each cell once; a segment through a cell corner
 * passes the two cells diagonal to each other, not the two beside the corner).
 *
 * Output: a text summary (also the thread's CPU time, which a busy machine inflates less than the
 * wall time, and the cells A* expanded), and with --json one line
 *   {"single_p50": ms, "single_p95": ms, "single_cpu_p50": ms, "single_cpu_p95": ms,
 *    "p50": ms, "p95": ms, "cpu_p50": ms, "cpu_p95": ms, "repeat": n,
 *    "mean_path_cells": cells, "mean_path_cost": cost, "failures": n, "invalid_paths": n}
 * (p50/p95 are the fastest-of-N wall times; single_* the single plans').
 * --verify-inflation re-inflates the map's lethal cells with InflationLayer (inscribed 0.15 m,
 * inflation 0.55 m, factor 10, the inputs' README) and fails unless every cell matches.
 * --per-pair prints one line per pair (time, cells expanded, path length and cost) to find the
 * slow tail; --only plans just the listed pair indices (0-based), e.g. to profile them.
 * Exit status 0 only when every pair was planned and every path is valid.
 */
#include <algorithm>
#include <cctype>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <ctime>
#include <fstream>
#include <limits>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>
#include <string>
#include <vector>

#include "mbot_common/strict_yaml.h"
#include "mbot_navigation/costmap/inflation_layer.h"
#include "mbot_navigation/global_planner/path_cost.h"
#include "mbot_navigation/global_planner/planner_factory.h"

using namespace mbot_navigation;

namespace
{
constexpr double kResolution = 0.05;  // [m/cell], from the inputs' README

struct Pair
{
  int sx, sy, gx, gy;
};

/// Read one header token of a PGM, skipping whitespace and # comments.
std::string pgmToken(std::istream& in)
{
  std::string tok;
  while (true)
  {
    const int c = in.get();
    if (c == EOF) break;
    if (c == '#')
    {
      std::string line;
      std::getline(in, line);
      continue;
    }
    if (std::isspace(c))
    {
      if (!tok.empty()) break;
      continue;
    }
    tok.push_back(static_cast<char>(c));
  }
  return tok;
}

Costmap2D readCostPgm(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot read the file");
  if (pgmToken(in) != "P5") throw std::runtime_error(path + ": expected a binary PGM (P5)");
  const int w = std::stoi(pgmToken(in)), h = std::stoi(pgmToken(in)), maxval = std::stoi(pgmToken(in));
  if (w <= 0 || h <= 0 || maxval != 255) throw std::runtime_error(path + ": expected maxval 255 and a size > 0");
  Costmap2D map(w, h, kResolution, 0.0, 0.0);
  in.read(reinterpret_cast<char*>(map.data()), static_cast<std::streamsize>(w) * h);
  if (in.gcount() != static_cast<std::streamsize>(w) * h) throw std::runtime_error(path + ": truncated pixel data");
  return map;  // first row of the file is y = 0: no flip
}

std::vector<Pair> readPairs(const std::string& path)
{
  std::ifstream in(path);
  if (!in) throw std::runtime_error(path + ": cannot read the file");
  std::string line;
  std::getline(in, line);  // idx,sx,sy,gx,gy,euclid_cells
  std::vector<Pair> pairs;
  int row = 1;
  while (std::getline(in, line))
  {
    ++row;
    if (line.empty()) continue;
    std::replace(line.begin(), line.end(), ',', ' ');
    std::istringstream s(line);
    int idx;
    Pair p;
    if (!(s >> idx >> p.sx >> p.sy >> p.gx >> p.gy))
      throw std::runtime_error(path + ": line " + std::to_string(row) + ": expected idx,sx,sy,gx,gy,...");
    pairs.push_back(p);
  }
  return pairs;
}

/// CPU time of this thread [ms] (wall time counts the other processes of a busy machine too).
double threadCpuMs()
{
  timespec ts;
  clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
  return ts.tv_sec * 1e3 + ts.tv_nsec * 1e-6;
}

double percentile(std::vector<double> v, double p)
{
  std::sort(v.begin(), v.end());
  const size_t rank = static_cast<size_t>(std::ceil(p * v.size()));  // nearest rank
  return v[std::min(v.size() - 1, rank == 0 ? 0 : rank - 1)];
}

/// Re-inflate the map's lethal cells with InflationLayer and count the cells that differ.
size_t verifyInflation(const Costmap2D& map)
{
  Costmap2D lethal(map.sizeX(), map.sizeY(), map.resolution(), 0.0, 0.0);
  for (size_t i = 0; i < static_cast<size_t>(map.sizeX()) * map.sizeY(); ++i)
    lethal.data()[i] = map.data()[i] == cost::LETHAL ? cost::LETHAL : cost::FREE;
  InflationLayer inflation;  // defaults: 0.55 m, 10 /m
  inflation.onFootprintChanged(0.15);
  const auto t0 = std::chrono::steady_clock::now();
  inflation.inflate(lethal);
  const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
  size_t diff = 0;
  for (size_t i = 0; i < static_cast<size_t>(map.sizeX()) * map.sizeY(); ++i) diff += lethal.data()[i] != map.data()[i];
  std::fprintf(stderr, "inflation check: %zu of %u cells differ from the input map (inflated in %.1f ms)\n", diff,
               map.sizeX() * map.sizeY(), ms);
  return diff;
}

/**
 * Read the A* settings from the `GlobalPlanner` section of a nav node config (the nav node reads
 * the same keys from ~GlobalPlanner/); keys that are not there keep AStarConfig's defaults.
 */
AStarConfig readAStarConfig(const std::string& path)
{
  const mbot_common::StrictYaml<> yaml(path);
  const YAML::Node root = yaml.load();
  AStarConfig c;
  const YAML::Node gp = root["GlobalPlanner"];
  if (!gp) return c;
  yaml.checkKeys(gp, "GlobalPlanner",
                 {"neutral_cost", "cost_factor", "allow_unknown", "heuristic_weight", "smooth_path",
                  "smoothing_tolerance", "smoothing_passes"});
  const auto num = [&](const char* key, double& value) {
    if (gp[key]) value = yaml.number(gp[key], std::string("GlobalPlanner.") + key);
  };
  const auto flag = [&](const char* key, bool& value) {
    if (gp[key]) value = yaml.boolean(gp[key], std::string("GlobalPlanner.") + key);
  };
  num("neutral_cost", c.neutral_cost);
  num("cost_factor", c.cost_factor);
  num("heuristic_weight", c.heuristic_weight);
  num("smoothing_tolerance", c.smoothing_tolerance);
  flag("allow_unknown", c.allow_unknown);
  flag("smooth_path", c.smooth_path);
  if (gp["smoothing_passes"])
    c.smoothing_passes = static_cast<int>(yaml.integer(gp["smoothing_passes"], "GlobalPlanner.smoothing_passes"));
  return c;
}

[[noreturn]] void usage(const std::string& why)
{
  std::cerr << "plan_bench: " << why
            << "\nusage: plan_bench --map FILE.pgm --pairs FILE.csv [--config nav_move_base.yaml]\n"
               "       [--planner astar] [--json] [--cost-factor X] [--neutral-cost X] [--heuristic-weight X]\n"
               "       [--smoothing-tolerance X] [--smoothing-passes N] [--no-smooth] [--verify-inflation]\n"
               "       [--per-pair] [--only I,J,...] [--repeat N]\n";
  std::exit(2);
}
}  // namespace

int main(int argc, char** argv)
{
  std::string map_path, pairs_path, planner_name = "astar";
  bool json = false, verify = false, per_pair = false;
  int repeat = 5;  // extra plans per pair for the fastest-of column
  std::vector<size_t> only;
  GlobalPlannerParams params;
  // --config first, wherever it stands, so that the single-setting flags override it.
  for (int i = 1; i + 1 < argc; ++i)
    if (std::string(argv[i]) == "--config")
    {
      try
      {
        params.astar = readAStarConfig(argv[i + 1]);
      }
      catch (const std::exception& e)
      {
        std::cerr << "plan_bench: " << e.what() << "\n";
        return 2;
      }
    }
  for (int i = 1; i < argc; ++i)
  {
    const std::string a = argv[i];
    auto value = [&]() -> std::string {
      if (i + 1 >= argc) usage(a + " needs a value");
      return argv[++i];
    };
    auto number = [&]() {
      const std::string v = value();
      try
      {
        return std::stod(v);
      }
      catch (const std::exception&)
      {
        usage(a + " expects a number, got '" + v + "'");
      }
    };
    if (a == "--map")
      map_path = value();
    else if (a == "--pairs")
      pairs_path = value();
    else if (a == "--config")
      value();  // read above
    else if (a == "--planner")
      planner_name = value();
    else if (a == "--json")
      json = true;
    else if (a == "--verify-inflation")
      verify = true;
    else if (a == "--per-pair")
      per_pair = true;
    else if (a == "--repeat")
    {
      repeat = static_cast<int>(number());
      if (repeat < 0) usage("--repeat expects a number >= 0");
    }
    else if (a == "--only")
    {
      std::string list = value();
      std::replace(list.begin(), list.end(), ',', ' ');
      std::istringstream s(list);
      for (size_t k; s >> k;) only.push_back(k);
      if (only.empty()) usage("--only expects pair indices, e.g. 3,17");
    }
    else if (a == "--cost-factor")
      params.astar.cost_factor = number();
    else if (a == "--neutral-cost")
      params.astar.neutral_cost = number();
    else if (a == "--heuristic-weight")
      params.astar.heuristic_weight = number();
    else if (a == "--smoothing-tolerance")
      params.astar.smoothing_tolerance = number();
    else if (a == "--no-smooth")
      params.astar.smooth_path = false;
    else if (a == "--smoothing-passes")
      params.astar.smoothing_passes = static_cast<int>(number());
    else
      usage("unknown argument '" + a + "'");
  }
  if (map_path.empty() || pairs_path.empty()) usage("--map and --pairs are required");

  try
  {
    const Costmap2D map = readCostPgm(map_path);
    std::vector<Pair> pairs = readPairs(pairs_path);
    if (!only.empty())
    {
      std::vector<Pair> picked;
      for (size_t k : only)
      {
        if (k >= pairs.size()) usage("--only: no pair " + std::to_string(k));
        picked.push_back(pairs[k]);
      }
      pairs.swap(picked);
    }
    if (pairs.empty()) throw std::runtime_error(pairs_path + ": no pairs");
    if (verify && verifyInflation(map) != 0) return 1;
    std::unique_ptr<GlobalPlanner> planner = makeGlobalPlanner(planner_name, params);
    const auto* astar = dynamic_cast<const AStarPlanner*>(planner.get());
    if (astar)
    {
      const AStarConfig& c = astar->config();
      std::printf(
          "A*: neutral_cost %g, cost_factor %g, heuristic_weight %g, smooth_path %s, smoothing_tolerance %g, "
          "smoothing_passes %d\n",
          c.neutral_cost, c.cost_factor, c.heuristic_weight, c.smooth_path ? "true" : "false", c.smoothing_tolerance,
          c.smoothing_passes);
    }

    auto pose = [&](int x, int y) {
      Pose2D p;
      map.mapToWorld(x, y, p.x, p.y);
      return p;
    };
    planner->makePlan(map, pose(pairs[0].sx, pairs[0].sy), pose(pairs[0].gx, pairs[0].gy));  // warm-up

    // Headline: one plan per pair.
    std::vector<double> ms, cpu_ms, lengths, costs, expanded;
    std::vector<uint32_t> mark(static_cast<size_t>(map.sizeX()) * map.sizeY(), 0);
    int failures = 0, invalid = 0;
    for (size_t k = 0; k < pairs.size(); ++k)
    {
      const Pair& p = pairs[k];
      const Pose2D s = pose(p.sx, p.sy), g = pose(p.gx, p.gy);
      const double c0 = threadCpuMs();
      const auto t0 = std::chrono::steady_clock::now();
      const PlanResult r = planner->makePlan(map, s, g);
      const auto t1 = std::chrono::steady_clock::now();
      cpu_ms.push_back(threadCpuMs() - c0);
      ms.push_back(std::chrono::duration<double, std::milli>(t1 - t0).count());
      if (astar) expanded.push_back(static_cast<double>(astar->lastStats().expanded));
      if (!r.ok)
      {
        ++failures;
        std::fprintf(stderr, "pair %zu: %s\n", k, r.error.c_str());
        continue;
      }
      double len = 0.0;
      bool valid = std::hypot(r.path.front().x - s.x, r.path.front().y - s.y) < 1e-9 &&
                   std::hypot(r.path.back().x - g.x, r.path.back().y - g.y) < 1e-9;
      for (size_t i = 0; i < r.path.size(); ++i)
      {
        unsigned mx, my;
        if (!map.worldToMap(r.path[i].x, r.path[i].y, mx, my) || map.cost(mx, my) >= cost::INSCRIBED) valid = false;
        if (i > 0) len += std::hypot(r.path[i].x - r.path[i - 1].x, r.path[i].y - r.path[i - 1].y);
      }
      if (!valid)
      {
        ++invalid;
        std::fprintf(stderr, "pair %zu: the path leaves the passable cells or misses an end\n", k);
      }
      lengths.push_back(len / kResolution);
      costs.push_back(pathCellCost(map, r.path, mark, static_cast<uint32_t>(k + 1)));
      if (per_pair)
        std::printf("pair %3zu: %8.3f ms, cpu %8.3f ms, expanded %7.0f, path %7.1f cells, cost %7.0f\n",
                    only.empty() ? k : only[k], ms.back(), cpu_ms.back(), expanded.empty() ? 0.0 : expanded.back(),
                    lengths.back(), costs.back());
    }

    // Second column: the fastest of `repeat` more plans per pair.
    std::vector<double> best_ms, best_cpu_ms;
    for (size_t k = 0; repeat > 0 && k < pairs.size(); ++k)
    {
      const Pose2D s = pose(pairs[k].sx, pairs[k].sy), g = pose(pairs[k].gx, pairs[k].gy);
      double best = 1e300, best_cpu = 1e300;
      for (int rep = 0; rep < repeat; ++rep)
      {
        const double c0 = threadCpuMs();
        const auto t0 = std::chrono::steady_clock::now();
        planner->makePlan(map, s, g);
        const auto t1 = std::chrono::steady_clock::now();
        best_cpu = std::min(best_cpu, threadCpuMs() - c0);
        best = std::min(best, std::chrono::duration<double, std::milli>(t1 - t0).count());
      }
      best_ms.push_back(best);
      best_cpu_ms.push_back(best_cpu);
    }

    auto mean = [](const std::vector<double>& v) {
      double sum = 0.0;
      for (double x : v) sum += x;
      return v.empty() ? 0.0 : sum / v.size();
    };
    const double mean_len = mean(lengths), mean_cost = mean(costs);
    std::printf(
        "planner %s on %s: %zu pairs, mean path %.1f cells, mean path cost %.1f, failures %d, "
        "invalid paths %d\n",
        planner->name().c_str(), map_path.c_str(), pairs.size(), mean_len, mean_cost, failures, invalid);
    std::printf("  one plan per pair:  p50 %.3f ms, p95 %.3f ms, max %.3f ms; thread CPU p50 %.3f ms, p95 %.3f ms\n",
                percentile(ms, 0.5), percentile(ms, 0.95), percentile(ms, 1.0), percentile(cpu_ms, 0.5),
                percentile(cpu_ms, 0.95));
    if (!best_ms.empty())
      std::printf("  fastest of %d:       p50 %.3f ms, p95 %.3f ms, max %.3f ms; thread CPU p50 %.3f ms, p95 %.3f ms\n",
                  repeat, percentile(best_ms, 0.5), percentile(best_ms, 0.95), percentile(best_ms, 1.0),
                  percentile(best_cpu_ms, 0.5), percentile(best_cpu_ms, 0.95));
    if (!expanded.empty())
      std::printf("  expanded cells: p50 %.0f, p95 %.0f\n", percentile(expanded, 0.5), percentile(expanded, 0.95));
    if (json)
    {
      // Without the fastest-of pass its keys repeat the single plans' figures.
      const std::vector<double>& b = best_ms.empty() ? ms : best_ms;
      const std::vector<double>& bc = best_cpu_ms.empty() ? cpu_ms : best_cpu_ms;
      std::printf(
          "{\"single_p50\": %.4f, \"single_p95\": %.4f, \"single_cpu_p50\": %.4f, \"single_cpu_p95\": %.4f, "
          "\"p50\": %.4f, \"p95\": %.4f, \"cpu_p50\": %.4f, \"cpu_p95\": %.4f, \"repeat\": %d, "
          "\"mean_path_cells\": %.2f, \"mean_path_cost\": %.2f, \"failures\": %d, \"invalid_paths\": %d}\n",
          percentile(ms, 0.5), percentile(ms, 0.95), percentile(cpu_ms, 0.5), percentile(cpu_ms, 0.95),
          percentile(b, 0.5), percentile(b, 0.95), percentile(bc, 0.5), percentile(bc, 0.95), repeat, mean_len,
          mean_cost, failures, invalid);
    }
    return (failures == 0 && invalid == 0) ? 0 : 1;
  }
  catch (const std::exception& e)
  {
    std::cerr << "plan_bench: " << e.what() << "\n";
    return 1;
  }
}
