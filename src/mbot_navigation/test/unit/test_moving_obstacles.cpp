// The moving obstacles layer (no ROS master): a laser scan of a walking disc, simulated here,
// gets a predicted sweep ahead of the disc, not passable over its first blocked_time unless our
// robot is caught well inside it; a disc standing still, a teammate, the map's walls and a track
// that vanished get none; a bad setting is an error naming its key.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <random>
#include <string>
#include <utility>
#include <vector>

#include "mbot_navigation/costmap/layered_costmap.h"
#include "mbot_navigation/costmap/moving_obstacles_layer.h"
#include "mbot_navigation/costmap/robots_layer.h"

using namespace mbot_navigation;

namespace
{
const double kInf = std::numeric_limits<double>::infinity();

struct Disc
{
  double x, y, r;
};

/// A 360-beam scan from (ox, oy) at time t [s] of the discs and, when wall_y is finite, of a wall
/// along y = wall_y: each beam ends at the nearest surface, or +Inf beyond 8 m.
ScanObservation laser(double ox, double oy, double t, const std::vector<Disc>& discs, double wall_y = kInf)
{
  ScanObservation s;
  s.origin_x = ox;
  s.origin_y = oy;
  s.range_min = 0.12;
  s.range_max = 8.0;
  s.stamp = t;
  for (int i = 0; i < 360; ++i)
  {
    const double a = -M_PI + i * M_PI / 180.0, dx = std::cos(a), dy = std::sin(a);
    double best = kInf;
    for (const Disc& d : discs)
    {
      const double b = dx * (d.x - ox) + dy * (d.y - oy);
      const double c = (d.x - ox) * (d.x - ox) + (d.y - oy) * (d.y - oy) - d.r * d.r;
      if (b * b - c < 0.0) continue;
      const double range = b - std::sqrt(b * b - c);
      if (range > 0.0) best = std::min(best, range);
    }
    if (std::isfinite(wall_y) && std::abs(dy) > 1e-9 && (wall_y - oy) / dy > 0.0)
      best = std::min(best, (wall_y - oy) / dy);
    s.beams.push_back({a, best <= s.range_max ? best : kInf});
  }
  return s;
}

/// A wall segment from (x0, y0) to (x1, y1) [m].
struct Segment
{
  double x0, y0, x1, y1;
};

/// A 360-beam scan of wall segments and discs, taken at the true pose (x, y, yaw) but placed, as
/// the nav node places it, at the localization's estimate: the true position plus (ex, ey), the
/// beams turned by eyaw.
ScanObservation laserAt(double x, double y, double t, const std::vector<Segment>& walls, const std::vector<Disc>& discs,
                        double ex, double ey, double eyaw)
{
  const ScanObservation of_discs = laser(x, y, t, discs);  // its beams start at -pi, as below
  ScanObservation s;
  s.origin_x = x + ex;
  s.origin_y = y + ey;
  s.range_min = 0.12;
  s.range_max = 8.0;
  s.stamp = t;
  for (int i = 0; i < 360; ++i)
  {
    const double a = -M_PI + i * M_PI / 180.0, dx = std::cos(a), dy = std::sin(a);
    double best = of_discs.beams[i].range;
    for (const Segment& w : walls)
    {
      // Ray (x, y) + r (dx, dy) against the segment, by Cramer's rule.
      const double sx = w.x1 - w.x0, sy = w.y1 - w.y0;
      const double den = dx * sy - dy * sx;
      if (std::abs(den) < 1e-12) continue;
      const double r = ((w.x0 - x) * sy - (w.y0 - y) * sx) / den;
      const double u = ((w.x0 - x) * dy - (w.y0 - y) * dx) / den;
      if (r > 0.0 && u >= 0.0 && u <= 1.0) best = std::min(best, r);
    }
    s.beams.push_back({a + eyaw, best <= s.range_max ? best : kInf});
  }
  return s;
}

/// Cost of the master cell holding (x, y) [m].
int costAt(const Costmap2D& m, double x, double y)
{
  unsigned mx, my;
  if (!m.worldToMap(x, y, mx, my)) return -1;
  return m.cost(mx, my);
}

/// A 6 x 6 m costmap (robot radius 0.15 m) with only the moving obstacles layer.
struct Fixture
{
  explicit Fixture(const MovingObstaclesConfig& config = defaults())
  {
    LayeredCostmapConfig c;
    c.width = c.height = 6.0;
    c.resolution = 0.05;
    c.robot_radius = 0.15;
    costmap = std::make_unique<LayeredCostmap>(c);
    layer = &static_cast<MovingObstaclesLayer&>(costmap->addLayer(std::make_unique<MovingObstaclesLayer>(config)));
  }
  static MovingObstaclesConfig defaults()
  {
    MovingObstaclesConfig c;
    c.prediction_time = 2.0;  // 0.5 s of passable sweep after the blocked part, as nav_costmaps.yaml
    c.blocked_time = 1.5;
    return c;
  }
  void scan(const ScanObservation& s)
  {
    layer->addObservation(s);
    costmap->updateMap(Pose2D{s.origin_x, s.origin_y, 0.0});
  }
  int at(double x, double y) const { return costAt(costmap->costmap(), x, y); }
  int predictedTracks() const
  {
    int n = 0;
    for (const MovingTrack& k : layer->tracks()) n += layer->predicted(k);
    return n;
  }
  int nonFreeCells() const
  {
    const Costmap2D& m = costmap->costmap();
    int n = 0;
    for (unsigned i = 0; i < m.sizeX() * m.sizeY(); ++i) n += m.data()[i] != cost::FREE;
    return n;
  }
  std::unique_ptr<LayeredCostmap> costmap;
  MovingObstaclesLayer* layer = nullptr;
};

/// A person (radius 0.25 m) from (3.0, 1.5) at (vx, vy) [m/s], seen from (1.0, 2.0) every 0.1 s
/// for `seconds`; returns where the person is at the last scan.
std::pair<double, double> walk(Fixture& f, double vx, double vy, double seconds = 1.0)
{
  double x = 3.0, y = 1.5;
  for (int k = 0; k <= static_cast<int>(std::lround(seconds / 0.1)); ++k)
  {
    const double t = 10.0 + 0.1 * k;
    x = 3.0 + vx * 0.1 * k;
    y = 1.5 + vy * 0.1 * k;
    f.scan(laser(1.0, 2.0, t, {{x, y, 0.25}}));
  }
  return {x, y};
}
}  // namespace

