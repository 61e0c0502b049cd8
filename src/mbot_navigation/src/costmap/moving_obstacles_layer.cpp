#include "mbot_navigation/costmap/moving_obstacles_layer.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <stdexcept>

namespace mbot_navigation
{
namespace
{
constexpr const char* kWho = "MovingObstaclesConfig";
// A single hit is as likely noise as an obstacle; a person at 2.5 m gets about eight.
constexpr size_t kMinHits = 2;
// The laser sees one side of a body: a cluster is drawn at least this wide (half of it) [m].
constexpr double kMinRadius = 0.1;

void requirePositive(double value, const char* key)
{
  if (!(value > 0.0)) throw std::invalid_argument(std::string(kWho) + ": '" + key + "' must be > 0");
}
}  // namespace

void checkMovingObstaclesConfig(const MovingObstaclesConfig& c)
{
  checkSweepPrediction(c, kWho);
  requirePositive(c.obstacle_range, "obstacle_range");
  if (!(c.static_margin >= 0.0)) throw std::invalid_argument(std::string(kWho) + ": 'static_margin' must be >= 0 [m]");
  requirePositive(c.cluster_distance, "cluster_distance");
  requirePositive(c.max_size, "max_size");
  requirePositive(c.association_gate, "association_gate");
  requirePositive(c.velocity_window, "velocity_window");
  if (!(c.min_track_age >= 0.0)) throw std::invalid_argument(std::string(kWho) + ": 'min_track_age' must be >= 0 [s]");
  requirePositive(c.track_timeout, "track_timeout");
  if (!(c.min_speed >= 0.0)) throw std::invalid_argument(std::string(kWho) + ": 'min_speed' must be >= 0 [m/s]");
  if (!(c.max_speed > c.min_speed))
    throw std::invalid_argument(std::string(kWho) + ": 'max_speed' must be > 'min_speed' [m/s]");
  if (!(c.blocked_time >= 0.0)) throw std::invalid_argument(std::string(kWho) + ": 'blocked_time' must be >= 0 [s]");
}

MovingObstaclesLayer::MovingObstaclesLayer(const MovingObstaclesConfig& config) : config_(config)
{
  checkMovingObstaclesConfig(config);
}

void MovingObstaclesLayer::reset()
{
  pending_.clear();
  tracks_.clear();
  latest_stamp_ = -1.0;
}

bool MovingObstaclesLayer::onStaticMap(double x, double y) const
{
  if (!static_map_ || static_map_->sizeX() == 0) return false;
  const Costmap2D& m = *static_map_;
  const double res = m.resolution();
  // A wall cell counts when its centre is within the margin (plus half a cell: the hit is on its edge).
  const double reach = config_.static_margin + 0.5 * res;
  const int x0 = static_cast<int>(std::floor((x - reach - m.originX()) / res));
  const int y0 = static_cast<int>(std::floor((y - reach - m.originY()) / res));
  const int xn = static_cast<int>(std::floor((x + reach - m.originX()) / res));
  const int yn = static_cast<int>(std::floor((y + reach - m.originY()) / res));
  for (int my = y0; my <= yn; ++my)
    for (int mx = x0; mx <= xn; ++mx)
    {
      if (!m.inBounds(mx, my) || m.cost(mx, my) != cost::LETHAL) continue;
      double wx, wy;
      m.mapToWorld(mx, my, wx, wy);
      if (std::hypot(wx - x, wy - y) <= reach) return true;
    }
  return false;
}

std::vector<MovingObstaclesLayer::Cluster> MovingObstaclesLayer::clusters(const ScanObservation& scan) const
{
  // 1. The hits that may be moving obstacles: those off the map's walls. All of them, not only
  //    those within obstacle_range: an unmapped wall cut off at that range would leave a small
  //    piece whose end moves with the robot, i.e. a fake walker.
  std::vector<double> xs, ys;
  for (const ScanBeam& beam : scan.beams)
  {
    const double r = beam.range;
    if (!std::isfinite(r) || r < scan.range_min || r > scan.range_max) continue;
    const double x = scan.origin_x + r * std::cos(beam.angle), y = scan.origin_y + r * std::sin(beam.angle);
    if (onStaticMap(x, y)) continue;
    xs.push_back(x);
    ys.push_back(y);
  }
  // 2. Single-linkage clusters (union-find): few hits are left after the map's walls.
  const size_t n = xs.size();
  std::vector<size_t> parent(n);
  std::iota(parent.begin(), parent.end(), 0);
  auto root = [&parent](size_t i) {
    while (parent[i] != i) i = parent[i] = parent[parent[i]];
    return i;
  };
  for (size_t i = 0; i < n; ++i)
    for (size_t j = i + 1; j < n; ++j)
      if (std::hypot(xs[i] - xs[j], ys[i] - ys[j]) <= config_.cluster_distance) parent[root(i)] = root(j);
  std::vector<std::vector<size_t>> members(n);
  for (size_t i = 0; i < n; ++i) members[root(i)].push_back(i);

  std::vector<Cluster> out;
  for (const std::vector<size_t>& m : members)
  {
    if (m.size() < kMinHits) continue;
    double cx = 0.0, cy = 0.0;
    for (size_t i : m)
    {
      cx += xs[i];
      cy += ys[i];
    }
    cx /= m.size();
    cy /= m.size();
    double radius = 0.0;
    for (size_t i : m) radius = std::max(radius, std::hypot(xs[i] - cx, ys[i] - cy));
    if (2.0 * radius > config_.max_size) continue;
    if (std::hypot(cx - scan.origin_x, cy - scan.origin_y) > config_.obstacle_range) continue;
    out.push_back({cx, cy, std::max(radius, kMinRadius)});
  }
  return out;
}

void MovingObstaclesLayer::track(const ScanObservation& scan)
{
  const double t = scan.stamp;
  if (t < latest_stamp_) tracks_.clear();  // time went back (a simulator reset): start over
  latest_stamp_ = t;
  const std::vector<Cluster> found = clusters(scan);

  // Nearest neighbour within the gate, closest pairs first; each track and cluster used once.
  struct Pair
  {
    double d;
    size_t track, cluster;
  };
  std::vector<Pair> pairs;
  for (size_t i = 0; i < tracks_.size(); ++i)
  {
    const MovingTrack& k = tracks_[i];
    const double dt = t - k.last_seen;
    const double px = k.x + k.vx * dt, py = k.y + k.vy * dt;
    for (size_t j = 0; j < found.size(); ++j)
    {
      const double d = std::hypot(found[j].x - px, found[j].y - py);
      if (d <= config_.association_gate) pairs.push_back({d, i, j});
    }
  }
  std::sort(pairs.begin(), pairs.end(), [](const Pair& a, const Pair& b) { return a.d < b.d; });
  std::vector<bool> track_used(tracks_.size(), false), cluster_used(found.size(), false);
  for (const Pair& p : pairs)
  {
    if (track_used[p.track] || cluster_used[p.cluster]) continue;
    track_used[p.track] = cluster_used[p.cluster] = true;
    MovingTrack& k = tracks_[p.track];
    const Cluster& c = found[p.cluster];
    k.x = c.x;
    k.y = c.y;
    k.radius = std::max(k.radius, std::min(c.radius, 0.5 * config_.max_size));
    k.last_seen = t;
    k.history.push_back({t, c.x, c.y});
    while (k.history.size() > 2 && k.history.front().t < t - config_.velocity_window) k.history.pop_front();
    // Velocity: least-squares slope of x(t) and y(t) over the history.
    double mt = 0.0, mx = 0.0, my = 0.0;
    for (const MovingTrack::Sample& s : k.history)
    {
      mt += s.t;
      mx += s.x;
      my += s.y;
    }
    const double n = static_cast<double>(k.history.size());
    mt /= n;
    mx /= n;
    my /= n;
    double stt = 0.0, stx = 0.0, sty = 0.0;
    for (const MovingTrack::Sample& s : k.history)
    {
      stt += (s.t - mt) * (s.t - mt);
      stx += (s.t - mt) * (s.x - mx);
      sty += (s.t - mt) * (s.y - my);
    }
    if (stt > 0.0)
    {
      k.vx = stx / stt;
      k.vy = sty / stt;
    }
  }
  for (size_t j = 0; j < found.size(); ++j)
  {
    if (cluster_used[j]) continue;
    MovingTrack k;
    k.id = next_id_++;
    k.x = found[j].x;
    k.y = found[j].y;
    k.radius = std::min(found[j].radius, 0.5 * config_.max_size);
    k.first_seen = k.last_seen = t;
    k.history.push_back({t, k.x, k.y});
    tracks_.push_back(k);
  }
  // A track that vanished (walked out of sight, or was a wrong cluster) is dropped.
  tracks_.erase(std::remove_if(tracks_.begin(), tracks_.end(),
                               [&](const MovingTrack& k) { return t - k.last_seen > config_.track_timeout; }),
                tracks_.end());
}

bool MovingObstaclesLayer::predicted(const MovingTrack& k) const
{
  const double speed = std::hypot(k.vx, k.vy);
  return k.history.size() >= 3 && k.last_seen - k.first_seen >= config_.min_track_age && speed >= config_.min_speed &&
         speed <= config_.max_speed;
}

std::vector<Pose2D> MovingObstaclesLayer::predict(const MovingTrack& k) const
{
  // Straight on at the estimated velocity: heading along it, forward speed its length.
  return predictPoses(Pose2D{k.x, k.y, std::atan2(k.vy, k.vx)}, std::hypot(k.vx, k.vy), 0.0, 0.0, config_);
}

std::vector<Pose2D> MovingObstaclesLayer::blocked(const MovingTrack& k) const
{
  const std::vector<Pose2D> poses = predict(k);
  std::vector<Pose2D> out;
  for (size_t i = 1; i < poses.size(); ++i)
  {
    const double ahead = std::min(i * config_.prediction_step, config_.prediction_time);  // [s]
    if (ahead > config_.blocked_time + 1e-9) break;
    // Our robot caught well inside the body's way (see the header): passable, so it can get out.
    if (std::hypot(poses[i].x - robot_.x, poses[i].y - robot_.y) <= k.radius + 0.5 * robot_radius_) return {};
    out.push_back(poses[i]);
  }
  return out;
}

void MovingObstaclesLayer::updateBounds(const Pose2D& robot, Bounds& bounds)
{
  robot_ = robot;
  std::stable_sort(pending_.begin(), pending_.end(),
                   [](const ScanObservation& a, const ScanObservation& b) { return a.stamp < b.stamp; });
  for (const ScanObservation& scan : pending_) track(scan);
  pending_.clear();

  // Erase what was drawn last time, and draw the current predictions.
  bounds.include(last_bounds_);
  Bounds now;
  for (const MovingTrack& k : tracks_)
    if (predicted(k)) includeDiscs(predict(k), k.radius + robot_radius_, now);
  bounds.include(now);
  last_bounds_ = now;
}

void MovingObstaclesLayer::updateCosts(Costmap2D& master, const CellWindow& w)
{
  for (const MovingTrack& k : tracks_)
  {
    if (!predicted(k)) continue;
    drawSweep(master, w, predict(k), k.radius + robot_radius_, config_.prediction_cost);
    for (const Pose2D& p : blocked(k)) drawDisc(master, w, p.x, p.y, k.radius, cost::LETHAL);
  }
}

}  // namespace mbot_navigation
