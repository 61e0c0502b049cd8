// Layered costmap: static, obstacle, inflation and robots layers, rolling window (no ROS master).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <random>
#include <tuple>
#include <vector>

#include "mbot_navigation/costmap/inflation_layer.h"
#include "mbot_navigation/costmap/layered_costmap.h"
#include "mbot_navigation/costmap/obstacle_layer.h"
#include "mbot_navigation/costmap/robots_layer.h"
#include "mbot_navigation/costmap/static_layer.h"

using namespace mbot_navigation;

namespace
{
const double kInf = std::numeric_limits<double>::infinity();

/// Cost of the master cell holding the point (x, y) [m]; -1 when outside.
int costAt(const Costmap2D& m, double x, double y)
{
  unsigned mx, my;
  if (!m.worldToMap(x, y, mx, my)) return -1;
  return m.cost(mx, my);
}

/// costmap_2d's inflation formula, written out independently of InflationLayer.
int formula(double dist_m, double inscribed, double inflation_radius, double csf)
{
  if (dist_m == 0.0) return 254;
  if (dist_m <= inscribed) return 253;
  if (dist_m > inflation_radius + 1e-12) return 0;
  return static_cast<int>(252.0 * std::exp(-csf * (dist_m - inscribed)));
}

LayeredCostmapConfig staticConfig(double w, double h, double robot_radius = 0.15)
{
  LayeredCostmapConfig c;
  c.width = w;
  c.height = h;
  c.resolution = 0.05;
  c.robot_radius = robot_radius;
  return c;
}
}  // namespace

// ---------------------------------------------------------------- inflation

TEST(InflationLayer, CostsMatchFormulaAtGivenDistances)
{
  // One lethal cell at (20, 20); 0.05 m cells, inscribed 0.15 m, inflation 0.55 m, factor 10.
  Costmap2D grid(41, 41, 0.05, 0.0, 0.0);
  grid.setCost(20, 20, cost::LETHAL);
  InflationLayer inflation;
  inflation.onFootprintChanged(0.15);
  inflation.inflate(grid);

  EXPECT_EQ(grid.cost(20, 20), 254);  // d = 0
  EXPECT_EQ(grid.cost(21, 20), 253);  // 0.05 m <= inscribed
  EXPECT_EQ(grid.cost(22, 20), 253);  // 0.10 m
  // 3 cells: 3 * 0.05 = 0.15000000000000002 > 0.15 in doubles, so costmap_2d gives
  // (unsigned char)(252 * exp(-10 * 2.8e-17)) = 251, not 253. We keep that.
  EXPECT_EQ(grid.cost(23, 20), 251);
  EXPECT_EQ(grid.cost(24, 20), 152);  // 252 * exp(-0.5)   = 152.85
  EXPECT_EQ(grid.cost(25, 20), 92);   // 252 * exp(-1.0)   = 92.71
  EXPECT_EQ(grid.cost(25, 25), 32);   // d = sqrt(50) cells = 0.3536 m: 252 * exp(-2.036) = 32.91
  EXPECT_EQ(grid.cost(30, 20), 7);    // 0.50 m: 252 * exp(-3.5) = 7.61
  EXPECT_EQ(grid.cost(31, 20), 4);    // 0.55 m = inflation_radius: 252 * exp(-4) = 4.62
  EXPECT_EQ(grid.cost(31, 21), 0);    // sqrt(122) cells = 0.5523 m > inflation_radius
  EXPECT_EQ(grid.cost(32, 20), 0);    // 0.60 m
  EXPECT_EQ(inflation.computeCost(4.0), 152);
}

