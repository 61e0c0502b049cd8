// SIPP and prioritized planning on hand-made cases, LaCAM where prioritized planning fails and
// against a brute-force search on tiny instances, and every algorithm on real benchmark instances.
#include <gtest/gtest.h>

#include <map>
#include <queue>
#include <random>
#include <set>

#include "mbot_coordination/lns.h"
#include "mbot_coordination/movingai.h"
#include "mbot_coordination/planner.h"
#include "mbot_coordination/sipp.h"

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

PlanResult solve(const std::string& algorithm, const Instance& inst, double limit = 2.0)
{
  PlannerOptions options;
  options.time_limit_s = limit;
  return makePlanner(algorithm)->solve(inst, options);
}

// Is there any conflict-free plan? Breadth-first over joint configurations (tiny instances only).
bool solvableByBruteForce(const Instance& inst)
{
  const Grid& g = *inst.grid;
  const size_t n = inst.starts.size();
  std::set<std::vector<int>> seen{inst.starts};
  std::queue<std::vector<int>> queue;
  queue.push(inst.starts);
  while (!queue.empty())
  {
    const auto c = queue.front();
    queue.pop();
    if (c == inst.goals) return true;
    // every combination of moves (wait or a neighbour per agent)
    std::vector<std::vector<int>> options(n);
    for (size_t i = 0; i < n; ++i)
    {
      options[i] = g.neighbours(c[i]);
      options[i].push_back(c[i]);
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
      if (ok && seen.insert(next).second) queue.push(next);
      size_t k = 0;
      while (k < n && ++pick[k] == options[k].size()) pick[k++] = 0;
      if (k == n) break;
    }
  }
  return false;
}
}  // namespace

TEST(Sipp, WaitsForAPassingAgent)
{
  // Agent 0 drives along the corridor; agent 1 in the side pocket (2,1) must wait until it passed
  // before going to (1,0): entering at t=1 would swap with it or block it.
  const Grid g = mapOf({".....", "@@.@@"});
  ReservationTable table(g.size());
  table.reservePath({g.id(0, 0), g.id(1, 0), g.id(2, 0), g.id(3, 0), g.id(4, 0)});
  const auto h = g.distancesTo(g.id(1, 0));
  const auto path = sippPath(g, table, g.id(2, 1), g.id(1, 0), h, Clock::now() + std::chrono::seconds(1));
  const std::vector<int> expected = {g.id(2, 1), g.id(2, 1), g.id(2, 1), g.id(2, 0), g.id(1, 0)};
  EXPECT_EQ(path, expected);
  Instance inst{&g, {g.id(0, 0), g.id(2, 1)}, {g.id(4, 0), g.id(1, 0)}};
  EXPECT_EQ(validate(inst, {{g.id(0, 0), g.id(1, 0), g.id(2, 0), g.id(3, 0), g.id(4, 0)}, path}), "");
}

TEST(Sipp, NoPathThroughAParkedAgent)
{
  // an agent parked for good at (1,0) cuts the corridor
  const Grid g = mapOf({"...."});
  ReservationTable table(g.size());
  table.reservePath({g.id(1, 0)});
  EXPECT_TRUE(
      sippPath(g, table, g.id(0, 0), g.id(3, 0), g.distancesTo(g.id(3, 0)), Clock::now() + std::chrono::seconds(1))
          .empty());
}

TEST(Sipp, ArrivesAfterTheLastAgentCrossingItsGoal)
{
  // agent X waits at (0,0), crosses (1,0) at t=4 and parks at (1,1): our agent (3,0) -> (1,0),
  // two steps away, can only stay at its goal from t=5 on
  const Grid g = mapOf({"....", "...."});
  const std::vector<int> x = {g.id(0, 0), g.id(0, 0), g.id(0, 0), g.id(0, 0), g.id(1, 0), g.id(1, 1)};
  ReservationTable table(g.size());
  table.reservePath(x);
  const auto p =
      sippPath(g, table, g.id(3, 0), g.id(1, 0), g.distancesTo(g.id(1, 0)), Clock::now() + std::chrono::seconds(1));
  ASSERT_EQ(p.size(), 6u);
  EXPECT_EQ(p.back(), g.id(1, 0));
  Instance inst{&g, {g.id(0, 0), g.id(3, 0)}, {g.id(1, 1), g.id(1, 0)}};
  EXPECT_EQ(validate(inst, {x, p}), "");
}