TEST(MovingObstaclesLayer, WalkingPersonGetsASweepAheadInItsDirectionOfMotion)
{
  Fixture f;
  const auto [x, y] = walk(f, 0.0, 0.6);  // walking +y at 0.6 m/s
  ASSERT_EQ(f.layer->tracks().size(), 1u);
  const MovingTrack& k = f.layer->tracks()[0];
  ASSERT_TRUE(f.layer->predicted(k));
  // The laser sees the near side, whose centre shifts a little as the bearing turns.
  EXPECT_NEAR(k.vx, 0.0, 0.1);
  EXPECT_NEAR(k.vy, 0.6, 0.1);
  // Ahead: the person covers 1.2 m in prediction_time 2 s; past blocked_time (0.9 m) the sweep
  // costs 200 (passable).
  EXPECT_EQ(f.at(x + 0.025, y + 1.2), 200);
  EXPECT_EQ(f.at(x + 0.025, y + 1.2 + 0.25 + 0.15 + 0.15), cost::FREE);  // past sweep + radii
  // Behind and beside it: nothing (this layer draws only the prediction).
  EXPECT_EQ(f.at(x + 0.025, y - 0.6), cost::FREE);
  EXPECT_EQ(f.at(x + 0.8, y + 0.6), cost::FREE);
  EXPECT_EQ(f.at(x - 0.8, y + 0.6), cost::FREE);

  // The other way round, the sweep is on the other side.
  Fixture g;
  const auto [x2, y2] = walk(g, -0.5, 0.0);
  const MovingTrack& k2 = g.layer->tracks()[0];
  EXPECT_EQ(g.at(k2.x - 1.2, k2.y), 200);  // 1.0 m in 2 s, past the blocked 0.75 m and the body
  EXPECT_EQ(g.at(x2 + 0.8, y2), cost::FREE);
}