TEST(InflationLayer, ExactEuclideanDistanceToNearestLethalCell)
{
  // Random obstacles; every cell must equal the formula at the brute-force nearest distance.
  const int W = 70, H = 55;
  Costmap2D grid(W, H, 0.05, 0.0, 0.0);
  std::mt19937 rng(7);
  std::uniform_int_distribution<int> rx(0, W - 1), ry(0, H - 1);
  std::vector<std::pair<int, int>> lethal;
  for (int i = 0; i < 25; ++i)
  {
    const int x = rx(rng), y = ry(rng);
    grid.setCost(x, y, cost::LETHAL);
    lethal.emplace_back(x, y);
  }
  InflationLayerConfig cfg;
  cfg.inflation_radius = 0.4;
  cfg.cost_scaling_factor = 5.0;
  InflationLayer inflation(cfg);
  inflation.onFootprintChanged(0.12);
  inflation.inflate(grid);

  int mismatches = 0, inflated = 0;
  for (int y = 0; y < H; ++y)
    for (int x = 0; x < W; ++x)
    {
      double best = kInf;
      for (const auto& l : lethal) best = std::min(best, std::hypot(x - l.first, y - l.second));
      const int expected = formula(best * 0.05, 0.12, 0.4, 5.0);
      mismatches += grid.cost(x, y) != expected;
      inflated += expected > 0 && expected < 253;
    }
  EXPECT_EQ(mismatches, 0);
  EXPECT_GT(inflated, 500);  // the check covered many inflated cells
}

// ---------------------------------------------------------------- static layer

TEST(StaticLayer, InterpretsOccupancyValues)
{
  std::vector<int8_t> data = {0, 100, -1, 50, 99, 0};  // 3 x 2 map
  for (bool track_unknown : {false, true})
  {
    LayeredCostmapConfig cc = staticConfig(1.0, 1.0);
    cc.track_unknown_space = track_unknown;
    LayeredCostmap costmap(cc);
    StaticLayerConfig sc;
    sc.track_unknown_space = track_unknown;
    auto& layer = static_cast<StaticLayer&>(costmap.addLayer(std::make_unique<StaticLayer>(sc)));
    layer.setMap(3, 2, 0.1, -1.0, 2.0, data.data());
    costmap.updateMap(Pose2D{});
    const Costmap2D& m = costmap.costmap();
    ASSERT_EQ(m.sizeX(), 3u);  // a static costmap takes the map's geometry
    ASSERT_EQ(m.sizeY(), 2u);
    EXPECT_DOUBLE_EQ(m.originX(), -1.0);
    EXPECT_EQ(m.cost(0, 0), cost::FREE);
    EXPECT_EQ(m.cost(1, 0), cost::LETHAL);
    EXPECT_EQ(m.cost(2, 0), track_unknown ? cost::NO_INFORMATION : cost::FREE);
    EXPECT_EQ(m.cost(0, 1), cost::FREE);  // trinary: 50 is free
    EXPECT_EQ(m.cost(1, 1), cost::FREE);  // 99 < lethal_cost_threshold 100
  }
}

// ---------------------------------------------------------------- obstacle layer

class ObstacleLayerTest : public ::testing::Test
{
protected:
  void SetUp() override
  {
    LayeredCostmapConfig cc = staticConfig(6.0, 6.0, 0.0);  // 120 x 120 cells at (0, 0)
    costmap = std::make_unique<LayeredCostmap>(cc);
    obstacles = &static_cast<ObstacleLayer&>(costmap->addLayer(std::make_unique<ObstacleLayer>()));
    costmap->updateMap(robot);
  }
  void scan(const ScanObservation& s)
  {
    obstacles->addObservation(s);
    costmap->updateMap(robot);
  }
  int at(double x, double y) const { return costAt(costmap->costmap(), x, y); }

  std::unique_ptr<LayeredCostmap> costmap;
  ObstacleLayer* obstacles = nullptr;
  Pose2D robot{0.5, 0.5, 0.0};
};

TEST_F(ObstacleLayerTest, MarksHitThenLaterBeamThroughItClearsIt)
{
  ScanObservation s1;
  s1.origin_x = 1.025;
  s1.origin_y = 1.025;
  s1.addEndpoint(2.025, 1.025);  // 1 m ahead
  scan(s1);
  EXPECT_EQ(at(2.025, 1.025), cost::LETHAL);
  EXPECT_EQ(at(1.525, 1.025), cost::FREE);

  // From elsewhere, a beam passes through that cell and hits 1 m further on.
  ScanObservation s2;
  s2.origin_x = 1.025;
  s2.origin_y = 1.025;
  s2.addEndpoint(3.025, 1.025);
  scan(s2);
  EXPECT_EQ(at(2.025, 1.025), cost::FREE);  // cleared by the ray
  EXPECT_EQ(at(3.025, 1.025), cost::LETHAL);
}