TEST(Prioritized, SwapWithAPassingPlace)
{
  // Two agents swap ends of a corridor with a pocket at (4,1): one of them ducks into it.
  const Grid g = mapOf({".......", "@@@@.@@"});
  Instance inst{&g, {g.id(0, 0), g.id(6, 0)}, {g.id(6, 0), g.id(0, 0)}};
  const PlanResult r = solve("pp", inst);
  ASSERT_TRUE(r.solved) << r.message;
  EXPECT_EQ(validate(inst, r.paths), "");
  bool ducked = false;
  for (const auto& p : r.paths)
    for (int v : p) ducked = ducked || v == g.id(4, 1);
  EXPECT_TRUE(ducked);
  EXPECT_EQ(sumOfCosts(r.paths), 6 + 9);  // one drives straight, the other loses 3 steps
}

TEST(Lacam, SolvesWherePrioritizedPlanningFails)
{
  // The pocket is in the middle: whichever agent goes first drives straight through it and the
  // other is caught in its dead end; with any order prioritized planning fails.
  const Grid g = mapOf({".....", "@@.@@"});
  Instance inst{&g, {g.id(0, 0), g.id(4, 0)}, {g.id(4, 0), g.id(0, 0)}};
  const PlanResult pp = solve("pp", inst, 0.2);
  EXPECT_FALSE(pp.solved);
  EXPECT_NE(pp.message.find("time limit"), std::string::npos);
  for (const std::string alg : {"lacam", "auto"})
  {
    const PlanResult r = solve(alg, inst, 2.0);
    ASSERT_TRUE(r.solved) << alg << ": " << r.message;
    EXPECT_EQ(validate(inst, r.paths), "") << alg;
    EXPECT_EQ(r.algorithm.rfind("lacam", 0), 0u) << r.algorithm;  // auto: "lacam+lns"
  }
  // Three agents through a room with one door: pp's first order blocks the door.
  const Grid room = mapOf({"...@...", "...@...", ".......", "...@..."});
  Instance crowd{&room,
                 {room.id(0, 0), room.id(1, 0), room.id(2, 0), room.id(6, 3)},
                 {room.id(6, 0), room.id(5, 0), room.id(3, 2), room.id(0, 3)}};
  const PlanResult r = solve("lacam", crowd);
  ASSERT_TRUE(r.solved) << r.message;
  EXPECT_EQ(validate(crowd, r.paths), "");
}

TEST(Lacam, ReportsAnUnsolvableInstance)
{
  // two agents swapping in a two-cell corridor: no solution; LaCAM is complete, so it says so
  const Grid g = mapOf({"..", "@@"});
  Instance inst{&g, {g.id(0, 0), g.id(1, 0)}, {g.id(1, 0), g.id(0, 0)}};
  const PlanResult r = solve("lacam", inst, 5.0);
  EXPECT_FALSE(r.solved);
  EXPECT_EQ(r.message, "no solution exists (every configuration tried)");
  EXPECT_LT(r.runtime_s, 1.0);  // it ends by exhausting the search, not by the limit
}

