// LaCAM (Okumura, "LaCAM: Search-Based Algorithm for Quick Multi-Agent Pathfinding", AAAI 2023):
// a depth-first search over configurations; a configuration's successors come from PIBT (Okumura
// et al. 2022) under constraints "agent i moves to cell v" that a per-configuration low-level
// search adds one agent at a time. Every configuration is eventually tried with every successor,
// so the search is complete: it finds a solution when one exists and otherwise ends saying so.
#include <algorithm>
#include <cmath>
#include <deque>
#include <memory>
#include <numeric>
#include <random>
#include <stdexcept>
#include <unordered_map>

#include "mbot_coordination/planner.h"
#include "mbot_coordination/sipp.h"

namespace mbot_coordination
{
namespace
{
using Config = std::vector<int>;

struct ConfigHash
{
  size_t operator()(const Config& c) const
  {
    size_t h = c.size();
    for (int v : c) h ^= static_cast<size_t>(v) + 0x9e3779b97f4a7c15ULL + (h << 6) + (h >> 2);
    return h;
  }
};

// A low-level node: the first `depth` agents of the high-level node's order are constrained.
struct LowNode
{
  std::vector<int> who;
  std::vector<int> where;
};

struct HighNode
{
  Config config;
  HighNode* parent;
  std::vector<double> priority;
  std::vector<int> order;  // agents by priority, highest first
  std::deque<std::shared_ptr<LowNode>> tree;
};

class Lacam
{
public:
  Lacam(const Instance& inst, unsigned seed) : inst_(inst), g_(*inst.grid), n_(inst.starts.size()), rng_(seed)
  {
    for (size_t i = 0; i < n_; ++i) dist_.push_back(g_.distancesTo(inst.goals[i]));
    occupied_now_.assign(g_.size(), -1);
    occupied_next_.assign(g_.size(), -1);
  }

  PlanResult run(Clock::time_point deadline)
  {
    PlanResult result;
    result.algorithm = "lacam";
    std::vector<double> prio(n_);
    for (size_t i = 0; i < n_; ++i) prio[i] = static_cast<double>(dist_[i][inst_.starts[i]]) / n_;
    std::vector<HighNode*> open{newNode(inst_.starts, nullptr, prio)};
    long expansions = 0;
    Config next(n_);
    while (!open.empty())
    {
      if ((++expansions & 255) == 0 && Clock::now() > deadline)
      {
        result.message = "time limit";
        break;
      }
      HighNode* h = open.back();
      if (h->config == inst_.goals)
      {
        std::vector<const Config*> configs;
        for (const HighNode* k = h; k; k = k->parent) configs.push_back(&k->config);
        std::reverse(configs.begin(), configs.end());
        result.paths.assign(n_, {});
        for (size_t i = 0; i < n_; ++i)
        {
          for (const Config* c : configs) result.paths[i].push_back((*c)[i]);
          // drop the waits at the goal at the end: the agent stays there anyway
          auto& p = result.paths[i];
          while (p.size() > 1 && p[p.size() - 2] == p.back()) p.pop_back();
        }
        result.solved = true;
        break;
      }
      if (h->tree.empty())
      {
        open.pop_back();
        continue;
      }
      const std::shared_ptr<LowNode> low = h->tree.front();
      h->tree.pop_front();
      const size_t depth = low->who.size();
      if (depth < n_)
      {
        const int i = h->order[depth];
        std::vector<int> cells = g_.neighbours(h->config[i]);
        cells.push_back(h->config[i]);
        std::shuffle(cells.begin(), cells.end(), rng_);
        for (int v : cells)
        {
          auto child = std::make_shared<LowNode>(*low);
          child->who.push_back(i);
          child->where.push_back(v);
          h->tree.push_back(child);
        }
      }
      if (!successor(*h, *low, next)) continue;
      auto found = explored_.find(next);
      if (found != explored_.end())
      {
        open.push_back(found->second);  // known: search on from it again
        continue;
      }
      std::vector<double> p(n_);
      for (size_t i = 0; i < n_; ++i)
        p[i] = next[i] != inst_.goals[i] ? h->priority[i] + 1.0 : h->priority[i] - std::floor(h->priority[i]);
      open.push_back(newNode(next, h, p));
    }
    if (!result.solved && result.message.empty()) result.message = "no solution exists (every configuration tried)";
    result.attempts = static_cast<long>(nodes_.size());
    return result;
  }

private:
  HighNode* newNode(const Config& config, HighNode* parent, const std::vector<double>& priority)
  {
    auto node = std::make_unique<HighNode>();
    node->config = config;
    node->parent = parent;
    node->priority = priority;
    node->order.resize(n_);
    std::iota(node->order.begin(), node->order.end(), 0);
    std::stable_sort(node->order.begin(), node->order.end(), [&](int a, int b) { return priority[a] > priority[b]; });
    node->tree.push_back(std::make_shared<LowNode>());
    HighNode* raw = node.get();
    nodes_.push_back(std::move(node));
    explored_.emplace(config, raw);
    return raw;
  }