namespace
{
/// An obstacle layer (inf_is_valid as given) with marks 2.0 m and 3.5 m along +x from the sensor at
/// (0.525, 2.025), then one +Inf beam along +x from there (range_max as given).
/// @return the costs at 2.0 m and 3.5 m, and the number of LETHAL cells.
std::tuple<int, int, int> afterANoReturnBeam(bool inf_is_valid, double range_max)
{
  LayeredCostmap costmap(staticConfig(6.0, 6.0, 0.0));
  ObstacleLayerConfig oc;
  oc.inf_is_valid = inf_is_valid;
  auto& layer = static_cast<ObstacleLayer&>(costmap.addLayer(std::make_unique<ObstacleLayer>(oc)));
  const Pose2D robot{0.5, 0.5, 0.0};
  ScanObservation marks;
  marks.origin_x = 0.525;
  marks.origin_y = 2.025;
  marks.addEndpoint(2.525, 2.025);
  ScanObservation far_mark;  // 3.5 m is beyond obstacle_range (2.5): mark it from closer
  far_mark.origin_x = 2.525;
  far_mark.origin_y = 3.025;
  far_mark.addEndpoint(4.025, 2.025);
  layer.addObservation(marks);
  layer.addObservation(far_mark);
  costmap.updateMap(robot);
  EXPECT_EQ(costAt(costmap.costmap(), 2.525, 2.025), cost::LETHAL);
  EXPECT_EQ(costAt(costmap.costmap(), 4.025, 2.025), cost::LETHAL);

  ScanObservation none;
  none.origin_x = 0.525;
  none.origin_y = 2.025;
  none.range_max = range_max;
  none.addNoReturn(0.0);  // +Inf along +x
  layer.addObservation(none);
  costmap.updateMap(robot);
  int lethal = 0;
  for (unsigned i = 0; i < 120 * 120; ++i) lethal += costmap.costmap().data()[i] == cost::LETHAL;
  return {costAt(costmap.costmap(), 2.525, 2.025), costAt(costmap.costmap(), 4.025, 2.025), lethal};
}
}  // namespace

TEST(ObstacleLayerInf, NoReturnBeamIsIgnoredByDefaultAsInCostmap2d)
{
  // costmap_2d's inf_is_valid defaults to false: a +Inf reading neither clears nor marks.
  EXPECT_FALSE(ObstacleLayerConfig().inf_is_valid);
  EXPECT_EQ(afterANoReturnBeam(false, 8.0), std::make_tuple(int(cost::LETHAL), int(cost::LETHAL), 2));
}

TEST(ObstacleLayerInf, NoReturnBeamWithInfIsValidClearsUpToRaytraceRange)
{
  // A reading at range_max (8 m): clears to raytrace_range (3.0 m), marks nothing (beyond 2.5 m).
  EXPECT_EQ(afterANoReturnBeam(true, 8.0), std::make_tuple(int(cost::FREE), int(cost::LETHAL), 1));
  // An infinite range_max: the same.
  EXPECT_EQ(afterANoReturnBeam(true, kInf), std::make_tuple(int(cost::FREE), int(cost::LETHAL), 1));
  // As in costmap_2d, a range_max within obstacle_range is a hit there: 1.5 m along +x is marked.
  EXPECT_EQ(std::get<2>(afterANoReturnBeam(true, 1.5)), 3);
}