TEST(Lacam, AgreesWithBruteForceOnTinyInstances)
{
  std::mt19937 rng(7);
  int solvable = 0, unsolvable = 0;
  for (int trial = 0; trial < 150; ++trial)
  {
    // a 3 x 3 grid with up to 3 random walls and 2-3 agents
    std::vector<std::string> rows(3, "...");
    for (int w = 0; w < static_cast<int>(rng() % 4); ++w) rows[rng() % 3][rng() % 3] = '@';
    const Grid g = mapOf(rows);
    std::vector<int> free;
    for (int v = 0; v < g.size(); ++v)
      if (g.isFree(v)) free.push_back(v);
    const size_t n = 2 + rng() % 2;
    if (free.size() < n + 1) continue;
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
      continue;  // a goal cut off from its start: not a MAPF question
    }
    const bool expected = solvableByBruteForce(inst);
    const PlanResult r = solve("lacam", inst, 5.0);
    EXPECT_EQ(r.solved, expected) << "trial " << trial << ": " << r.message;
    if (r.solved) EXPECT_EQ(validate(inst, r.paths), "") << "trial " << trial;
    const PlanResult pp = solve("pp", inst, 0.05);
    if (pp.solved)
    {
      EXPECT_TRUE(expected) << "trial " << trial;
      EXPECT_EQ(validate(inst, pp.paths), "") << "trial " << trial;
    }
    (expected ? solvable : unsolvable)++;
  }
  EXPECT_GT(solvable, 30);  // both kinds were met
  EXPECT_GT(unsolvable, 3);
}

TEST(Planners, BenchmarkInstances)
{
  const std::pair<std::string, int> cases[] = {{"empty-32-32", 20}, {"random-32-32-10", 30}, {"room-32-32-4", 30}};
  for (const auto& c : cases)
  {
    const Grid g = readMap(kDir + "/" + c.first + ".map");
    const auto rows = readScen(kDir + "/" + c.first + "-random-1.scen", &g);
    const Instance inst = instanceFromScen(g, rows, c.second);
    double scen_bound = 0.0;
    for (int i = 0; i < c.second; ++i) scen_bound += rows[i].optimal_length;
    for (const auto& alg : plannerNames())
    {
      const PlanResult r = solve(alg, inst, 10.0);
      ASSERT_TRUE(r.solved) << c.first << " " << alg << ": " << r.message;
      EXPECT_EQ(validate(inst, r.paths), "") << c.first << " " << alg;
      EXPECT_GE(sumOfCosts(r.paths), lowerBound(inst)) << c.first << " " << alg;
      EXPECT_GE(sumOfCosts(r.paths), scen_bound) << c.first << " " << alg;
      EXPECT_GE(lowerBound(inst), scen_bound);  // 4-connected paths are never shorter than octile ones
    }
  }
}

TEST(Lns, ImprovesAndKeepsTheSolutionValid)
{
  // pp's solution on room-32-32-4 with 60 agents has room to improve (measured: 17 % over the bound)
  const Grid g = readMap(kDir + "/room-32-32-4.map");
  const Instance inst = instanceFromScen(g, readScen(kDir + "/room-32-32-4-random-1.scen", &g), 60);
  const PlanResult pp = solve("pp", inst);
  ASSERT_TRUE(pp.solved) << pp.message;
  Paths paths = pp.paths;
  // 100 iterations (the 20 s deadline only guards against a hang): the same on a busy machine
  const auto stats = refineLns(inst, paths, Clock::now() + std::chrono::seconds(20), 1, 8, 100);
  EXPECT_EQ(stats.iterations, 100);
  EXPECT_GT(stats.improvements, 0);
  EXPECT_LT(sumOfCosts(paths), sumOfCosts(pp.paths));
  EXPECT_GE(sumOfCosts(paths), lowerBound(inst));
  EXPECT_EQ(validate(inst, paths), "");
}

TEST(Planners, ByNameAndBadInput)
{
  for (const auto& name : plannerNames()) EXPECT_EQ(makePlanner(name)->name(), name);
  try
  {
    makePlanner("cbs");
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_STREQ(e.what(), "unknown MAPF algorithm 'cbs' (known: pp, lacam, ecbs, eecbs, auto)");
  }
  const Grid g = mapOf({"...."});
  Instance two_on_one_goal{&g, {g.id(0, 0), g.id(1, 0)}, {g.id(3, 0), g.id(3, 0)}};
  for (const auto& name : plannerNames()) EXPECT_THROW(solve(name, two_on_one_goal), std::invalid_argument) << name;
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
