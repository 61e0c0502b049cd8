// ECBS: with w = 1 the optimum (against an exhaustive search over joint moves), with w > 1 within
// w of it, its lower bound never above the optimum; what prioritized planning cannot solve; a real
// benchmark instance; a bad w refused.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <queue>
#include <random>

#include "mbot_coordination/movingai.h"
#include "mbot_coordination/planner.h"

using namespace mbot_coordination;

namespace
{
const std::string kDir = MAPF_BENCH_DIR;

Grid mapOf(const std::vector<std::string>& rows)
{
  std::string text =
      "type octile\nheight " + std::to_string(rows.size()) + "\nwidth " + std::to_string(rows[0].size()) + "\nmap\n";
  for (const auto& r : rows) text += r + "\n";
  return parseMap(text, "test.map");
}

PlanResult ecbs(const Instance& inst, double w, double limit = 5.0, const std::string& name = "ecbs")
{
  PlannerOptions options;
  options.time_limit_s = limit;
  options.w = w;
  return makePlanner(name)->solve(inst, options);
}

// The optimal sum of costs (-1: no solution), by Dijkstra over (every agent's cell, which agents
// have stopped at their goals for good). A step costs one per agent not stopped; stopping at the
// goal costs nothing and the agent never moves again, so an agent pays up to its last arrival.
long optimalSumOfCosts(const Instance& inst)
{
  const Grid& g = *inst.grid;
  const size_t n = inst.starts.size();
  using State = std::pair<std::vector<int>, unsigned>;
  std::map<State, long> best;
  using Item = std::pair<long, State>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  auto relax = [&](const State& s, long cost) {
    auto it = best.find(s);
    if (it != best.end() && it->second <= cost) return;
    best[s] = cost;
    queue.push({cost, s});
  };
  relax({inst.starts, 0u}, 0);
  const unsigned all = (1u << n) - 1;
  while (!queue.empty())
  {
    const auto [cost, s] = queue.top();
    queue.pop();
    if (best[s] < cost) continue;
    const auto& c = s.first;
    const unsigned stopped = s.second;
    if (stopped == all) return cost;
    for (size_t i = 0; i < n; ++i)
      if (!(stopped & (1u << i)) && c[i] == inst.goals[i]) relax({c, stopped | (1u << i)}, cost);
    std::vector<std::vector<int>> options(n);
    long step = 0;
    for (size_t i = 0; i < n; ++i)
    {
      options[i] = {c[i]};
      if (stopped & (1u << i)) continue;
      ++step;
      for (int v : g.neighbours(c[i])) options[i].push_back(v);
    }
    std::vector<size_t> pick(n, 0);
    while (true)
    {
      std::vector<int> next(n);
      for (size_t i = 0; i < n; ++i) next[i] = options[i][pick[i]];
      bool ok = true;
      for (size_t i = 0; i < n && ok; ++i)
        for (size_t j = i + 1; j < n && ok; ++j)
          if (next[i] == next[j] || (next[i] == c[j] && next[j] == c[i])) ok = false;
      if (ok) relax({next, stopped}, cost + step);
      size_t k = 0;
      while (k < n && ++pick[k] == options[k].size()) pick[k++] = 0;
      if (k == n) break;
    }
  }
  return -1;
}
}  // namespace