TEST(MovingObstaclesLayer, WhereThePersonWalksWithinBlockedTimeIsNotPassable)
{
  // A blind walker crossing our path: what it reaches within blocked_time is its body, LETHAL
  // (the planners may not cut in front); only the later part of the sweep is passable.
  Fixture f;
  walk(f, 0.0, 0.6);
  ASSERT_EQ(f.predictedTracks(), 1);
  const MovingTrack k = f.layer->tracks()[0];
  EXPECT_EQ(f.at(k.x, k.y + 0.3), cost::LETHAL);  // 0.5 s ahead
  EXPECT_EQ(f.at(k.x, k.y + 0.6), cost::LETHAL);  // 1 s
  EXPECT_EQ(f.at(k.x, k.y + 0.9), cost::LETHAL);  // 1.5 s: the last blocked pose
  EXPECT_EQ(f.at(k.x, k.y + 0.9 + k.radius + 0.1), 200);
  EXPECT_EQ(f.at(k.x, k.y + 1.2), 200);  // 2 s
  // The body, not the sweep grown by our radius, is LETHAL (the inflation layer adds our radius).
  EXPECT_EQ(f.at(k.x + k.radius + 0.1, k.y + 0.6), 200);

  // blocked_time 0: the whole sweep passable, as teammates' sweeps are.
  MovingObstaclesConfig passable = Fixture::defaults();
  passable.blocked_time = 0.0;
  Fixture g(passable);
  walk(g, 0.0, 0.6);
  const MovingTrack& k2 = g.layer->tracks()[0];
  EXPECT_EQ(g.at(k2.x, k2.y + 0.6), 200);
}

TEST(MovingObstaclesLayer, RobotCaughtInsideTheBlockedPartGetsOnlyThePassableSweep)
{
  Fixture f;
  walk(f, 0.0, 0.6);
  const MovingTrack k = f.layer->tracks()[0];
  ASSERT_EQ(f.at(k.x, k.y + 0.6), cost::LETHAL);
  // Our robot 0.6 m ahead, on the person's path (the person walks at it): a LETHAL body there
  // would leave it no trajectory at all; the sweep stays, passable.
  f.costmap->updateMap(Pose2D{k.x, k.y + 0.6, 0.0});
  EXPECT_EQ(f.at(k.x, k.y + 0.3), 200);
  EXPECT_EQ(f.at(k.x, k.y + 0.6), 200);
  // Waiting beside the path, where DWA stops it (the body's radius plus its own away): blocked.
  f.costmap->updateMap(Pose2D{k.x + k.radius + 0.15, k.y + 0.6, 0.0});
  EXPECT_EQ(f.at(k.x, k.y + 0.6), cost::LETHAL);
}

TEST(MovingObstaclesLayer, PersonStandingStillGetsNoSweep)
{
  Fixture f;
  walk(f, 0.0, 0.0, 2.0);
  ASSERT_EQ(f.layer->tracks().size(), 1u);  // seen and tracked...
  EXPECT_EQ(f.predictedTracks(), 0);        // ...but not moving
  EXPECT_EQ(f.nonFreeCells(), 0);

  // Nor when the robot drives past it at 0.4 m/s (the laser sees another side of it).
  Fixture g;
  for (int k = 0; k <= 20; ++k) g.scan(laser(1.0, 1.0 + 0.04 * k, 10.0 + 0.1 * k, {{3.0, 1.5, 0.25}}));
  EXPECT_EQ(g.predictedTracks(), 0);
  EXPECT_EQ(g.nonFreeCells(), 0);
}

TEST(MovingObstaclesLayer, TeammateIsNotTracked)
{
  // A teammate walks like the person; its hits are taken out as the nav node does.
  Fixture f, unfiltered;
  TeammateState mate;
  mate.radius = 0.25;
  for (int k = 0; k <= 10; ++k)
  {
    mate.pose = Pose2D{3.0, 1.5 + 0.06 * k, M_PI / 2};
    const ScanObservation s = laser(1.0, 2.0, 10.0 + 0.1 * k, {{mate.pose.x, mate.pose.y, mate.radius}});
    f.scan(withoutTeammateHits(s, {mate}, 0.15));
    unfiltered.scan(s);
  }
  EXPECT_TRUE(f.layer->tracks().empty());
  EXPECT_EQ(f.nonFreeCells(), 0);
  EXPECT_EQ(unfiltered.predictedTracks(), 1);  // the same scans, not filtered: a sweep
}

