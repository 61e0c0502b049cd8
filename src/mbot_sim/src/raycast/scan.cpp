/**
 * @file scan.cpp
 * @brief castScan(): one whole laser scan. The beam directions (a laser's layout is computed
 *        once), the walls (GridRaycaster::castScanWalls), then every shape near the sensor
 *        shortens the few beams inside the angle it covers, then REP-117 encoding.
 */
#include "mbot_sim/raycast.h"

#include "internal.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <limits>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbot_sim
{
using namespace detail;

namespace
{
/// Beam directions relative to the sensor heading, cos/sin of min_angle + i * increment. A
/// laser's layout never changes, so they are computed once and only rotated by the yaw.
struct BeamLayout
{
  double min_angle = 0.0;
  double increment = 0.0;
  std::vector<double> rel_cos;
  std::vector<double> rel_sin;

  bool matches(const ScanSpec& spec) const
  {
    return rel_cos.size() == static_cast<size_t>(spec.beams) && min_angle == spec.min_angle &&
           increment == spec.angle_increment;
  }
};

/// Reused between calls (per thread) so that a scan allocates nothing and computes no cos/sin.
struct ScanScratch
{
  std::vector<BeamLayout> layouts;  ///< the few laser layouts of the fleet's models
  size_t next_to_replace = 0;
  std::vector<double> dir_x;  ///< world beam directions of the current scan
  std::vector<double> dir_y;
  std::vector<double> range;  ///< nearest return so far per beam [m]

  const BeamLayout& layout(const ScanSpec& spec)
  {
    for (const BeamLayout& l : layouts)
      if (l.matches(spec)) return l;
    constexpr size_t kMaxLayouts = 8;  // beyond that, replace them in turn
    if (layouts.size() < kMaxLayouts)
      layouts.emplace_back();
    else
      std::swap(layouts[next_to_replace++ % kMaxLayouts], layouts.back());
    BeamLayout& l = layouts.back();
    l.min_angle = spec.min_angle;
    l.increment = spec.angle_increment;
    l.rel_cos.resize(spec.beams);
    l.rel_sin.resize(spec.beams);
    for (int i = 0; i < spec.beams; ++i)
    {
      l.rel_cos[i] = std::cos(spec.min_angle + i * spec.angle_increment);
      l.rel_sin[i] = std::sin(spec.min_angle + i * spec.angle_increment);
    }
    return l;
  }
};

/// What the shape sweeps need to know about the scan being cast.
struct ScanView
{
  double sx, sy;  ///< sensor position [m]
  double range_max;
  const BeamFan& fan;
  const double* dir_x;
  const double* dir_y;
  double* range;  ///< per beam, nearest return so far [m]

  void sensorInsideShape() const { std::fill(range, range + fan.beams, 0.0); }
};

/// Shorten the beams that hit circle c.
void sweepCircle(const ScanView& scan, const Circle& c)
{
  const double mx = c.x - scan.sx;  // sensor -> centre
  const double my = c.y - scan.sy;
  const double d2 = mx * mx + my * my;
  const double r2 = c.radius * c.radius;
  if (d2 <= r2) return scan.sensorInsideShape();
  const double d = std::sqrt(d2);
  const double nearest = d - c.radius;  // no beam can meet the circle closer than this
  if (nearest >= scan.range_max) return;
  // Seen from the sensor the circle covers bearing +- asin(r / d). r / sqrt(d^2 - r^2) (the
  // tangent of that angle) is a little wider and needs no asin: fine, since every beam in
  // the interval gets the exact test. (Capped at pi/2, which asin never exceeds.)
  const double half = std::min(c.radius / std::sqrt(d2 - r2), 0.5 * kPi) + kApproxAtan2Error;
  const double bearing = approxAtan2(my, mx);
  forEachBeamBetween(scan.fan, bearing - half, bearing + half, [&](int i) {
    if (nearest >= scan.range[i]) return;  // this beam already has a closer return (a wall or another shape)
    // Ray-circle: closest approach at b along the beam; the entry lies sqrt(disc) before it.
    const double b = mx * scan.dir_x[i] + my * scan.dir_y[i];
    const double disc = b * b - (d2 - r2);
    if (disc < 0.0 || b < 0.0) return;
    scan.range[i] = std::min(scan.range[i], b - std::sqrt(disc));
  });
}

/// Ray from local point (lx, ly) along local unit (ux, uy) against the box |x| <= hl, |y| <= hw
/// (slab test): distance to the entry point, or +Inf. The ray starts outside the box.
inline double rayBox(double lx, double ly, double ux, double uy, double hl, double hw)
{
  double t_in = 0.0;
  double t_out = kInf;
  const double p[2] = {lx, ly};
  const double u[2] = {ux, uy};
  const double half[2] = {hl, hw};
  for (int a = 0; a < 2; ++a)
  {
    if (u[a] == 0.0)
    {
      if (std::abs(p[a]) > half[a]) return kInf;
      continue;
    }
    double t0 = (-half[a] - p[a]) / u[a];
    double t1 = (half[a] - p[a]) / u[a];
    if (t0 > t1) std::swap(t0, t1);
    t_in = std::max(t_in, t0);
    t_out = std::min(t_out, t1);
  }
  return t_in <= t_out ? t_in : kInf;
}

/// Shorten the beams that hit box b (with cos_yaw, sin_yaw of its yaw).
void sweepBox(const ScanView& scan, const OrientedBox& b, double cos_yaw, double sin_yaw)
{
  const double mx = b.x - scan.sx;  // sensor -> centre
  const double my = b.y - scan.sy;
  // The sensor in the box frame.
  const double lx = -(cos_yaw * mx + sin_yaw * my);
  const double ly = -(-sin_yaw * mx + cos_yaw * my);
  const double gap_x = std::abs(lx) - b.half_length;
  const double gap_y = std::abs(ly) - b.half_width;
  if (gap_x <= 0.0 && gap_y <= 0.0) return scan.sensorInsideShape();
  const double nearest = std::hypot(std::max(gap_x, 0.0), std::max(gap_y, 0.0));
  if (nearest >= scan.range_max) return;
  // The box covers the bearings between its extreme corners. The sensor is outside the
  // (convex) box, so that cone is narrower than pi and contains the centre's bearing: measure
  // the corners' bearings relative to the centre's and take the smallest and largest.
  double lo = 0.0;
  double hi = 0.0;
  for (int k = 0; k < 4; ++k)
  {
    const double cl = (k & 1) ? b.half_length : -b.half_length;
    const double cw = (k & 2) ? b.half_width : -b.half_width;
    const double vx = mx + cos_yaw * cl - sin_yaw * cw;  // sensor -> corner
    const double vy = my + sin_yaw * cl + cos_yaw * cw;
    const double rel = approxAtan2(mx * vy - my * vx, mx * vx + my * vy);
    lo = std::min(lo, rel);
    hi = std::max(hi, rel);
  }
  const double bearing = approxAtan2(my, mx);
  const double pad = 2.0 * kApproxAtan2Error;
  forEachBeamBetween(scan.fan, bearing + lo - pad, bearing + hi + pad, [&](int i) {
    if (nearest >= scan.range[i]) return;
    const double ux = cos_yaw * scan.dir_x[i] + sin_yaw * scan.dir_y[i];  // beam in box frame
    const double uy = -sin_yaw * scan.dir_x[i] + cos_yaw * scan.dir_y[i];
    scan.range[i] = std::min(scan.range[i], rayBox(lx, ly, ux, uy, b.half_length, b.half_width));
  });
}
}  // namespace

void castScan(const GridRaycaster& grid, const ShapeSet& shapes, const ScanSpec& spec, std::vector<float>& ranges)
{
  if (spec.beams < 0) throw std::invalid_argument("castScan: beams must be >= 0, got " + std::to_string(spec.beams));
  if (!(spec.range_max > 0.0))
    throw std::invalid_argument("castScan: range_max must be > 0 [m], got " + std::to_string(spec.range_max));
  if (!std::isfinite(spec.x) || !std::isfinite(spec.y) || !std::isfinite(spec.yaw) || !std::isfinite(spec.min_angle) ||
      !std::isfinite(spec.angle_increment))
    throw std::invalid_argument(
        "castScan: x, y, yaw, min_angle and angle_increment must be "
        "finite");
  const int n = spec.beams;
  ranges.resize(n);
  if (n == 0) return;

  // ---- beam directions
  thread_local ScanScratch scratch;
  const BeamLayout& layout = scratch.layout(spec);
  scratch.dir_x.resize(n);
  scratch.dir_y.resize(n);
  scratch.range.resize(n);
  const double cos_yaw = std::cos(spec.yaw);
  const double sin_yaw = std::sin(spec.yaw);
  for (int i = 0; i < n; ++i)
  {
    scratch.dir_x[i] = cos_yaw * layout.rel_cos[i] - sin_yaw * layout.rel_sin[i];
    scratch.dir_y[i] = sin_yaw * layout.rel_cos[i] + cos_yaw * layout.rel_sin[i];
  }
  const BeamFan fan(spec.yaw + spec.min_angle, spec.angle_increment, n);
  const ScanView scan{
      spec.x, spec.y, spec.range_max, fan, scratch.dir_x.data(), scratch.dir_y.data(), scratch.range.data()};

  // ---- walls first: every beam gets its grid range (range_max when it hits nothing).
  grid.castScanWalls(spec.x, spec.y, scan.dir_x, scan.dir_y, spec.yaw + spec.min_angle, spec.angle_increment, n,
                     spec.range_max, scan.range);

  // ---- then shapes: each one can only shorten the beams inside the angle it covers.
  // Shapes are bucketed by centre, so look at buckets up to range_max + the largest shape
  // extent away: a shape whose centre is farther cannot reach any beam.
  auto ignored = [&](int owner) { return spec.ignore_owner >= 0 && owner == spec.ignore_owner; };
  const double reach = spec.range_max + shapes.max_extent_;
  const int64_t bx0 = shapes.bucketIndex(spec.x - reach);
  const int64_t bx1 = shapes.bucketIndex(spec.x + reach);
  const int64_t by0 = shapes.bucketIndex(spec.y - reach);
  const int64_t by1 = shapes.bucketIndex(spec.y + reach);
  for (int64_t by = by0; by <= by1 && shapes.count_ > 0; ++by)
  {
    for (int64_t bx = bx0; bx <= bx1; ++bx)
    {
      const ShapeSet::Bucket* bucket = shapes.findBucket(bx, by);
      if (bucket == nullptr) continue;
      for (const Circle& c : bucket->circles)
        if (!ignored(c.owner)) sweepCircle(scan, c);
      for (const ShapeSet::PreparedBox& pb : bucket->boxes)
        if (!ignored(pb.box.owner)) sweepBox(scan, pb.box, pb.cos_yaw, pb.sin_yaw);
    }
  }

  // ---- REP-117 encoding.
  const float inf = std::numeric_limits<float>::infinity();
  const double range_min = spec.range_min;
  const double range_max = spec.range_max;
  float* out = ranges.data();
  for (int i = 0; i < n; ++i)
  {
    const double r = scan.range[i];
    const float near = selectNoBranch<float, uint32_t>(r < range_min, -inf, static_cast<float>(r));
    out[i] = selectNoBranch<float, uint32_t>(r >= range_max, inf, near);
  }
}

}  // namespace mbot_sim
