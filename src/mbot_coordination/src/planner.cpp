#include "mbot_coordination/planner.h"

#include <algorithm>
#include <stdexcept>

#include "mbot_coordination/lns.h"
#include "mbot_coordination/sipp.h"

namespace mbot_coordination
{
PlanResult AutoPlanner::solve(const Instance& inst, const PlannerOptions& options)
{
  checkInstance(inst);
  const auto t0 = Clock::now();
  PlannerOptions pp_options = options;
  // With following conflicts lacam cannot help: pp gets the whole time.
  pp_options.time_limit_s =
      options.following ? options.time_limit_s : options.time_limit_s * std::clamp(options.pp_share, 0.0, 1.0);
  PlanResult result = PrioritizedPlanner().solve(inst, pp_options);
  if (!result.solved && !options.following)
  {
    PlannerOptions rest = options;
    rest.time_limit_s = options.time_limit_s - std::chrono::duration<double>(Clock::now() - t0).count();
    const std::string pp_message = result.message;
    result = LacamPlanner().solve(inst, rest);
    result.message = "pp: " + pp_message + (result.solved ? "" : "; lacam: " + result.message);
  }
  if (result.solved)
  {
    result.first_solution_s = std::chrono::duration<double>(Clock::now() - t0).count();
    result.first_sum_of_costs = sumOfCosts(result.paths);
    const auto end = t0 + std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(std::max(
                              0.0, std::min(options.time_limit_s, result.first_solution_s + options.refine_s))));
    if (options.refine_s > 0.0)
    {
      result.lns_iterations = refineLns(inst, result.paths, end, options.seed, 8, -1, options.following).iterations;
      result.algorithm += "+lns";
    }
  }
  result.runtime_s = std::chrono::duration<double>(Clock::now() - t0).count();
  return result;
}

std::vector<std::string> plannerNames() { return {"pp", "lacam", "ecbs", "eecbs", "auto"}; }

std::unique_ptr<Planner> makePlanner(const std::string& name)
{
  if (name == "pp") return std::make_unique<PrioritizedPlanner>();
  if (name == "lacam") return std::make_unique<LacamPlanner>();
  if (name == "ecbs") return std::make_unique<EcbsPlanner>();
  if (name == "eecbs") return std::make_unique<EcbsPlanner>(true);
  if (name == "auto") return std::make_unique<AutoPlanner>();
  std::string known;
  for (const auto& n : plannerNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown MAPF algorithm '" + name + "' (known: " + known + ")");
}

}  // namespace mbot_coordination
