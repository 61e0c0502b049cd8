// A* global planner on hand-made grids (no ROS master).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <functional>
#include <queue>
#include <random>
#include <string>
#include <vector>

#include "mbot_navigation/global_planner/astar_planner.h"
#include "mbot_navigation/costmap/inflation_layer.h"
#include "mbot_navigation/global_planner/path_cost.h"
#include "mbot_navigation/global_planner/planner_factory.h"

using namespace mbot_navigation;

namespace
{
const double kRes = 0.05;

Pose2D at(const Costmap2D& m, int x, int y, double theta = 0.0)
{
  Pose2D p;
  m.mapToWorld(x, y, p.x, p.y);
  p.theta = theta;
  return p;
}

/// Length of a returned path [cells].
double lengthCells(const PlanResult& r)
{
  double len = 0.0;
  for (size_t i = 1; i < r.path.size(); ++i)
    len += std::hypot(r.path[i].x - r.path[i - 1].x, r.path[i].y - r.path[i - 1].y);
  return len / kRes;
}

/// Reference: plain Dijkstra with the planner's cost model; returns the optimal cost (or -1) and,
/// when `path` is given, the cells of the optimal path from start to goal.
double referenceCost(const Costmap2D& m, int sx, int sy, int gx, int gy, double neutral, double factor,
                     std::vector<int>* path = nullptr)
{
  const int W = m.sizeX(), H = m.sizeY();
  std::vector<double> dist(W * H, 1e300);
  std::vector<int> parent(W * H, -1);
  using Item = std::pair<double, int>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> pq;
  dist[sy * W + sx] = 0.0;
  pq.push({0.0, sy * W + sx});
  while (!pq.empty())
  {
    auto [d, i] = pq.top();
    pq.pop();
    if (d > dist[i]) continue;
    if (i == gy * W + gx)
    {
      if (path)
      {
        path->clear();
        for (int c = i; c != -1; c = parent[c]) path->push_back(c);
        std::reverse(path->begin(), path->end());
      }
      return d;
    }
    const int x = i % W, y = i / W;
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx)
      {
        const int nx = x + dx, ny = y + dy;
        if ((dx == 0 && dy == 0) || nx < 0 || ny < 0 || nx >= W || ny >= H) continue;
        const int c = m.cost(nx, ny);
        if (c >= cost::INSCRIBED) continue;
        // No corner cutting (the planner's rule): a diagonal step needs both side cells passable.
        if (dx != 0 && dy != 0 && (m.cost(x + dx, y) >= cost::INSCRIBED || m.cost(x, y + dy) >= cost::INSCRIBED))
          continue;
        const double nd = d + std::hypot(dx, dy) * (neutral + factor * c);
        if (nd < dist[ny * W + nx])
        {
          dist[ny * W + nx] = nd;
          parent[ny * W + nx] = i;
          pq.push({nd, ny * W + nx});
        }
      }
  }
  return -1.0;
}

/// Every pose of the path lies on a passable cell; consecutive poses are at most one cell apart.
void expectValidPath(const Costmap2D& m, const PlanResult& r)
{
  ASSERT_TRUE(r.ok) << r.error;
  for (size_t i = 0; i < r.path.size(); ++i)
  {
    unsigned mx, my;
    ASSERT_TRUE(m.worldToMap(r.path[i].x, r.path[i].y, mx, my));
    EXPECT_LT(m.cost(mx, my), cost::INSCRIBED) << "pose " << i;
    if (i > 0)
    {
      EXPECT_LE(std::hypot(r.path[i].x - r.path[i - 1].x, r.path[i].y - r.path[i - 1].y), kRes + 1e-9);
    }
  }
}

/// Optimal A* (heuristic_weight 1), no smoothing: the path is the grid path.
AStarConfig gridOnly()
{
  AStarConfig c;
  c.smooth_path = false;
  c.heuristic_weight = 1.0;
  return c;
}

/**
 * A fixture like the benchmark maps (bench/inputs/README.md), small enough for a brute-force
 * reference: 300 x 300 cells with a lethal border and seeded random lethal rectangles (8..60
 * cells a side, as there, ~15 % of the map), inflated as costmap_2d does (inscribed 0.15 m, inflation 0.55 m,
 * cost scaling 10) by InflationLayer.
 */