TEST(MovingObstaclesLayer, TrackThatVanishesIsDropped)
{
  Fixture f;
  const auto [x, y] = walk(f, 0.0, 0.6);
  ASSERT_EQ(f.at(x + 0.025, y + 1.2), 200);
  // Nobody there any more (walked out of sight): after track_timeout (0.5 s) the track and its
  // sweep are gone.
  double t = 11.0;
  for (int k = 1; k <= 3; ++k) f.scan(laser(1.0, 2.0, t + 0.1 * k, {}));
  EXPECT_EQ(f.layer->tracks().size(), 1u);  // missed 0.3 s: still kept
  for (int k = 4; k <= 7; ++k) f.scan(laser(1.0, 2.0, t + 0.1 * k, {}));
  EXPECT_TRUE(f.layer->tracks().empty());
  EXPECT_EQ(f.nonFreeCells(), 0);

  // reset() (clear_costmaps) forgets the tracks too.
  walk(f, 0.0, 0.6);
  ASSERT_EQ(f.predictedTracks(), 1);
  f.costmap->reset();
  EXPECT_TRUE(f.layer->tracks().empty());
}

TEST(MovingObstaclesLayer, WallsOfTheMapAreNotTrackedButAPersonBesideThemIs)
{
  // The static map: a wall row of cells at y = 3.0 m, longer than the laser's 8 m reach.
  Costmap2D map(400, 400, 0.05, -9.0, -7.0);
  for (unsigned mx = 0; mx < 400; ++mx) map.setCost(mx, 200, cost::LETHAL);
  Fixture f;
  f.layer->setStaticMap(&map);
  // The robot drives along the wall; the laser sees the wall's lower face (y = 3.0).
  for (int k = 0; k <= 20; ++k) f.scan(laser(1.0 + 0.04 * k, 2.0, 10.0 + 0.1 * k, {}, 3.0));
  EXPECT_TRUE(f.layer->tracks().empty());
  // A person walking along the wall 0.4 m from it is tracked and predicted.
  for (int k = 0; k <= 10; ++k) f.scan(laser(1.0, 2.0, 13.0 + 0.1 * k, {{2.0 + 0.06 * k, 2.6 - 0.25, 0.25}}, 3.0));
  EXPECT_EQ(f.predictedTracks(), 1);
  // Without the map, the wall's hits are one cluster, too wide to be tracked (also its piece within
  // obstacle_range, whose end would move with the robot).
  Fixture g;
  for (int k = 0; k <= 20; ++k) g.scan(laser(1.0 + 0.04 * k, 2.0, 10.0 + 0.1 * k, {}, 3.0));
  EXPECT_EQ(g.predictedTracks(), 0);
}

