#include <algorithm>
#include <numeric>
#include <random>

#include "mbot_coordination/planner.h"
#include "mbot_coordination/sipp.h"

namespace mbot_coordination
{
PlanResult PrioritizedPlanner::solve(const Instance& inst, const PlannerOptions& options)
{
  checkInstance(inst);
  const auto t0 = Clock::now();
  const auto deadline = t0 + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(std::max(0.0, options.time_limit_s)));
  const Grid& g = *inst.grid;
  const size_t n = inst.starts.size();
  std::vector<std::vector<int>> h(n);
  for (size_t i = 0; i < n; ++i) h[i] = g.distancesTo(inst.goals[i]);
  // First order: the shortest journeys first (longest first was 28 % over the bound on empty-32-32
  // with 100 agents, this 1 %; ordering by how many shortest paths cross a goal was 10-23 %).
  std::vector<int> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(),
                   [&](int a, int b) { return h[a][inst.starts[a]] < h[b][inst.starts[b]]; });
  std::mt19937 rng(options.seed);
  PlanResult result;
  result.algorithm = name();
  const auto elapsed = [&] { return std::chrono::duration<double>(Clock::now() - t0).count(); };
  while (true)
  {
    ++result.attempts;
    ReservationTable table(g.size(), options.following);
    Paths paths(n);
    int failed = -1;
    bool timed_out = false;
    for (size_t k = 0; k < n; ++k)
    {
      const int i = order[k];
      if (options.following)
      {
        // The agents after i stand on their starts at t = 0: i may not enter one at t = 1.
        ReservationTable with_starts = table;
        for (size_t j = k + 1; j < n; ++j)
          for (int t = 0; t <= 1; ++t) with_starts.reserveCell(inst.starts[order[j]], t);
        paths[i] = sippPath(g, with_starts, inst.starts[i], inst.goals[i], h[i], deadline, &timed_out);
      }
      else
        paths[i] = sippPath(g, table, inst.starts[i], inst.goals[i], h[i], deadline, &timed_out);
      if (paths[i].empty())
      {
        failed = i;
        break;
      }
      table.reservePath(paths[i]);
    }
    if (failed < 0)
    {
      result.solved = true;
      result.paths = std::move(paths);
      break;
    }
    if (timed_out || Clock::now() > deadline)
    {
      result.message = "time limit after " + std::to_string(result.attempts) + " orders";
      break;
    }
    // Re-prioritise: the agent that failed goes first; every 8th restart the rest are shuffled.
    auto it = std::find(order.begin(), order.end(), failed);
    order.erase(it);
    if (result.attempts % 64 == 0) std::shuffle(order.begin(), order.end(), rng);
    order.insert(order.begin(), failed);
  }
  result.runtime_s = elapsed();
  if (result.solved)
  {
    result.first_solution_s = result.runtime_s;
    result.first_sum_of_costs = sumOfCosts(result.paths);
  }
  return result;
}

}  // namespace mbot_coordination