TEST(ObstacleLayerInf, MarkingAndClearingCanBeSwitchedOff)
{
  for (const bool marking : {true, false})
    for (const bool clearing : {true, false})
    {
      LayeredCostmap costmap(staticConfig(6.0, 6.0, 0.0));
      ObstacleLayerConfig oc;
      oc.marking = marking;
      oc.clearing = clearing;
      auto& layer = static_cast<ObstacleLayer&>(costmap.addLayer(std::make_unique<ObstacleLayer>(oc)));
      ScanObservation first, second;  // a hit at 1 m, then a beam through it to 2 m
      first.origin_x = second.origin_x = 1.025;
      first.origin_y = second.origin_y = 1.025;
      first.addEndpoint(2.025, 1.025);
      second.addEndpoint(3.025, 1.025);
      layer.addObservation(first);
      costmap.updateMap(Pose2D{0.5, 0.5, 0.0});
      EXPECT_EQ(costAt(costmap.costmap(), 2.025, 1.025), marking ? cost::LETHAL : cost::FREE);
      layer.addObservation(second);
      costmap.updateMap(Pose2D{0.5, 0.5, 0.0});
      EXPECT_EQ(costAt(costmap.costmap(), 2.025, 1.025), marking && !clearing ? cost::LETHAL : cost::FREE)
          << marking << clearing;
      EXPECT_EQ(costAt(costmap.costmap(), 3.025, 1.025), marking ? cost::LETHAL : cost::FREE);
    }
}

TEST_F(ObstacleLayerTest, ObstacleRangeAndInvalidRanges)
{
  ScanObservation s;
  s.origin_x = 0.525;
  s.origin_y = 0.525;
  s.beams.push_back({0.0, 2.4});                // marked (<= obstacle_range 2.5)
  s.beams.push_back({M_PI / 2, 2.7});           // not marked (> 2.5), but clears
  s.beams.push_back({M_PI / 4, std::nan("")});  // ignored
  s.beams.push_back({M_PI / 4, -kInf});         // ignored (REP-117: too close)
  scan(s);
  EXPECT_EQ(at(0.525 + 2.4, 0.525), cost::LETHAL);
  EXPECT_EQ(at(0.525, 0.525 + 2.7), cost::FREE);
  int lethal = 0;
  for (unsigned i = 0; i < 120 * 120; ++i) lethal += costmap->costmap().data()[i] == cost::LETHAL;
  EXPECT_EQ(lethal, 1);
}

/// A wall of 41 cells (x = 2.525 m, y from 1.025 to 3.025 m) scanned 50 times from (0.525, 2.025)
/// by one beam per wall cell, each beam dropping out with probability 0.3 and then reading
/// `dropped` instead of its range. @return how many wall cells are LETHAL after the last scan.
int wallCellsLeftUnderDropout(double dropped, bool inf_is_valid = false)
{
  LayeredCostmap costmap(staticConfig(6.0, 6.0, 0.0));
  ObstacleLayerConfig oc;
  oc.inf_is_valid = inf_is_valid;
  auto& layer = static_cast<ObstacleLayer&>(costmap.addLayer(std::make_unique<ObstacleLayer>(oc)));
  const Pose2D robot{0.525, 2.025, 0.0};
  costmap.updateMap(robot);
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  for (int k = 0; k < 50; ++k)
  {
    ScanObservation s;
    s.origin_x = robot.x;
    s.origin_y = robot.y;
    s.range_max = 8.0;
    for (int j = 0; j <= 40; ++j)
    {
      s.addEndpoint(2.525, 1.025 + 0.05 * j);
      if (uniform(rng) < 0.3) s.beams.back().range = dropped;
    }
    layer.addObservation(s);
    costmap.updateMap(robot);
  }
  int lethal = 0;
  for (int j = 0; j <= 40; ++j) lethal += costAt(costmap.costmap(), 2.525, 1.025 + 0.05 * j) == cost::LETHAL;
  return lethal;
}

TEST(ObstacleLayerDropout, NaNBeamsNeitherMarkNorClearSoAnObstacleStays)
{
  // REP-117: a dropped beam (NaN, "invalid") says nothing; the wall stays whole.
  EXPECT_EQ(wallCellsLeftUnderDropout(std::nan("")), 41);
  // +Inf ("nothing in range") is ignored too unless inf_is_valid is set, as in costmap_2d.
  EXPECT_EQ(wallCellsLeftUnderDropout(kInf), 41);
  // With inf_is_valid it clears the cells it passes, so the last scan's dropped beams erase
  // about 30 % of the wall (the reason dropouts must not be +Inf).
  const int left_with_inf = wallCellsLeftUnderDropout(kInf, true);
  EXPECT_LT(left_with_inf, 38);
  EXPECT_GT(left_with_inf, 20);
}

