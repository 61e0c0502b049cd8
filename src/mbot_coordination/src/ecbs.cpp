// ECBS (Barer, Sharon, Stern, Felner, SoCS 2014): conflict-based search with focal search on both
// levels. The returned sum of costs is <= w * LB <= w * optimum, where LB (the minimum over the
// high-level OPEN of the sum of the agents' low-level f-min values) is reported as the proof.
#include <algorithm>
#include <cmath>
#include <limits>
#include <memory>
#include <set>
#include <stdexcept>
#include <tuple>
#include <unordered_map>
#include <unordered_set>

#include "mbot_coordination/planner.h"
#include "mbot_coordination/sipp.h"

namespace mbot_coordination
{
namespace
{
double since(Clock::time_point t0) { return std::chrono::duration<double>(Clock::now() - t0).count(); }

// One agent's constraints: not at cell v at time t; not moving from u to v arriving at time t.
struct Constraint
{
  int agent;
  int from;  // -1 for a vertex constraint
  int to;
  int t;
};

struct AgentConstraints
{
  std::unordered_set<int64_t> vertex, edge;
  int last_time = 0;      // the latest constraint's time: after it the agent moves freely
  int min_goal_time = 0;  // the path may end only at or after this (after every constraint on the goal)
};

// The other agents' paths, for counting the conflicts a partial path would have (the focal order).
struct ConflictTable
{
  std::unordered_map<int64_t, int> at;       // (t, v) -> agents there (before they park)
  std::unordered_map<int64_t, int> moves;    // (t, from, to) -> agents making that move
  std::unordered_map<int, int> parked_from;  // goal cell -> time its agent parks there for ever
  int64_t cells = 0;