Costmap2D benchLikeMap(unsigned seed)
{
  const int N = 300;
  Costmap2D m(N, N, kRes, 0.0, 0.0);
  std::mt19937 rng(seed);
  std::uniform_int_distribution<int> side(8, 60), pos(1, N - 2);
  for (int i = 0; i < N; ++i)
  {
    m.setCost(i, 0, cost::LETHAL);
    m.setCost(i, N - 1, cost::LETHAL);
    m.setCost(0, i, cost::LETHAL);
    m.setCost(N - 1, i, cost::LETHAL);
  }
  for (int lethal = 0; lethal < N * N * 15 / 100;)
  {
    const int x0 = pos(rng), y0 = pos(rng), w = side(rng), h = side(rng);
    for (int y = y0; y < std::min(N - 1, y0 + h); ++y)
      for (int x = x0; x < std::min(N - 1, x0 + w); ++x)
        if (m.cost(x, y) != cost::LETHAL)
        {
          m.setCost(x, y, cost::LETHAL);
          ++lethal;
        }
  }
  InflationLayer inflation;  // defaults: 0.55 m, 10 /m
  inflation.onFootprintChanged(0.15);
  inflation.inflate(m);
  return m;
}

/// The poses through the centres of `cells` (as a planner returns them, ends at the centres).
std::vector<Pose2D> posesThrough(const Costmap2D& m, const std::vector<int>& cells)
{
  std::vector<Pose2D> poses;
  for (int c : cells) poses.push_back(at(m, c % m.sizeX(), c / m.sizeX()));
  return poses;
}

/// 40 x 40 free grid with a vertical wall at x = 20 except a gap at y = 32..33.
Costmap2D wallWithGap()
{
  Costmap2D m(40, 40, kRes, 0.0, 0.0);
  for (int y = 0; y < 40; ++y)
    if (y != 32 && y != 33) m.setCost(20, y, cost::LETHAL);
  return m;
}

/// 40 x 40 grid with a U opening to the left around the start; the goal is to its right.
Costmap2D uTrap()
{
  Costmap2D m(40, 40, kRes, 0.0, 0.0);
  for (int y = 10; y <= 30; ++y) m.setCost(25, y, cost::LETHAL);  // bottom of the U
  for (int x = 10; x <= 25; ++x)
  {
    m.setCost(x, 10, cost::LETHAL);  // arms
    m.setCost(x, 30, cost::LETHAL);
  }
  return m;
}
}  // namespace

TEST(AStar, EmptyGridGridPathIsOctileOptimalAndSmoothedPathIsStraight)
{
  Costmap2D m(30, 20, kRes, 0.0, 0.0);
  AStarPlanner grid(gridOnly());
  const PlanResult r = grid.makePlan(m, at(m, 2, 3), at(m, 27, 12, 0.7));
  expectValidPath(m, r);
  const double octile = 25 + (std::sqrt(2.0) - 1.0) * 9;  // dx 25, dy 9
  EXPECT_NEAR(grid.lastStats().grid_path_length, octile, 1e-9);
  EXPECT_NEAR(lengthCells(r), octile, 1e-9);

  AStarPlanner smooth;
  const PlanResult s = smooth.makePlan(m, at(m, 2, 3), at(m, 27, 12, 0.7));
  expectValidPath(m, s);
  EXPECT_NEAR(lengthCells(s), std::hypot(25, 9), 1e-9);  // one straight segment
  EXPECT_EQ(smooth.lastVertices().size(), 2u);
  // Orientation along the path, the goal's at the end.
  EXPECT_NEAR(s.path.front().theta, std::atan2(9, 25), 1e-9);
  EXPECT_NEAR(s.path[s.path.size() / 2].theta, std::atan2(9, 25), 1e-9);
  EXPECT_DOUBLE_EQ(s.path.back().theta, 0.7);
  EXPECT_DOUBLE_EQ(s.path.front().x, at(m, 2, 3).x);
}

TEST(AStar, WallWithOneGapOptimalAndSmoothedNotLonger)
{
  const Costmap2D m = wallWithGap();
  AStarPlanner grid(gridOnly());
  const PlanResult r = grid.makePlan(m, at(m, 5, 5), at(m, 35, 5));
  expectValidPath(m, r);
  // Free cells only: the cost is neutral_cost * length, so the reference gives the length.
  const double optimal = referenceCost(m, 5, 5, 35, 5, 1.0, 0.0);
  EXPECT_NEAR(grid.lastStats().grid_path_length, optimal, 1e-9);
  EXPECT_GT(optimal, 50.0);  // the detour through the gap is real (straight line: 30)

  AStarPlanner smooth;  // defaults: weighted A* + smoothing
  const PlanResult s = smooth.makePlan(m, at(m, 5, 5), at(m, 35, 5));
  expectValidPath(m, s);
  EXPECT_LE(lengthCells(s), smooth.lastStats().grid_path_length + 1e-9);
  // Any path passes through the gap's cells: no shorter than the two straight legs to its corner.
  const double lower = std::hypot(19.5 - 5, 31.5 - 5) + std::hypot(35 - 20.5, 31.5 - 5) + 1.0;
  EXPECT_GE(lengthCells(s), lower - 1e-9);
  EXPECT_LT(lengthCells(s), optimal - 3.0);  // smoothing cut the staircase
}

