#include "mbot_coordination/instance.h"

#include <algorithm>
#include <stdexcept>
#include <unordered_map>

namespace mbot_coordination
{
namespace
{
std::string cellName(const Grid& g, int v) { return "(" + std::to_string(g.x(v)) + "," + std::to_string(g.y(v)) + ")"; }
}  // namespace

Instance instanceFromScen(const Grid& grid, const std::vector<ScenRow>& rows, int agents)
{
  if (agents <= 0) throw std::invalid_argument("agents must be >= 1, got " + std::to_string(agents));
  if (static_cast<size_t>(agents) > rows.size())
    throw std::invalid_argument("asked for " + std::to_string(agents) + " agents, the scenario has " +
                                std::to_string(rows.size()) + " rows");
  Instance inst;
  inst.grid = &grid;
  for (int i = 0; i < agents; ++i)
  {
    const ScenRow& r = rows[i];
    if (!grid.inside(r.start_x, r.start_y) || !grid.inside(r.goal_x, r.goal_y))
      throw std::invalid_argument("scenario line " + std::to_string(r.line) + ": start or goal outside the map");
    inst.starts.push_back(grid.id(r.start_x, r.start_y));
    inst.goals.push_back(grid.id(r.goal_x, r.goal_y));
  }
  return inst;
}

void checkInstance(const Instance& inst)
{
  if (!inst.grid) throw std::invalid_argument("instance has no grid");
  const Grid& g = *inst.grid;
  if (inst.starts.size() != inst.goals.size())
    throw std::invalid_argument(std::to_string(inst.starts.size()) + " starts but " +
                                std::to_string(inst.goals.size()) + " goals");
  if (inst.starts.empty()) throw std::invalid_argument("instance has no agents");
  std::unordered_map<int, size_t> start_of, goal_of;
  for (size_t i = 0; i < inst.starts.size(); ++i)
  {
    const int s = inst.starts[i], t = inst.goals[i];
    if (s < 0 || s >= g.size()) throw std::invalid_argument("agent " + std::to_string(i) + ": start outside the grid");
    if (t < 0 || t >= g.size()) throw std::invalid_argument("agent " + std::to_string(i) + ": goal outside the grid");
    if (!g.isFree(s))
      throw std::invalid_argument("agent " + std::to_string(i) + ": start " + cellName(g, s) + " is blocked");
    if (!g.isFree(t))
      throw std::invalid_argument("agent " + std::to_string(i) + ": goal " + cellName(g, t) + " is blocked");
    if (!start_of.emplace(s, i).second)
      throw std::invalid_argument("agents " + std::to_string(start_of[s]) + " and " + std::to_string(i) +
                                  " start at the same cell " + cellName(g, s));
    if (!goal_of.emplace(t, i).second)
      throw std::invalid_argument("agents " + std::to_string(goal_of[t]) + " and " + std::to_string(i) +
                                  " have the same goal " + cellName(g, t));
  }
  for (size_t i = 0; i < inst.starts.size(); ++i)
    if (g.distancesTo(inst.goals[i])[inst.starts[i]] < 0)
      throw std::invalid_argument("agent " + std::to_string(i) + ": goal " + cellName(g, inst.goals[i]) +
                                  " is not reachable from its start " + cellName(g, inst.starts[i]));
}

std::string validate(const Instance& inst, const Paths& paths, bool following)
{
  if (!inst.grid) return "instance has no grid";
  const Grid& g = *inst.grid;
  const size_t n = inst.starts.size();
  if (paths.size() != n) return std::to_string(paths.size()) + " paths for " + std::to_string(n) + " agents";
  size_t horizon = 0;
  for (size_t i = 0; i < n; ++i)
  {
    const auto& p = paths[i];
    const std::string a = "agent " + std::to_string(i);
    if (p.empty()) return a + ": empty path";
    if (p.front() != inst.starts[i]) return a + ": path starts at " + cellName(g, p.front()) + ", not its start";
    if (p.back() != inst.goals[i]) return a + ": path ends at " + cellName(g, p.back()) + ", not its goal";
    for (size_t t = 0; t < p.size(); ++t)
    {
      if (!g.isFree(p[t]))
        return a + ": blocked or outside cell " + (p[t] >= 0 && p[t] < g.size() ? cellName(g, p[t]) : "") +
               " at t=" + std::to_string(t);
      if (t > 0 && p[t] != p[t - 1] && !g.adjacent(p[t - 1], p[t]))
        return a + ": jumps from " + cellName(g, p[t - 1]) + " to " + cellName(g, p[t]) + " at t=" + std::to_string(t);
    }
    horizon = std::max(horizon, p.size());
  }
  const auto at = [&](size_t i, size_t t) { return t < paths[i].size() ? paths[i][t] : paths[i].back(); };
  std::vector<int> who(g.size(), -1);
  for (size_t t = 0; t < horizon; ++t)
  {
    for (size_t i = 0; i < n; ++i)
    {
      const int v = at(i, t);
      if (who[v] >= 0)
        return "vertex conflict: agents " + std::to_string(who[v]) + " and " + std::to_string(i) + " at " +
               cellName(g, v) + " at t=" + std::to_string(t);
      who[v] = static_cast<int>(i);
    }
    if (t > 0)
      for (size_t i = 0; i < n; ++i)
      {
        // i moved prev -> cur; the agent now at prev swapped when it came from cur.
        const int prev = at(i, t - 1), cur = at(i, t);
        if (prev == cur) continue;
        const int j = who[prev];
        if (j >= 0 && at(j, t - 1) == cur)
          return "edge conflict: agents " + std::to_string(i) + " and " + std::to_string(j) + " swap " +
                 cellName(g, prev) + " and " + cellName(g, cur) + " at t=" + std::to_string(t);
      }
    if (following && t > 0)
      for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j)
          if (i != j && at(i, t) == at(j, t - 1) && at(i, t - 1) != at(i, t))
            return "following conflict: agent " + std::to_string(i) + " enters " + cellName(g, at(i, t)) +
                   " at t=" + std::to_string(t) + ", left by agent " + std::to_string(j) + " at t=" + std::to_string(t);
    for (size_t i = 0; i < n; ++i) who[at(i, t)] = -1;
  }
  return "";
}

int agentCost(const std::vector<int>& path)
{
  if (path.empty()) return 0;
  int t = static_cast<int>(path.size()) - 1;
  while (t > 0 && path[t - 1] == path.back()) --t;
  return t;
}

long sumOfCosts(const Paths& paths)
{
  long soc = 0;
  for (const auto& p : paths) soc += agentCost(p);
  return soc;
}

int makespan(const Paths& paths)
{
  int m = 0;
  for (const auto& p : paths) m = std::max(m, agentCost(p));
  return m;
}

long lowerBound(const Instance& inst)
{
  long lb = 0;
  for (size_t i = 0; i < inst.starts.size(); ++i) lb += inst.grid->distancesTo(inst.goals[i])[inst.starts[i]];
  return lb;
}

}  // namespace mbot_coordination