  ConflictTable(const Paths& paths, int skip, int cells_) : cells(cells_)
  {
    for (size_t j = 0; j < paths.size(); ++j)
    {
      if (static_cast<int>(j) == skip || paths[j].empty()) continue;  // the root: not planned yet
      const auto& p = paths[j];
      for (size_t t = 0; t + 1 < p.size(); ++t)
      {
        ++at[static_cast<int64_t>(t) * cells + p[t]];
        if (p[t] != p[t + 1]) ++moves[(static_cast<int64_t>(t + 1) * cells + p[t]) * cells + p[t + 1]];
      }
      parked_from[p.back()] = static_cast<int>(p.size()) - 1;
    }
  }
  int count(int from, int to, int t) const
  {
    int n = 0;
    auto a = at.find(static_cast<int64_t>(t) * cells + to);
    if (a != at.end()) n += a->second;
    auto p = parked_from.find(to);
    if (p != parked_from.end() && t >= p->second) ++n;
    if (from != to)
    {
      auto m = moves.find((static_cast<int64_t>(t) * cells + to) * cells + from);  // someone swapping with us
      if (m != moves.end()) n += m->second;
    }
    return n;
  }
};

struct LowLevelResult
{
  std::vector<int> path;
  int f_min = 0;  // a lower bound on this agent's cost under its constraints
  bool timed_out = false;
};

// Focal A* in space-time for one agent: OPEN by f = t + h, FOCAL = open nodes with f <= w * f_min,
// expanded by fewest conflicts with the other agents' paths. Its path costs <= w * f_min.
LowLevelResult focalAStar(const Grid& grid, int start, int goal, const std::vector<int>& h, const AgentConstraints& c,
                          const ConflictTable& table, double w, Clock::time_point deadline)
{
  struct Node
  {
    int v, t, f, conflicts, parent;
    bool open;
  };
  std::vector<Node> nodes;
  std::unordered_map<int64_t, int> index;  // (t, v) -> node
  const int64_t cells = grid.size();
  // after the last constraint nothing changes, so a path is found by then plus one crossing of the grid
  const int horizon = std::max(c.last_time, c.min_goal_time) + grid.size() + 1;
  auto heur = [&](int v, int t) { return std::max(h[v], c.min_goal_time - t); };
  using OpenKey = std::pair<int, int>;              // f, node
  using FocalKey = std::tuple<int, int, int, int>;  // conflicts, f, -t (deeper first), node
  std::set<OpenKey> open;
  std::set<FocalKey> focal;
  auto bound = [&](int f_min) { return static_cast<int>(std::floor(w * f_min + 1e-9)); };
  auto push = [&](int v, int t, int conflicts, int parent, int f_bound) {
    const int f = t + heur(v, t);
    const int64_t key = static_cast<int64_t>(t) * cells + v;
    auto it = index.find(key);
    if (it != index.end())
    {
      Node& n = nodes[it->second];
      if (!n.open || n.conflicts <= conflicts) return;  // same g (= t) either way: keep the fewer conflicts
      if (n.f <= f_bound) focal.erase(FocalKey{n.conflicts, n.f, -n.t, it->second});
      n.conflicts = conflicts;
      n.parent = parent;
      if (n.f <= f_bound) focal.insert(FocalKey{n.conflicts, n.f, -n.t, it->second});
      return;
    }
    const int id = static_cast<int>(nodes.size());
    nodes.push_back(Node{v, t, f, conflicts, parent, true});
    index.emplace(key, id);
    open.insert(OpenKey{f, id});
    if (f <= f_bound) focal.insert(FocalKey{conflicts, f, -t, id});
  };
  LowLevelResult result;
  push(start, 0, 0, -1, std::numeric_limits<int>::max());
  int f_min = open.begin()->first;
  long expansions = 0;
  while (!open.empty())
  {
    if ((++expansions & 1023) == 0 && Clock::now() > deadline)
    {
      result.timed_out = true;
      return result;
    }
    // OPEN's minimum rose: the open nodes now inside the widened bound join FOCAL
    const int new_min = open.begin()->first;
    if (new_min > f_min)
    {
      for (auto it = open.upper_bound(OpenKey{bound(f_min), std::numeric_limits<int>::max()});
           it != open.end() && it->first <= bound(new_min); ++it)
        focal.insert(FocalKey{nodes[it->second].conflicts, it->first, -nodes[it->second].t, it->second});
      f_min = new_min;
    }
    const int id = std::get<3>(*focal.begin());
    focal.erase(focal.begin());
    Node cur = nodes[id];
    open.erase(OpenKey{cur.f, id});
    nodes[id].open = false;
    if (cur.v == goal && cur.t >= c.min_goal_time)
    {
      result.f_min = f_min;
      for (int n = id; n >= 0; n = nodes[n].parent) result.path.push_back(nodes[n].v);
      std::reverse(result.path.begin(), result.path.end());
      return result;
    }
    if (cur.t >= horizon) continue;
    const int t = cur.t + 1;
    auto expand = [&](int to) {
      if (c.vertex.count(static_cast<int64_t>(t) * cells + to)) return;
      if (to != cur.v && c.edge.count((static_cast<int64_t>(t) * cells + cur.v) * cells + to)) return;
      push(to, t, cur.conflicts + table.count(cur.v, to, t), id, bound(f_min));
    };
    for (int to : grid.neighbours(cur.v)) expand(to);
    expand(cur.v);
  }
  result.f_min = f_min;
  return result;  // no path under these constraints: this branch of the tree is dead
}

struct Conflict
{
  int a, b;
  int v, u;  // vertex conflict: both at v; edge conflict: a moves v -> u while b moves u -> v
  int t;
  bool edge;
};

int64_t positionKey(int t, int v, int64_t cells) { return static_cast<int64_t>(t) * cells + v; }

// All conflicts' count and the earliest one (the one to split on).
int findConflicts(const Paths& paths, int cells, Conflict* first)
{
  int makespan_ = 0;
  for (const auto& p : paths) makespan_ = std::max(makespan_, static_cast<int>(p.size()) - 1);
  auto at = [&](size_t i, int t) { return paths[i][std::min<size_t>(t, paths[i].size() - 1)]; };
  int count = 0;
  first->t = std::numeric_limits<int>::max();
  std::unordered_map<int64_t, int> occupied;
  for (int t = 0; t <= makespan_; ++t)
  {
    occupied.clear();
    for (size_t i = 0; i < paths.size(); ++i)
    {
      auto ins = occupied.emplace(at(i, t), static_cast<int>(i));
      if (!ins.second)
      {
        ++count;
        if (t < first->t) *first = Conflict{ins.first->second, static_cast<int>(i), at(i, t), -1, t, false};
      }
    }
    if (t == 0) continue;
    for (size_t i = 0; i < paths.size(); ++i)
    {
      const int from = at(i, t - 1), to = at(i, t);
      if (from == to) continue;
      auto other = occupied.find(from);  // who is now where i was, coming from where i is now
      if (other == occupied.end()) continue;
      const int j = other->second;
      if (j > static_cast<int>(i) && at(j, t - 1) == to)
      {
        ++count;
        if (t < first->t) *first = Conflict{static_cast<int>(i), j, from, to, t, true};
      }
    }
  }
  (void)cells;
  return count;
}

struct CtNode
{
  std::shared_ptr<const CtNode> parent;
  Constraint constraint{-1, -1, -1, -1};  // the one this node adds to its parent's
  Paths paths;
  std::vector<int> f_min;  // per agent: a lower bound on its cost under this node's constraints
  long cost = 0, lb = 0;
  int conflicts = 0;
  Conflict conflict{};
  long id = 0;
};

AgentConstraints constraintsOf(const CtNode* node, int agent, int goal, int64_t cells)
{
  AgentConstraints c;
  for (; node != nullptr; node = node->parent.get())
  {
    const Constraint& k = node->constraint;
    if (k.agent != agent) continue;
    c.last_time = std::max(c.last_time, k.t);
    if (k.from < 0)
    {
      c.vertex.insert(positionKey(k.t, k.to, cells));
      if (k.to == goal) c.min_goal_time = std::max(c.min_goal_time, k.t + 1);
    }
    else
      c.edge.insert((static_cast<int64_t>(k.t) * cells + k.from) * cells + k.to);
  }
  return c;
}
}  // namespace

PlanResult EcbsPlanner::solve(const Instance& inst, const PlannerOptions& given)
{
  if (given.following) throw std::invalid_argument(name() + " does not support following conflicts (use pp or auto)");
  checkInstance(inst);
  PlannerOptions options = given;
  if (eecbs_) options.ecbs_bypass = options.ecbs_explicit_estimation = true;
  if (!(options.w >= 1.0) || !std::isfinite(options.w))
    throw std::invalid_argument("ecbs: suboptimality bound w must be >= 1, got " + std::to_string(options.w));
  const auto t0 = Clock::now();
  const auto deadline = t0 + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(std::max(0.0, options.time_limit_s)));
  const Grid& grid = *inst.grid;
  const int n = static_cast<int>(inst.starts.size());
  const int64_t cells = grid.size();
  const double w = options.w;
  std::vector<std::vector<int>> h(n);
  for (int i = 0; i < n; ++i) h[i] = grid.distancesTo(inst.goals[i]);