TEST(Ecbs, OptimalWithW1AndBoundedWithW)
{
  std::mt19937 rng(11);
  int compared = 0, detours = 0;
  for (int trial = 0; trial < 120; ++trial)
  {
    // a 4 x 3 grid with up to 3 random walls and 2-3 agents
    std::vector<std::string> rows(3, "....");
    for (int w = 0; w < static_cast<int>(rng() % 4); ++w) rows[rng() % 3][rng() % 4] = '@';
    const Grid g = mapOf(rows);
    std::vector<int> free;
    for (int v = 0; v < g.size(); ++v)
      if (g.isFree(v)) free.push_back(v);
    const size_t n = 2 + rng() % 2;
    if (free.size() < n + 2) continue;
    std::shuffle(free.begin(), free.end(), rng);
    Instance inst{&g, std::vector<int>(free.begin(), free.begin() + n), {}};
    std::shuffle(free.begin(), free.end(), rng);
    inst.goals.assign(free.begin(), free.begin() + n);
    try
    {
      checkInstance(inst);
    }
    catch (const std::invalid_argument&)
    {
      continue;  // a goal cut off from its start
    }
    const long optimum = optimalSumOfCosts(inst);
    if (optimum < 0) continue;  // unsolvable: CBS would search for ever (only the time limit ends it)
    ++compared;
    if (optimum > lowerBound(inst)) ++detours;
    for (const auto& [name, w] :
         std::vector<std::pair<std::string, double>>{{"ecbs", 1.0}, {"ecbs", 1.5}, {"eecbs", 1.0}, {"eecbs", 1.5}})
    {
      const PlanResult r = ecbs(inst, w, 30.0, name);  // a guard: one case needs ~34000 nodes
      SCOPED_TRACE(name);
      ASSERT_TRUE(r.solved) << "trial " << trial << " w " << w << ": " << r.message;
      EXPECT_EQ(validate(inst, r.paths), "") << "trial " << trial;
      const long cost = sumOfCosts(r.paths);
      if (w == 1.0) EXPECT_EQ(cost, optimum) << "trial " << trial;
      EXPECT_LE(cost, w * optimum + 1e-9) << "trial " << trial << " w " << w;
      EXPECT_LE(cost, w * r.lower_bound + 1e-9) << "trial " << trial << " w " << w;  // the certificate
      EXPECT_LE(r.lower_bound, optimum) << "trial " << trial << " w " << w;          // a true lower bound
      EXPECT_GE(r.lower_bound, lowerBound(inst)) << "trial " << trial << " w " << w;
    }
  }
  EXPECT_GT(compared, 50);
  EXPECT_GT(detours, 10);  // instances where agents get in each other's way were among them
}

TEST(Ecbs, SolvesWherePrioritizedPlanningFails)
{
  // the swap through a pocket in the middle of a corridor (no priority order solves it)
  const Grid g = mapOf({".....", "@@.@@"});
  Instance inst{&g, {g.id(0, 0), g.id(4, 0)}, {g.id(4, 0), g.id(0, 0)}};
  PlannerOptions quick;
  quick.time_limit_s = 0.2;
  EXPECT_FALSE(makePlanner("pp")->solve(inst, quick).solved);
  const PlanResult r = ecbs(inst, 1.0);
  ASSERT_TRUE(r.solved) << r.message;
  EXPECT_EQ(validate(inst, r.paths), "");
  EXPECT_EQ(sumOfCosts(r.paths), optimalSumOfCosts(inst));
  // an agent parked on its goal in a corridor must step aside and come back (goal constraints)
  const Grid h = mapOf({".....", "@.@@@"});
  Instance park{&h, {h.id(0, 0), h.id(2, 0)}, {h.id(4, 0), h.id(2, 0)}};
  const PlanResult p = ecbs(park, 1.0);
  ASSERT_TRUE(p.solved) << p.message;
  EXPECT_EQ(validate(park, p.paths), "");
  EXPECT_EQ(sumOfCosts(p.paths), optimalSumOfCosts(park));
}

TEST(Ecbs, BenchmarkInstanceWithinItsBound)
{
  const Grid g = readMap(kDir + "/random-32-32-10.map");
  const Instance inst = instanceFromScen(g, readScen(kDir + "/random-32-32-10-random-1.scen", &g), 50);
  for (const auto& [name, w] :
       std::vector<std::pair<std::string, double>>{{"ecbs", 1.05}, {"eecbs", 1.05}, {"ecbs", 1.2}})
  {
    SCOPED_TRACE(name);
    const PlanResult r = ecbs(inst, w, 30.0, name);  // the limit only guards against a hang
    ASSERT_TRUE(r.solved) << "w " << w << ": " << r.message;
    EXPECT_EQ(validate(inst, r.paths), "");
    EXPECT_LE(sumOfCosts(r.paths), w * r.lower_bound + 1e-9) << "w " << w;
    EXPECT_GE(r.lower_bound, lowerBound(inst)) << "w " << w;
  }
}

TEST(Ecbs, RefusesABadW)
{
  const Grid g = mapOf({"...."});
  Instance inst{&g, {g.id(0, 0)}, {g.id(3, 0)}};
  for (double w : {0.9, -1.0, std::nan("")})
  {
    try
    {
      ecbs(inst, w);
      FAIL() << w;
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_EQ(std::string(e.what()).rfind("ecbs: suboptimality bound w must be >= 1, got ", 0), 0u) << e.what();
    }
  }
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