TEST(LayeredCostmap, MaximumCombinationAndUnknownRevealedByClearing)
{
  // Static map: a lethal cell at (10, 10) and unknown cells in row 20; tracking unknown space.
  const unsigned W = 40, H = 40;
  std::vector<int8_t> data(W * H, 0);
  data[10 * W + 10] = 100;
  for (unsigned x = 0; x < W; ++x) data[20 * W + x] = -1;
  LayeredCostmapConfig cc = staticConfig(2.0, 2.0, 0.0);
  cc.track_unknown_space = true;
  LayeredCostmap costmap(cc);
  StaticLayerConfig sc;
  sc.track_unknown_space = true;
  auto& stat = static_cast<StaticLayer&>(costmap.addLayer(std::make_unique<StaticLayer>(sc)));
  ObstacleLayerConfig oc;
  oc.track_unknown_space = true;
  auto& obs = static_cast<ObstacleLayer&>(costmap.addLayer(std::make_unique<ObstacleLayer>(oc)));
  stat.setMap(W, H, 0.05, 0.0, 0.0, data.data());
  costmap.updateMap(Pose2D{});
  EXPECT_EQ(costmap.costmap().cost(5, 20), cost::NO_INFORMATION);

  // A beam up column 5 through the unknown row 20, and one along row 10 through the static obstacle.
  ScanObservation s;
  s.origin_x = 0.275;
  s.origin_y = 0.025;
  s.addEndpoint(0.275, 1.525);
  ScanObservation s2;
  s2.origin_x = 0.025;
  s2.origin_y = 0.525;
  s2.addEndpoint(1.525, 0.525);
  obs.addObservation(s);
  obs.addObservation(s2);
  costmap.updateMap(Pose2D{});
  EXPECT_EQ(costmap.costmap().cost(10, 10), cost::LETHAL);  // clearing never lowers the static cost
  EXPECT_EQ(costmap.costmap().cost(5, 20), cost::FREE);     // unknown, now seen free
  EXPECT_EQ(costmap.costmap().cost(6, 20), cost::NO_INFORMATION);
}

TEST(LayeredCostmap, IncrementalUpdatesEqualAFullRecompute)
{
  // Scans change small windows; after every few updates the master must equal the static and
  // obstacle grids combined by maximum and then inflated as a whole.
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  const unsigned W = 120, H = 100;
  std::vector<int8_t> map(W * H, 0);
  for (auto& v : map) v = (rng() % 40 == 0) ? 100 : 0;
  LayeredCostmap costmap(staticConfig(1.0, 1.0, 0.17));
  auto& stat = static_cast<StaticLayer&>(costmap.addLayer(std::make_unique<StaticLayer>()));
  auto& obs = static_cast<ObstacleLayer&>(costmap.addLayer(std::make_unique<ObstacleLayer>()));
  costmap.addLayer(std::make_unique<InflationLayer>());
  stat.setMap(W, H, 0.05, -1.0, -1.0, map.data());
  Pose2D robot{2.0, 1.5, 0.0};
  int checks = 0, differing = 0;
  for (int it = 0; it < 60; ++it)
  {
    robot.x = std::max(-0.5, std::min(4.5, robot.x + 0.3 * u(rng)));
    robot.y = std::max(-0.5, std::min(3.5, robot.y + 0.3 * u(rng)));
    ScanObservation s;
    s.origin_x = robot.x;
    s.origin_y = robot.y;
    for (int b = 0; b < 40; ++b)
      s.beams.push_back({0.16 * b + u(rng), rng() % 8 == 0 ? kInf : 2.8 * std::fabs(u(rng))});
    obs.addObservation(s);
    costmap.updateMap(robot);
    ASSERT_FALSE(costmap.lastWindow().empty());
    if (it % 10 != 9) continue;
    Costmap2D expected(W, H, 0.05, -1.0, -1.0);
    for (unsigned i = 0; i < W * H; ++i)
    {
      updateWithMax(expected.data()[i], stat.grid().data()[i]);
      updateWithMax(expected.data()[i], obs.grid().data()[i]);
    }
    InflationLayer inflation;
    inflation.onFootprintChanged(0.17);
    inflation.inflate(expected);
    for (unsigned i = 0; i < W * H; ++i) differing += expected.data()[i] != costmap.costmap().data()[i];
    ++checks;
  }
  EXPECT_EQ(checks, 6);
  EXPECT_EQ(differing, 0);
  // A short beam only rewrites a small window: beam + robot footprint + inflation radius.
  ScanObservation s;
  s.origin_x = 2.025;
  s.origin_y = 1.525;
  s.addEndpoint(2.325, 1.525);
  obs.addObservation(s);
  costmap.updateMap(Pose2D{2.025, 1.525, 0.0});
  const CellWindow& w = costmap.lastWindow();
  // x: from the footprint's left edge (2.025 - 0.17) to the hit (2.325), y: the footprint
  // (1.525 +- 0.17), each grown by the 0.55 m inflation radius: 1.57 m and 1.44 m.
  EXPECT_EQ(w.xn - w.x0, 32);  // cells 46..77
  EXPECT_EQ(w.yn - w.y0, 29);  // cells 36..64
}