  // PIBT from h's configuration with low's constraints; false when they cannot all hold.
  bool successor(const HighNode& h, const LowNode& low, Config& next)
  {
    from_ = &h.config;
    next_ = &next;
    std::fill(next.begin(), next.end(), -1);
    for (size_t i = 0; i < n_; ++i) occupied_now_[h.config[i]] = static_cast<int>(i);
    bool ok = true;
    for (size_t k = 0; k < low.who.size() && ok; ++k)
    {
      const int i = low.who[k], v = low.where[k];
      const int j = occupied_now_[v];
      if (occupied_next_[v] >= 0 || (j >= 0 && j != i && next[j] == h.config[i]))
        ok = false;
      else
      {
        next[i] = v;
        occupied_next_[v] = i;
        touched_.push_back(v);
      }
    }
    for (size_t k = 0; k < n_ && ok; ++k)
    {
      const int i = h.order[k];
      if (next[i] < 0 && !pibt(i)) ok = false;
    }
    for (size_t i = 0; i < n_; ++i) occupied_now_[h.config[i]] = -1;
    for (int v : touched_) occupied_next_[v] = -1;
    touched_.clear();
    return ok;
  }

  bool pibt(int i)
  {
    const Config& from = *from_;
    Config& next = *next_;
    std::vector<int> cells = g_.neighbours(from[i]);
    cells.push_back(from[i]);
    std::shuffle(cells.begin(), cells.end(), rng_);  // random tie-breaks
    const auto& d = dist_[i];
    std::stable_sort(cells.begin(), cells.end(), [&](int a, int b) {
      if (d[a] != d[b]) return d[a] < d[b];
      return (occupied_now_[a] >= 0) < (occupied_now_[b] >= 0);  // free cells first
    });
    for (int u : cells)
    {
      if (occupied_next_[u] >= 0) continue;
      const int j = occupied_now_[u];
      if (j >= 0 && j != i && next[j] == from[i]) continue;  // would swap with j
      occupied_next_[u] = i;
      touched_.push_back(u);
      next[i] = u;
      if (j >= 0 && j != i && next[j] < 0 && !pibt(j)) continue;  // j could not make room
      return true;
    }
    occupied_next_[from[i]] = i;
    touched_.push_back(from[i]);
    next[i] = from[i];
    return false;
  }

  const Instance& inst_;
  const Grid& g_;
  size_t n_;
  std::mt19937 rng_;
  std::vector<std::vector<int>> dist_;
  std::vector<int> occupied_now_, occupied_next_, touched_;
  const Config* from_ = nullptr;
  Config* next_ = nullptr;
  std::vector<std::unique_ptr<HighNode>> nodes_;
  std::unordered_map<Config, HighNode*, ConfigHash> explored_;
};
}  // namespace

PlanResult LacamPlanner::solve(const Instance& inst, const PlannerOptions& options)
{
  if (options.following) throw std::invalid_argument("lacam does not support following conflicts (use pp or auto)");
  checkInstance(inst);
  const auto t0 = Clock::now();
  const auto deadline = t0 + std::chrono::duration_cast<Clock::duration>(
                                 std::chrono::duration<double>(std::max(0.0, options.time_limit_s)));
  Lacam lacam(inst, options.seed);
  PlanResult result = lacam.run(deadline);
  result.runtime_s = std::chrono::duration<double>(Clock::now() - t0).count();
  if (result.solved)
  {
    result.first_solution_s = result.runtime_s;
    result.first_sum_of_costs = sumOfCosts(result.paths);
  }
  return result;
}

}  // namespace mbot_coordination