TEST(AStar, UTrapOptimalAndSmoothedNotLonger)
{
  const Costmap2D m = uTrap();
  AStarPlanner grid(gridOnly());
  const PlanResult r = grid.makePlan(m, at(m, 20, 20), at(m, 35, 20));
  expectValidPath(m, r);
  const double optimal = referenceCost(m, 20, 20, 35, 20, 1.0, 0.0);
  EXPECT_NEAR(grid.lastStats().grid_path_length, optimal, 1e-9);
  EXPECT_GT(optimal, 40.0);  // out of the U's mouth and around an arm

  AStarConfig c = gridOnly();
  c.smooth_path = true;
  AStarPlanner smooth(c);
  const PlanResult s = smooth.makePlan(m, at(m, 20, 20), at(m, 35, 20));
  expectValidPath(m, s);
  EXPECT_LE(lengthCells(s), grid.lastStats().grid_path_length + 1e-9);
  EXPECT_LT(lengthCells(s), optimal - 0.5);                           // the staircases are cut
  EXPECT_EQ(smooth.lastStats().expanded, grid.lastStats().expanded);  // smoothing does not change the search
}

TEST(AStar, CostAwareGridPathIsOptimalForTheCostModel)
{
  // A band of cost-200 cells across the direct route with a free detour around its end.
  Costmap2D m(50, 40, kRes, 0.0, 0.0);
  for (int y = 0; y < 30; ++y)
    for (int x = 24; x <= 26; ++x) m.setCost(x, y, 200);
  AStarConfig c = gridOnly();
  c.cost_factor = 3.0;
  AStarPlanner planner(c);
  const PlanResult r = planner.makePlan(m, at(m, 5, 10), at(m, 45, 10));
  expectValidPath(m, r);
  const double optimal = referenceCost(m, 5, 10, 45, 10, c.neutral_cost, c.cost_factor);
  // Within one bucket of the open list (neutral_cost / 8) of the optimum.
  EXPECT_GE(planner.lastStats().grid_path_cost, optimal * (1.0 - 1e-6));
  EXPECT_LE(planner.lastStats().grid_path_cost, optimal + c.neutral_cost / 8);
  // With cost_factor 3 crossing the band costs 3 cells * 650 = 1950 > the detour: it goes around.
  int max_cost = 0;
  for (uint32_t i : planner.lastGridPath()) max_cost = std::max<int>(max_cost, m.data()[i]);
  EXPECT_EQ(max_cost, 0);

  // With cost_factor 0 the band is just distance: straight through.
  AStarConfig flat = gridOnly();
  flat.cost_factor = 0.0;
  AStarPlanner straight(flat);
  const PlanResult f = straight.makePlan(m, at(m, 5, 10), at(m, 45, 10));
  EXPECT_NEAR(straight.lastStats().grid_path_length, 40.0, 1e-9);
}