TEST(MovingObstaclesLayer, MappedWallsSeenFromAJitteringPoseAreNotTrackedButAPersonIs)
{
  // The particle filter's pose is off by a few centimetres and jumps at each of its updates; the
  // walls placed from it land beside the map's, most at the far end of a beam (yaw error times
  // range). Office-like: a corridor wall along y = 3.0 m with a 1.2 m door (its frame ends at
  // x = 2.0 and 3.2 m, a wall going north from each), a wall along y = 0 and a room's corner.
  const std::vector<Segment> walls = {{-6.0, 3.0, 2.0, 3.0}, {3.2, 3.0, 10.0, 3.0}, {2.0, 3.0, 2.0, 6.0},
                                      {3.2, 3.0, 3.2, 6.0},  {5.0, 3.0, 5.0, 0.5},  {5.0, 0.5, 8.0, 0.5},
                                      {-6.0, 0.0, 4.0, 0.0}};
  Costmap2D map(400, 400, 0.05, -9.0, -7.0);
  for (const Segment& w : walls)
    for (double f = 0.0; f <= 1.0; f += 0.001)
    {
      unsigned mx, my;
      if (map.worldToMap(w.x0 + f * (w.x1 - w.x0), w.y0 + f * (w.y1 - w.y0), mx, my)) map.setCost(mx, my, cost::LETHAL);
    }
  Fixture f;
  f.layer->setStaticMap(&map);
  // The estimate's error is new every 0.5 s (a filter update), up to 0.05 m and 0.05 rad each way
  // (nav_office_pf.test, 16 runs: position error p95 0.034-0.056 m, heading p95 at most 0.009 rad).
  // With 0.15 m and 0.1 rad this layer does draw false sweeps: static_margin is what holds it.
  std::mt19937 random(7);
  std::uniform_real_distribution<double> offset(-0.05, 0.05), turn(-0.05, 0.05);
  double ex = 0.0, ey = 0.0, eyaw = 0.0;
  auto lethalCells = [&f]() {
    const Costmap2D& m = f.costmap->costmap();
    int n = 0;
    for (unsigned i = 0; i < m.sizeX() * m.sizeY(); ++i) n += m.data()[i] == cost::LETHAL;
    return n;
  };
  // The robot drives east along y = 1.5 m at 0.4 m/s past the door, 10 scans a second for 15 s.
  int predicted = 0, lethal = 0;
  for (int k = 0; k <= 150; ++k)
  {
    if (k % 5 == 0)
    {
      ex = offset(random);
      ey = offset(random);
      eyaw = turn(random);
    }
    f.scan(laserAt(-2.0 + 0.04 * k, 1.5, 10.0 + 0.1 * k, walls, {}, ex, ey, eyaw));
    predicted += f.predictedTracks();
    lethal += lethalCells();
  }
  EXPECT_EQ(predicted, 0);
  EXPECT_EQ(lethal, 0);

  // Standing at (1.0, 1.5) with the same jitter, it sees a person walk west along the corridor at
  // 0.6 m/s, 0.45 m from the wall (0.7 m from the door frame): a sweep, LETHAL in front.
  for (int k = 0; k <= 20; ++k)
  {
    if (k % 5 == 0)
    {
      ex = offset(random);
      ey = offset(random);
      eyaw = turn(random);
    }
    f.scan(laserAt(1.0, 1.5, 30.0 + 0.1 * k, walls, {{3.5 - 0.06 * k, 2.3, 0.25}}, ex, ey, eyaw));
  }
  ASSERT_EQ(f.predictedTracks(), 1);
  const MovingTrack& k = f.layer->tracks()[0];
  EXPECT_NEAR(k.vx, -0.6, 0.2);
  EXPECT_NEAR(k.vy, 0.0, 0.2);
  EXPECT_GT(lethalCells(), 0);
}

TEST(MovingObstaclesLayer, BadSettingIsAnErrorNamingTheKey)
{
  const std::vector<std::pair<std::string, std::function<void(MovingObstaclesConfig&)>>> bad = {
      {"prediction_time", [](MovingObstaclesConfig& c) { c.prediction_time = -1.0; }},
      {"prediction_step", [](MovingObstaclesConfig& c) { c.prediction_step = 0.0; }},
      {"prediction_cost", [](MovingObstaclesConfig& c) { c.prediction_cost = cost::LETHAL; }},
      {"obstacle_range", [](MovingObstaclesConfig& c) { c.obstacle_range = 0.0; }},
      {"static_margin", [](MovingObstaclesConfig& c) { c.static_margin = -0.1; }},
      {"cluster_distance", [](MovingObstaclesConfig& c) { c.cluster_distance = 0.0; }},
      {"max_size", [](MovingObstaclesConfig& c) { c.max_size = std::nan(""); }},
      {"association_gate", [](MovingObstaclesConfig& c) { c.association_gate = -0.5; }},
      {"velocity_window", [](MovingObstaclesConfig& c) { c.velocity_window = 0.0; }},
      {"min_track_age", [](MovingObstaclesConfig& c) { c.min_track_age = -0.3; }},
      {"track_timeout", [](MovingObstaclesConfig& c) { c.track_timeout = 0.0; }},
      {"min_speed", [](MovingObstaclesConfig& c) { c.min_speed = -0.1; }},
      {"max_speed", [](MovingObstaclesConfig& c) { c.max_speed = 0.1; }},  // below min_speed 0.15
      {"blocked_time", [](MovingObstaclesConfig& c) { c.blocked_time = -1.0; }},
  };
  EXPECT_NO_THROW(MovingObstaclesLayer{MovingObstaclesConfig()});
  for (const auto& [key, spoil] : bad)
  {
    MovingObstaclesConfig c;
    spoil(c);
    try
    {
      MovingObstaclesLayer layer(c);
      ADD_FAILURE() << key << ": accepted";
    }
    catch (const std::invalid_argument& e)
    {
      EXPECT_NE(std::string(e.what()).find("'" + key + "'"), std::string::npos) << key << ": " << e.what();
    }
  }
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
