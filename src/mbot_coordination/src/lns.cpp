#include "mbot_coordination/lns.h"

#include <algorithm>
#include <numeric>
#include <random>
#include <unordered_set>

namespace mbot_coordination
{
LnsStats refineLns(const Instance& inst, Paths& paths, Clock::time_point deadline, unsigned seed, int neighbourhood,
                   long max_iterations, bool following)
{
  LnsStats stats;
  const Grid& g = *inst.grid;
  const int n = static_cast<int>(inst.starts.size());
  std::vector<std::vector<int>> h(n);
  for (int i = 0; i < n; ++i) h[i] = g.distancesTo(inst.goals[i]);
  const long bound = lowerBound(inst);
  for (auto& p : paths) p.resize(std::max(1, agentCost(p) + 1));  // drop waits at the goal at the end
  long soc = sumOfCosts(paths);
  std::mt19937 rng(seed);
  const int size = std::min(neighbourhood, n);
  std::vector<int> all(n);
  std::iota(all.begin(), all.end(), 0);
  while (soc > bound && Clock::now() < deadline && (max_iterations < 0 || stats.iterations < max_iterations))
  {
    ++stats.iterations;
    // Seed: an agent that is late, picked with probability by its delay; then the agents on its
    // own shortest path's cells (those that make it late), then random ones.
    std::vector<double> delay(n);
    for (int i = 0; i < n; ++i) delay[i] = agentCost(paths[i]) - h[i][inst.starts[i]];
    std::discrete_distribution<int> pick(delay.begin(), delay.end());
    const int seed_agent = pick(rng);
    std::vector<int> group{seed_agent};
    std::unordered_set<int> in_group{seed_agent};
    std::unordered_set<int> cells;
    for (int v = inst.starts[seed_agent]; h[seed_agent][v] > 0;)
    {
      cells.insert(v);
      for (int u : g.neighbours(v))
        if (h[seed_agent][u] == h[seed_agent][v] - 1)
        {
          v = u;
          break;
        }
    }
    cells.insert(inst.goals[seed_agent]);
    std::vector<int> blockers;
    for (int i = 0; i < n; ++i)
      if (i != seed_agent)
        for (int v : paths[i])
          if (cells.count(v))
          {
            blockers.push_back(i);
            break;
          }
    std::shuffle(blockers.begin(), blockers.end(), rng);
    for (int i : blockers)
      if (static_cast<int>(group.size()) < size && in_group.insert(i).second) group.push_back(i);
    std::shuffle(all.begin(), all.end(), rng);
    for (int i : all)
      if (static_cast<int>(group.size()) < size && in_group.insert(i).second) group.push_back(i);

    ReservationTable table(g.size(), following);
    long old_cost = 0;
    for (int i = 0; i < n; ++i)
      if (in_group.count(i))
        old_cost += agentCost(paths[i]);
      else
        table.reservePath(paths[i]);
    std::shuffle(group.begin(), group.end(), rng);
    std::vector<std::vector<int>> replanned;
    long new_cost = 0;
    bool timed_out = false;
    for (size_t k = 0; k < group.size(); ++k)
    {
      const int i = group[k];
      ReservationTable with_starts = table;
      if (following)  // the group's agents after i stand on their starts at t = 0 and must leave them
        for (size_t j = k + 1; j < group.size(); ++j)
          for (int t = 0; t <= 1; ++t) with_starts.reserveCell(inst.starts[group[j]], t);
      auto p = sippPath(g, with_starts, inst.starts[i], inst.goals[i], h[i], deadline, &timed_out);
      if (p.empty()) break;
      new_cost += agentCost(p);
      if (new_cost >= old_cost) break;  // cannot win any more
      table.reservePath(p);
      replanned.push_back(std::move(p));
    }
    if (replanned.size() == group.size() && new_cost < old_cost)
    {
      for (size_t k = 0; k < group.size(); ++k) paths[group[k]] = std::move(replanned[k]);
      soc -= old_cost - new_cost;
      ++stats.improvements;
    }
    if (timed_out) break;
  }
  return stats;
}

}  // namespace mbot_coordination