  PlanResult result;
  result.algorithm = name();
  auto timeUp = [&](const std::string& where) {
    result.message = "time limit reached (" + where + ")";
    result.runtime_s = since(t0);
    return result;
  };

  auto root = std::make_shared<CtNode>();
  root->paths.resize(n);
  root->f_min.resize(n);
  for (int i = 0; i < n; ++i)
  {
    const ConflictTable table(root->paths, i, grid.size());
    const LowLevelResult r =
        focalAStar(grid, inst.starts[i], inst.goals[i], h[i], AgentConstraints(), table, w, deadline);
    if (r.timed_out) return timeUp("root");
    if (r.path.empty()) throw std::logic_error("ecbs: no path for agent " + std::to_string(i) + " without constraints");
    root->paths[i] = r.path;
    root->f_min[i] = r.f_min;
  }
  auto finish = [&](CtNode& node) {
    node.cost = sumOfCosts(node.paths);
    node.lb = 0;
    for (int f : node.f_min) node.lb += f;
    node.conflicts = findConflicts(node.paths, grid.size(), &node.conflict);
  };
  finish(*root);

  // CLEANUP: every open node by lb (its minimum is LB). FOCAL: the open nodes with cost <= w * threshold,
  // by fewest conflicts; WAITING: the other open nodes, by cost. ECBS: threshold = LB. EECBS's explicit
  // estimation (Li et al. 2021, here with the estimate = the node's cost): threshold = the least cost
  // of an open node, and the node expanded is FOCAL's best if its cost <= w * LB, else the cheapest
  // open node if within w * LB, else CLEANUP's best (which raises LB).
  using Ptr = std::shared_ptr<CtNode>;
  std::unordered_map<long, Ptr> nodes;
  std::set<std::pair<long, long>> cleanup, by_cost, waiting;
  std::set<std::tuple<int, long, long>> focal;
  long next_id = 0;
  double threshold = static_cast<double>(root->lb);
  auto add = [&](const Ptr& node) {
    node->id = next_id++;
    nodes[node->id] = node;
    cleanup.insert({node->lb, node->id});
    by_cost.insert({node->cost, node->id});
    if (node->cost <= w * threshold + 1e-9)
      focal.insert({node->conflicts, node->cost, node->id});
    else
      waiting.insert({node->cost, node->id});
  };
  add(root);
  while (!cleanup.empty())
  {
    if (Clock::now() > deadline) return timeUp("high level");
    const double lb_min = static_cast<double>(cleanup.begin()->first);
    const double new_threshold = options.ecbs_explicit_estimation ? by_cost.begin()->first : lb_min;
    if (new_threshold > threshold || focal.empty())
    {
      threshold = new_threshold;
      while (!waiting.empty() && waiting.begin()->first <= w * threshold + 1e-9)
      {
        const long id = waiting.begin()->second;
        waiting.erase(waiting.begin());
        focal.insert({nodes[id]->conflicts, nodes[id]->cost, id});
      }
    }
    long id = std::get<2>(*focal.begin());
    if (nodes[id]->cost > w * lb_min + 1e-9)  // only with explicit estimation: FOCAL reaches past w * LB
    {
      id = by_cost.begin()->first <= w * lb_min + 1e-9 ? by_cost.begin()->second : cleanup.begin()->second;
      ++result.cleanup_expansions;
    }
    Ptr node = nodes[id];
    nodes.erase(id);
    cleanup.erase({node->lb, id});
    by_cost.erase({node->cost, id});
    focal.erase({node->conflicts, node->cost, id});
    waiting.erase({node->cost, id});
    ++result.attempts;
    if (node->conflicts == 0)
    {
      result.solved = true;
      result.paths = node->paths;
      result.lower_bound = static_cast<long>(std::ceil(lb_min - 1e-9));
      result.first_solution_s = since(t0);
      result.first_sum_of_costs = node->cost;
      result.runtime_s = since(t0);
      return result;
    }
    const Conflict k = node->conflict;
    std::vector<Ptr> children;
    bool bypassed = false;
    for (int side = 0; side < 2 && !bypassed; ++side)
    {
      auto child = std::make_shared<CtNode>();
      child->parent = node;
      const int agent = side == 0 ? k.a : k.b;
      if (!k.edge)
        child->constraint = Constraint{agent, -1, k.v, k.t};
      else if (side == 0)
        child->constraint = Constraint{agent, k.v, k.u, k.t};
      else
        child->constraint = Constraint{agent, k.u, k.v, k.t};
      const AgentConstraints c = constraintsOf(child.get(), agent, inst.goals[agent], cells);
      const ConflictTable table(node->paths, agent, grid.size());
      const LowLevelResult r = focalAStar(grid, inst.starts[agent], inst.goals[agent], h[agent], c, table, w, deadline);
      if (r.timed_out) return timeUp("low level");
      if (r.path.empty()) continue;  // no path under these constraints
      child->paths = node->paths;
      child->paths[agent] = r.path;
      child->f_min = node->f_min;
      child->f_min[agent] = std::max(node->f_min[agent], r.f_min);  // both bound this agent's cost here
      finish(*child);
      // Bypass (EECBS, Li et al. 2021): the new path also satisfies the parent's constraints; when it
      // has fewer conflicts and keeps the parent within its bound, the parent takes it instead of splitting.
      if (options.ecbs_bypass && child->conflicts < node->conflicts && child->cost <= w * node->lb + 1e-9)
      {
        node->paths = std::move(child->paths);
        node->cost = child->cost;
        node->conflicts = child->conflicts;
        node->conflict = child->conflict;
        bypassed = true;
        ++result.bypasses;
      }
      else
        children.push_back(child);
    }
    if (bypassed)
      add(node);
    else
      for (const auto& child : children) add(child);
  }
  result.message = "no solution exists (the constraint tree is exhausted)";
  result.runtime_s = since(t0);
  return result;
}

}  // namespace mbot_coordination
