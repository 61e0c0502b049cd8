#include "mbot_navigation/costmap/obstacle_layer.h"

#include <cmath>
#include <cstdlib>
#include <stdexcept>

namespace mbot_navigation
{
void ScanObservation::addEndpoint(double x, double y)
{
  beams.push_back({std::atan2(y - origin_y, x - origin_x), std::hypot(x - origin_x, y - origin_y)});
}

void ScanObservation::addNoReturn(double angle) { beams.push_back({angle, std::numeric_limits<double>::infinity()}); }

ObstacleLayer::ObstacleLayer(const ObstacleLayerConfig& config) : config_(config)
{
  if (!(config.obstacle_range >= 0.0) || !(config.raytrace_range >= 0.0))
    throw std::invalid_argument("ObstacleLayerConfig: 'obstacle_range' and 'raytrace_range' must be >= 0 [m]");
}

void ObstacleLayer::matchSize(const Costmap2D& master)
{
  grid_ = Costmap2D(master.sizeX(), master.sizeY(), master.resolution(), master.originX(), master.originY(),
                    unknownValue());
}

void ObstacleLayer::updateOrigin(double new_origin_x, double new_origin_y)
{
  grid_.updateOrigin(new_origin_x, new_origin_y, unknownValue());
}

void ObstacleLayer::reset()
{
  grid_.fill(unknownValue());
  pending_.clear();
}

namespace
{
/// Clip the segment p0 -> p1 [m] to the box [lo, hi] (Liang-Barsky); t1 is the kept end fraction.
bool clipEnd(double x0, double y0, double dx, double dy, double lo_x, double lo_y, double hi_x, double hi_y, double& t1)
{
  t1 = 1.0;
  const double p[4] = {-dx, dx, -dy, dy};
  const double q[4] = {x0 - lo_x, hi_x - x0, y0 - lo_y, hi_y - y0};
  for (int i = 0; i < 4; ++i)
  {
    if (q[i] < 0.0) return false;  // the start is outside the box
    if (p[i] > 0.0) t1 = std::min(t1, q[i] / p[i]);
  }
  return true;
}
}  // namespace

void ObstacleLayer::raytrace(double x0, double y0, double x1, double y1, bool keep_end, Bounds& bounds)
{
  const double res = grid_.resolution();
  // The box of cell centres' cells, shrunk a little so that a clipped end stays inside.
  const double eps = 1e-6 * res;
  const double lo_x = grid_.originX() + eps, lo_y = grid_.originY() + eps;
  const double hi_x = grid_.originX() + grid_.sizeX() * res - eps;
  const double hi_y = grid_.originY() + grid_.sizeY() * res - eps;
  double t1;
  // As costmap_2d: a sensor outside the grid clears nothing.
  if (!clipEnd(x0, y0, x1 - x0, y1 - y0, lo_x, lo_y, hi_x, hi_y, t1)) return;
  if (t1 < 1.0) keep_end = false;  // the end was cut off: the hit lies outside the grid
  x1 = x0 + t1 * (x1 - x0);
  y1 = y0 + t1 * (y1 - y0);
  bounds.include(x0, y0);
  bounds.include(x1, y1);

  unsigned cx0, cy0, cx1, cy1;
  if (!grid_.worldToMap(x0, y0, cx0, cy0) || !grid_.worldToMap(x1, y1, cx1, cy1)) return;
  // Bresenham from the sensor cell to the end cell.
  int x = static_cast<int>(cx0), y = static_cast<int>(cy0);
  const int ex = static_cast<int>(cx1), ey = static_cast<int>(cy1);
  const int adx = std::abs(ex - x), ady = -std::abs(ey - y);
  const int sx = x < ex ? 1 : -1, sy = y < ey ? 1 : -1;
  int err = adx + ady;
  uint8_t* cells = grid_.data();
  while (true)
  {
    const bool at_end = (x == ex && y == ey);
    if (at_end && keep_end) break;
    cells[grid_.index(x, y)] = cost::FREE;
    if (at_end) break;
    const int e2 = 2 * err;
    if (e2 >= ady)
    {
      err += ady;
      x += sx;
    }
    if (e2 <= adx)
    {
      err += adx;
      y += sy;
    }
  }
}

double ObstacleLayer::usableRange(double range, const ScanObservation& scan) const
{
  const double kSkip = std::numeric_limits<double>::quiet_NaN();
  if (std::isinf(range) && range > 0.0)
    // costmap_2d (inf_is_valid) puts the reading a tenth of a millimetre inside range_max.
    return config_.inf_is_valid ? scan.range_max - 0.0001 : kSkip;
  if (!std::isfinite(range)) return kSkip;                             // REP-117: invalid, too close
  if (range < scan.range_min || range > scan.range_max) return kSkip;  // out of the sensor's spec
  return range;
}

void ObstacleLayer::updateBounds(const Pose2D& robot, Bounds& bounds)
{
  // 1. Clearing, for every queued scan (costmap_2d's raytraceFreespace).
  for (const ScanObservation& scan : pending_)
  {
    if (!config_.clearing) break;
    for (const ScanBeam& beam : scan.beams)
    {
      const double r = usableRange(beam.range, scan);
      if (std::isnan(r)) continue;
      const bool no_end = std::isinf(r);  // +Inf with an infinite range_max: clear, end nowhere
      const double length = no_end ? config_.raytrace_range : std::min(r, config_.raytrace_range);
      const bool hit_inside = !no_end && r <= config_.raytrace_range;
      raytrace(scan.origin_x, scan.origin_y, scan.origin_x + length * std::cos(beam.angle),
               scan.origin_y + length * std::sin(beam.angle), hit_inside, bounds);
    }
  }
  // 2. Marking: finite readings within obstacle_range.
  for (const ScanObservation& scan : pending_)
  {
    if (!config_.marking) break;
    for (const ScanBeam& beam : scan.beams)
    {
      const double r = usableRange(beam.range, scan);
      if (!std::isfinite(r) || r > config_.obstacle_range) continue;
      const double px = scan.origin_x + r * std::cos(beam.angle);
      const double py = scan.origin_y + r * std::sin(beam.angle);
      unsigned mx, my;
      if (!grid_.worldToMap(px, py, mx, my)) continue;
      grid_.setCost(mx, my, cost::LETHAL);
      bounds.include(px, py);
    }
  }
  pending_.clear();

  // 3. The robot's own cells are free (the robot cannot stand in an obstacle).
  if (config_.footprint_clearing_enabled && robot_radius_ > 0.0)
  {
    const double res = grid_.resolution();
    const int r_cells = static_cast<int>(std::ceil(robot_radius_ / res));
    unsigned cx, cy;
    if (grid_.worldToMap(robot.x, robot.y, cx, cy))
    {
      for (int dy = -r_cells; dy <= r_cells; ++dy)
        for (int dx = -r_cells; dx <= r_cells; ++dx)
        {
          const int x = static_cast<int>(cx) + dx, y = static_cast<int>(cy) + dy;
          if (!grid_.inBounds(x, y)) continue;
          double wx, wy;
          grid_.mapToWorld(x, y, wx, wy);
          if (std::hypot(wx - robot.x, wy - robot.y) <= robot_radius_) grid_.setCost(x, y, cost::FREE);
        }
      bounds.include(robot.x - robot_radius_, robot.y - robot_radius_);
      bounds.include(robot.x + robot_radius_, robot.y + robot_radius_);
    }
  }
}

void ObstacleLayer::updateCosts(Costmap2D& master, const CellWindow& w)
{
  for (int y = w.y0; y < w.yn; ++y)
    for (int x = w.x0; x < w.xn; ++x) updateWithMax(master.data()[master.index(x, y)], grid_.cost(x, y));
}

}  // namespace mbot_navigation