// ---------------------------------------------------------------- robots layer

TEST(RobotsLayer, MarksFootprintAndPredictedMotionAndForgetsOldPoses)
{
  LayeredCostmap costmap(staticConfig(5.0, 5.0, 0.1));
  RobotsLayerConfig rc;
  rc.prediction_time = 1.0;
  rc.prediction_cost = 200;
  auto& robots = static_cast<RobotsLayer&>(costmap.addLayer(std::make_unique<RobotsLayer>(rc)));
  TeammateState mate;
  mate.name = "robot_1";
  mate.pose = Pose2D{2.0, 2.0, 0.0};
  mate.radius = 0.2;
  mate.vx = 0.5;  // heading +x at 0.5 m/s: at (2.5, 2.0) in 1 s
  robots.setTeammates({mate});
  costmap.updateMap(Pose2D{});
  const Costmap2D& m = costmap.costmap();

  // Queries at cell centres (x.x25), so that no point sits on a cell boundary.
  EXPECT_EQ(costAt(m, 2.025, 2.025), cost::LETHAL);
  EXPECT_EQ(costAt(m, 2.175, 2.025), cost::LETHAL);     // 0.18 m: inside the 0.2 m footprint
  EXPECT_EQ(costAt(m, 2.525, 2.025), 200);              // where it will be in 1 s
  EXPECT_EQ(costAt(m, 2.775, 2.025), 200);              // 0.28 m beyond: radius 0.2 + our 0.1 m
  EXPECT_EQ(costAt(m, 2.875, 2.025), cost::FREE);       // 0.38 m beyond: outside the sweep
  EXPECT_EQ(costAt(m, 1.675, 2.025), cost::FREE);       // behind it: 0.33 m > 0.2 m footprint
  EXPECT_LT(costAt(m, 2.525, 2.025), cost::INSCRIBED);  // passable

  // It moved away: the old cells are free again.
  mate.pose = Pose2D{4.0, 4.0, M_PI / 2};
  robots.setTeammates({mate});
  costmap.updateMap(Pose2D{});
  EXPECT_EQ(costAt(m, 2.025, 2.025), cost::FREE);
  EXPECT_EQ(costAt(m, 2.525, 2.025), cost::FREE);
  EXPECT_EQ(costAt(m, 4.025, 4.025), cost::LETHAL);
  EXPECT_EQ(costAt(m, 4.025, 4.525), 200);  // heading +y now
}