TEST(AStar, RandomCostGridsOptimalAndWeightedBounds)
{
  // 100 random 60 x 50 grids (10 % lethal, 30 % random costs): heuristic_weight 1 finds the
  // optimal cost (within one open-list bucket); the default weight and 1.5 stay within that many
  // times the optimum (weighted A* without re-opening closed cells keeps its bound).
  std::mt19937 rng(3);
  std::uniform_int_distribution<int> value(0, 252), die(0, 9), col(0, 59), row(0, 49);
  const double default_w = AStarConfig().heuristic_weight;
  ASSERT_GT(default_w, 1.0);
  ASSERT_LT(default_w, 1.5);
  double worst_excess = 0.0, worst_ratio = 0.0, worst_default_ratio = 0.0;
  int planned = 0;
  for (int trial = 0; trial < 100; ++trial)
  {
    Costmap2D m(60, 50, kRes, 0.0, 0.0);
    for (int y = 0; y < 50; ++y)
      for (int x = 0; x < 60; ++x) m.setCost(x, y, die(rng) == 0 ? cost::LETHAL : (die(rng) < 3 ? value(rng) : 0));
    const int sx = col(rng), sy = row(rng), gx = col(rng), gy = row(rng);
    m.setCost(sx, sy, 0);
    m.setCost(gx, gy, 0);
    AStarConfig c = gridOnly();
    c.cost_factor = 3.0;
    const double optimal = referenceCost(m, sx, sy, gx, gy, c.neutral_cost, c.cost_factor);
    for (double w : {1.0, default_w, 1.5})
    {
      c.heuristic_weight = w;
      AStarPlanner planner(c);
      const PlanResult r = planner.makePlan(m, at(m, sx, sy), at(m, gx, gy));
      ASSERT_EQ(r.ok, optimal >= 0.0) << r.error;
      if (!r.ok) continue;
      const double got = planner.lastStats().grid_path_cost;
      if (w == 1.0)
      {
        worst_excess = std::max(worst_excess, got - optimal);
        ++planned;
      }
      else
      {
        double& worst = w == 1.5 ? worst_ratio : worst_default_ratio;
        worst = std::max(worst, got / std::max(optimal, 1e-9));
      }
    }
  }
  EXPECT_GT(planned, 50);
  EXPECT_LE(worst_excess, 50.0 / 8);
  EXPECT_LE(worst_ratio, 1.5);
  EXPECT_LE(worst_default_ratio, default_w);
}

TEST(AStar, WalledInGoalReportsNoPathAndSearchedCells)
{
  Costmap2D m(30, 30, kRes, 0.0, 0.0);
  for (int i = 18; i <= 24; ++i)
  {
    m.setCost(i, 18, cost::LETHAL);
    m.setCost(i, 24, cost::LETHAL);
    m.setCost(18, i, cost::LETHAL);
    m.setCost(24, i, cost::LETHAL);
  }
  AStarPlanner planner;
  const PlanResult r = planner.makePlan(m, at(m, 3, 3), at(m, 21, 21));
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.path.empty());
  // The search exhausts the start's region: all cells outside the box.
  const size_t reachable = 30 * 30 - 7 * 7;
  EXPECT_EQ(planner.lastStats().expanded, reachable);
  EXPECT_NE(r.error.find("unreachable from start"), std::string::npos) << r.error;
  EXPECT_NE(r.error.find("searched " + std::to_string(reachable) + " cells"), std::string::npos) << r.error;
}

TEST(AStar, RefusesGoalOrStartInAnObstacleWithItsCost)
{
  Costmap2D m = wallWithGap();
  m.setCost(30, 30, cost::INSCRIBED);
  AStarPlanner planner;
  // (1.01, 0.51) is in wall cell (20, 10); (1.51, 1.52) in cell (30, 30).
  PlanResult r = planner.makePlan(m, at(m, 5, 5), Pose2D{1.01, 0.51, 0.0});
  EXPECT_FALSE(r.ok);
  EXPECT_TRUE(r.path.empty());
  EXPECT_EQ(r.error, "goal (1.01, 0.51) is in an obstacle (cost 254)");
  r = planner.makePlan(m, Pose2D{1.51, 1.52, 0.0}, at(m, 5, 5));
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "start (1.51, 1.52) is too close to an obstacle (cost 253)");
}

TEST(AStar, RefusesOutsideAndNaN)
{
  Costmap2D m(20, 20, kRes, -0.5, -0.5);
  AStarPlanner planner;
  PlanResult r = planner.makePlan(m, Pose2D{0.0, 0.0, 0.0}, Pose2D{0.6, 0.0, 0.0});
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("goal (0.60, 0.00) is outside the map"), std::string::npos) << r.error;
  r = planner.makePlan(m, Pose2D{std::nan(""), 0.0, 0.0}, Pose2D{0.1, 0.0, 0.0});
  EXPECT_FALSE(r.ok);
  EXPECT_EQ(r.error, "start pose is not finite (NaN or Inf)");
  r = planner.makePlan(m, Pose2D{0.0, 0.0, 0.0}, Pose2D{0.1, 0.0, std::nan("")});
  EXPECT_EQ(r.error, "goal pose is not finite (NaN or Inf)");
}

