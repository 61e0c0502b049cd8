// mapf_bench: one MAPF instance (a MovingAI map, the first K rows of a scenario) solved by the
// planner the live coordinator uses; prints success, sum of costs, makespan, runtime and the lower
// bounds, and checks every solution it reports with the validator.
//   mapf_bench --map FILE --scen FILE --agents K --time-limit S [--algorithm pp|lacam|ecbs|eecbs|auto]
//              [--seed N] [--refine S] [--w W] [--json FILE|-]
// --refine: auto's time for improving its first solution (LNS), default 0.5 s
// --w: ecbs's and eecbs's suboptimality bound (default 1.05); they also report its proven lower bound
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "mbot_coordination/movingai.h"
#include "mbot_coordination/planner.h"

using namespace mbot_coordination;

namespace
{
[[noreturn]] void usage(const std::string& problem)
{
  std::cerr
      << "mapf_bench: " << problem << "\n"
      << "usage: mapf_bench --map FILE --scen FILE --agents K --time-limit S [--algorithm pp|lacam|ecbs|eecbs|auto]"
         " [--seed N] [--refine S] [--w W] [--json FILE|-]\n";
  std::exit(2);
}

double number(const std::string& flag, const std::string& text)
{
  char* end = nullptr;
  const double v = std::strtod(text.c_str(), &end);
  if (text.empty() || *end != '\0') usage(flag + " needs a number, got '" + text + "'");
  return v;
}

std::string baseName(const std::string& path)
{
  const size_t slash = path.find_last_of('/');
  return slash == std::string::npos ? path : path.substr(slash + 1);
}

std::string quoted(const std::string& s)
{
  std::string out = "\"";
  for (char c : s) out += (c == '"' || c == '\\') ? std::string("\\") + c : std::string(1, c);
  return out + "\"";
}
}  // namespace

int main(int argc, char** argv)
{
  std::string map_path, scen_path, algorithm = "auto", json_path;
  int agents = 0;
  double time_limit = -1.0;
  unsigned seed = 0;
  double refine = PlannerOptions().refine_s;
  double w = PlannerOptions().w;
  for (int k = 1; k < argc; ++k)
  {
    const std::string a = argv[k];
    if (a == "-h" || a == "--help") usage("help");
    if (k + 1 >= argc) usage("missing value after " + a);
    const std::string v = argv[++k];
    if (a == "--map")
      map_path = v;
    else if (a == "--scen")
      scen_path = v;
    else if (a == "--agents")
      agents = static_cast<int>(number(a, v));
    else if (a == "--time-limit")
      time_limit = number(a, v);
    else if (a == "--algorithm")
      algorithm = v;
    else if (a == "--seed")
      seed = static_cast<unsigned>(number(a, v));
    else if (a == "--refine")
      refine = number(a, v);
    else if (a == "--w")
      w = number(a, v);
    else if (a == "--json")
      json_path = v;
    else
      usage("unknown option " + a);
  }
  if (map_path.empty() || scen_path.empty()) usage("--map and --scen are required");
  if (agents < 1) usage("--agents must be >= 1");
  if (!(time_limit > 0.0)) usage("--time-limit must be > 0 seconds");
  if (!(refine >= 0.0)) usage("--refine must be >= 0 seconds");
  if (!(w >= 1.0)) usage("--w must be >= 1");

  PlanResult result;
  Instance inst;
  long lower_bound = 0;
  double scen_bound = 0.0;
  std::string invalid;
  try
  {
    auto planner = makePlanner(algorithm);
    const Grid grid = readMap(map_path);
    const auto rows = readScen(scen_path, &grid);
    if (rows[0].map != baseName(map_path))
      throw FormatError(scen_path, rows[0].line,
                        "scenario is for map '" + rows[0].map + "', not " + baseName(map_path));
    inst = instanceFromScen(grid, rows, agents);
    for (int i = 0; i < agents; ++i) scen_bound += rows[i].optimal_length;
    lower_bound = lowerBound(inst);
    PlannerOptions options;
    options.time_limit_s = time_limit;
    options.seed = seed;
    options.refine_s = refine;
    options.w = w;
    result = planner->solve(inst, options);
    if (result.solved) invalid = validate(inst, result.paths);
  }
  catch (const std::exception& e)
  {
    std::cerr << "mapf_bench: " << e.what() << "\n";
    return 2;
  }
  const bool ok = result.solved && invalid.empty();
  const long soc = ok ? sumOfCosts(result.paths) : 0;
  const int span = ok ? makespan(result.paths) : 0;
  std::ostringstream json;
  json.precision(6);
  json << "{\"map\": " << quoted(baseName(map_path)) << ", \"scen\": " << quoted(baseName(scen_path))
       << ", \"agents\": " << agents << ", \"algorithm\": " << quoted(algorithm)
       << ", \"solved_by\": " << quoted(result.algorithm) << ", \"success\": " << (ok ? "true" : "false")
       << ", \"runtime_s\": " << result.runtime_s << ", \"time_limit_s\": " << time_limit;
  if (ok)
    json << ", \"sum_of_costs\": " << soc << ", \"makespan\": " << span
         << ", \"first_solution_s\": " << result.first_solution_s
         << ", \"first_sum_of_costs\": " << result.first_sum_of_costs
         << ", \"lns_iterations\": " << result.lns_iterations;
  if (ok && result.lower_bound > 0) json << ", \"w\": " << w << ", \"proven_lower_bound\": " << result.lower_bound;
  json << ", \"lower_bound\": " << lower_bound << ", \"scen_optimal_sum\": " << scen_bound
       << ", \"attempts\": " << result.attempts
       << ", \"message\": " << quoted(invalid.empty() ? result.message : invalid) << "}";

  std::printf("%s, %s, %d agents, %s\n", baseName(map_path).c_str(), baseName(scen_path).c_str(), agents,
              algorithm.c_str());
  std::printf("success:       %s%s\n", ok ? "yes" : "no",
              ok ? (" (" + result.algorithm + ")").c_str()
                 : (" (" + (invalid.empty() ? result.message : "INVALID SOLUTION: " + invalid) + ")").c_str());
  if (ok)
  {
    std::printf("sum of costs:  %ld (%.2f %% over the lower bound)\n", soc, 100.0 * (soc - lower_bound) / lower_bound);
    if (result.lower_bound > 0)
      std::printf("proven bound:  %ld (the optimum is >= this: sum of costs / bound = %.4f <= w = %g)\n",
                  result.lower_bound, static_cast<double>(soc) / result.lower_bound, w);
    std::printf("makespan:      %d\n", span);
    std::printf("first solution: %.4f s, sum of costs %ld (then %ld LNS iterations)\n", result.first_solution_s,
                result.first_sum_of_costs, result.lns_iterations);
  }
  std::printf("runtime:       %.4f s (limit %g s)\n", result.runtime_s, time_limit);
  std::printf(
      "lower bound:   %ld (each agent's 4-connected shortest path); scen rows' optimal lengths sum %.2f "
      "(8-connected)\n",
      lower_bound, scen_bound);
  if (json_path == "-")
    std::printf("%s\n", json.str().c_str());
  else if (!json_path.empty())
  {
    std::ofstream out(json_path);
    if (!(out << json.str() << "\n"))
    {
      std::cerr << "mapf_bench: cannot write " << json_path << "\n";
      return 2;
    }
  }
  if (!invalid.empty()) return 3;  // a planner bug: never report it as a result
  return ok ? 0 : 1;
}