TEST(RobotsLayer, TeammateIsInflatedByTheInflationLayer)
{
  LayeredCostmap costmap(staticConfig(4.0, 4.0, 0.15));
  auto& robots = static_cast<RobotsLayer&>(costmap.addLayer(std::make_unique<RobotsLayer>()));
  costmap.addLayer(std::make_unique<InflationLayer>());
  TeammateState mate;
  mate.pose = Pose2D{2.025, 2.025, 0.0};
  mate.radius = 0.11;
  robots.setTeammates({mate});
  costmap.updateMap(Pose2D{});
  // Footprint: the cell centred 0.10 m away is lethal, the one 0.15 m away is not; inflation
  // makes the cell 2 cells (0.10 m <= inscribed 0.15 m) beyond the footprint edge INSCRIBED.
  EXPECT_EQ(costAt(costmap.costmap(), 2.13, 2.03), cost::LETHAL);
  EXPECT_EQ(costAt(costmap.costmap(), 2.23, 2.03), cost::INSCRIBED);
  EXPECT_EQ(costAt(costmap.costmap(), 2.48, 2.03), 34);  // 7 cells = 0.35 m: 252 * exp(-2) = 34.1
}

// ---------------------------------------------------------------- rolling window

TEST(Costmap2D, UpdateOriginKeepsOverlap)
{
  Costmap2D m(10, 8, 0.5, 0.0, 0.0, 7);
  m.setCost(6, 5, 200);
  m.updateOrigin(1.0, 0.5, 9);  // 2 cells right, 1 cell up
  EXPECT_DOUBLE_EQ(m.originX(), 1.0);
  EXPECT_DOUBLE_EQ(m.originY(), 0.5);
  EXPECT_EQ(m.cost(4, 4), 200);  // same world cell
  EXPECT_EQ(m.cost(0, 0), 7);    // kept
  EXPECT_EQ(m.cost(9, 0), 9);    // entered
  EXPECT_EQ(m.cost(0, 7), 9);    // entered
}

TEST(LayeredCostmap, RollingWindowKeepsDataWhenRecentering)
{
  LayeredCostmapConfig cc;
  cc.rolling_window = true;
  cc.width = 4.0;
  cc.height = 4.0;
  cc.resolution = 0.05;
  cc.robot_radius = 0.1;
  LayeredCostmap costmap(cc);
  auto& obs = static_cast<ObstacleLayer&>(costmap.addLayer(std::make_unique<ObstacleLayer>()));
  costmap.addLayer(std::make_unique<InflationLayer>());
  Pose2D robot{0.0, 0.0, 0.0};
  costmap.updateMap(robot);
  EXPECT_NEAR(costmap.costmap().originX(), -2.0, 1e-9);

  ScanObservation s;
  s.origin_x = 0.0;
  s.origin_y = 0.0;
  // Points inside cells (not on boundaries), so that the cell they fall in is unambiguous.
  s.addEndpoint(1.01, 0.51);
  s.addEndpoint(-1.49, -1.49);
  obs.addObservation(s);
  costmap.updateMap(robot);
  ASSERT_EQ(costAt(costmap.costmap(), 1.01, 0.51), cost::LETHAL);
  ASSERT_EQ(costAt(costmap.costmap(), -1.49, -1.49), cost::LETHAL);
  const int inflated_before = costAt(costmap.costmap(), 1.21, 0.51);
  EXPECT_EQ(inflated_before, 92);  // 4 cells = 0.2 m, inscribed 0.1 m: 252 * exp(-10 * 0.1) = 92.7

  // Move 0.8 m right and 0.3 m up, with no new scan: the window recentres.
  robot = Pose2D{0.8, 0.3, 0.0};
  costmap.updateMap(robot);
  EXPECT_NEAR(costmap.costmap().originX(), -1.2, 1e-9);
  EXPECT_NEAR(costmap.costmap().originY(), -1.7, 1e-9);
  EXPECT_EQ(costAt(costmap.costmap(), 1.01, 0.51), cost::LETHAL);     // kept at its world position
  EXPECT_EQ(costAt(costmap.costmap(), 1.21, 0.51), inflated_before);  // and its inflation
  EXPECT_EQ(costAt(costmap.costmap(), -1.49, -1.49), -1);             // left the window
  EXPECT_EQ(costAt(costmap.costmap(), 2.71, 2.21), cost::FREE);       // entered: default
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