TEST(AStar, UnknownCellsPassableOnlyWithAllowUnknown)
{
  Costmap2D m(30, 30, kRes, 0.0, 0.0);
  for (int y = 0; y < 30; ++y) m.setCost(15, y, cost::NO_INFORMATION);
  AStarPlanner allow;
  EXPECT_TRUE(allow.makePlan(m, at(m, 5, 5), at(m, 25, 5)).ok);
  AStarConfig c;
  c.allow_unknown = false;
  AStarPlanner refuse(c);
  const PlanResult r = refuse.makePlan(m, at(m, 5, 5), at(m, 25, 5));
  EXPECT_FALSE(r.ok);
  EXPECT_NE(r.error.find("unreachable"), std::string::npos);
  EXPECT_EQ(refuse.lastStats().expanded, 15u * 30u);  // the left half
}

TEST(AStar, StartAndGoalOnTheMapEdgeAndRepeatedQueries)
{
  Costmap2D m(25, 25, kRes, 0.0, 0.0);
  AStarPlanner planner(gridOnly());
  PlanResult a = planner.makePlan(m, at(m, 0, 0), at(m, 24, 24));
  expectValidPath(m, a);
  EXPECT_NEAR(planner.lastStats().grid_path_length, 24 * std::sqrt(2.0), 1e-9);
  PlanResult b = planner.makePlan(m, at(m, 24, 0), at(m, 0, 10));
  expectValidPath(m, b);
  EXPECT_NEAR(planner.lastStats().grid_path_length, 14 + 10 * std::sqrt(2.0), 1e-9);
  // Stamps from earlier queries do not leak into later ones; another map size works too.
  PlanResult a2 = planner.makePlan(m, at(m, 0, 0), at(m, 24, 24));
  ASSERT_EQ(a2.path.size(), a.path.size());
  for (size_t i = 0; i < a.path.size(); ++i) EXPECT_DOUBLE_EQ(a2.path[i].x, a.path[i].x);
  const Costmap2D wall = wallWithGap();
  EXPECT_NEAR(lengthCells(planner.makePlan(wall, at(wall, 5, 5), at(wall, 35, 5))),
              referenceCost(wall, 5, 5, 35, 5, 1.0, 0.0), 1e-9);
}

TEST(AStar, QueriesAfterAnExhaustedSearchAreStillOptimal)
{
  // The per-cell state and the open list are reused between queries: an exhausted search (no
  // path) and one that stopped early with cells still queued must not leak into the next one.
  Costmap2D m = wallWithGap();
  for (int i = 30; i <= 36; ++i)  // a walled-in box right of the wall, around (33, 15)
  {
    m.setCost(i, 12, cost::LETHAL);
    m.setCost(i, 18, cost::LETHAL);
    m.setCost(30, i - 18, cost::LETHAL);
    m.setCost(36, i - 18, cost::LETHAL);
  }
  AStarPlanner planner(gridOnly());
  const double optimal = referenceCost(m, 5, 5, 35, 5, 1.0, 0.0);
  for (int round = 0; round < 3; ++round)
  {
    EXPECT_FALSE(planner.makePlan(m, at(m, 5, 5), at(m, 33, 15)).ok);
    const PlanResult r = planner.makePlan(m, at(m, 5, 5), at(m, 35, 5));
    expectValidPath(m, r);
    EXPECT_NEAR(planner.lastStats().grid_path_length, optimal, 1e-9) << "round " << round;
    const PlanResult back = planner.makePlan(m, at(m, 35, 5), at(m, 5, 5));
    expectValidPath(m, back);
    EXPECT_NEAR(planner.lastStats().grid_path_length, optimal, 1e-9) << "round " << round;
  }
}

TEST(AStar, StartAndGoalInTheSameCell)
{
  Costmap2D m(10, 10, kRes, 0.0, 0.0);
  AStarPlanner planner;
  const PlanResult r = planner.makePlan(m, Pose2D{0.21, 0.22, 0.0}, Pose2D{0.23, 0.24, 1.0});
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_EQ(r.path.size(), 2u);
  EXPECT_DOUBLE_EQ(r.path[0].x, 0.21);
  EXPECT_NEAR(r.path[0].theta, M_PI / 4, 1e-9);  // facing the goal
  EXPECT_DOUBLE_EQ(r.path[1].y, 0.24);
  EXPECT_DOUBLE_EQ(r.path[1].theta, 1.0);
  EXPECT_EQ(planner.lastStats().expanded, 1u);
}

TEST(AStar, SmoothingKeepsClearOfInflatedCellsItMayNotCross)
{
  // A lethal block with a 2-cell inscribed halo: the straight line would cut the halo's corner.
  Costmap2D m(40, 40, kRes, 0.0, 0.0);
  for (int y = 10; y < 30; ++y)
    for (int x = 15; x < 25; ++x)
      m.setCost(x, y, (x < 17 || x > 22 || y < 12 || y > 27) ? cost::INSCRIBED : cost::LETHAL);
  AStarPlanner planner;
  const PlanResult r = planner.makePlan(m, at(m, 5, 15), at(m, 35, 25));
  expectValidPath(m, r);
  EXPECT_LE(lengthCells(r), planner.lastStats().grid_path_length + 1e-9);
}

TEST(AStar, PathCostWithinAQuarterOfNavfnDijkstraOnBenchLikeMaps)
{
  // The default settings (those of config/nav_move_base.yaml) against a brute-force Dijkstra with
  // navfn's cost model (neutral 50, factor 0.8: move_base's default planner), on random pairs of
  // far-apart free cells: the mean path cost (map costs of the cells the path passes,
  // path_cost.h) is at most 1.25 times the reference's. Every shortcut of the smoothing keeps the
  // cost at or below the grid path's, and the smoothed path is shorter.
  AStarPlanner planner;
  double planned_cost = 0.0, reference_cost = 0.0, planned_len = 0.0, grid_len = 0.0;
  int pairs = 0;
  for (unsigned seed : {1u, 2u, 3u})
  {
    const Costmap2D m = benchLikeMap(seed);
    std::mt19937 rng(100 + seed);
    std::uniform_int_distribution<int> pos(1, 298);
    for (int k = 0; k < 15;)
    {
      const int sx = pos(rng), sy = pos(rng), gx = pos(rng), gy = pos(rng);
      if (m.cost(sx, sy) >= cost::INSCRIBED || m.cost(gx, gy) >= cost::INSCRIBED || std::hypot(gx - sx, gy - sy) < 150)
        continue;
      std::vector<int> reference;
      if (referenceCost(m, sx, sy, gx, gy, 50.0, 0.8, &reference) < 0.0) continue;
      ++k;
      const PlanResult r = planner.makePlan(m, at(m, sx, sy), at(m, gx, gy));
      expectValidPath(m, r);
      const double cost = pathCellCost(m, r.path);
      const std::vector<uint32_t>& grid = planner.lastGridPath();
      const double grid_cost = pathCellCost(m, posesThrough(m, std::vector<int>(grid.begin(), grid.end())));
      EXPECT_LE(cost, grid_cost + 1e-9) << "seed " << seed << " pair " << k;
      planned_cost += cost;
      reference_cost += pathCellCost(m, posesThrough(m, reference));
      planned_len += lengthCells(r);
      grid_len += planner.lastStats().grid_path_length;
      ++pairs;
    }
  }
  ASSERT_EQ(pairs, 45);
  EXPECT_GT(reference_cost, 0.0);  // the pairs do pass inflated cells
  EXPECT_LE(planned_cost, 1.25 * reference_cost) << "mean " << planned_cost / pairs << " vs " << reference_cost / pairs;
  EXPECT_LT(planned_len, grid_len);
  std::printf("mean path cost %.1f (navfn-model Dijkstra %.1f), mean length %.1f cells (grid path %.1f)\n",
              planned_cost / pairs, reference_cost / pairs, planned_len / pairs, grid_len / pairs);
}

TEST(PlannerFactory, MakesAStarAndRejectsUnknownNames)
{
  GlobalPlannerParams params;
  params.astar.cost_factor = 2.0;
  auto planner = makeGlobalPlanner("astar", params);
  ASSERT_TRUE(planner);
  EXPECT_EQ(planner->name(), "astar");
  EXPECT_DOUBLE_EQ(dynamic_cast<AStarPlanner&>(*planner).config().cost_factor, 2.0);
  params.ompl.planner = "rrtconnect";
  auto ompl = makeGlobalPlanner("ompl", params);
  ASSERT_TRUE(ompl);
  EXPECT_EQ(ompl->name(), "ompl");
  EXPECT_EQ(dynamic_cast<OmplPlanner&>(*ompl).config().planner, "rrtconnect");
  try
  {
    makeGlobalPlanner("dstar", params);
    FAIL() << "expected an exception";
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_NE(std::string(e.what()).find("unknown global planner 'dstar' (expected one of: astar, ompl)"),
              std::string::npos)
        << e.what();
  }
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
