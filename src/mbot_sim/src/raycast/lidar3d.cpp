/**
 * @file lidar3d.cpp
 * @brief The 3D lidar in the 2.5D world: rays against the extruded walls (through the 2D
 *        caster), the floor and the upright prisms; the Mid-360-like pattern; frames over time.
 *        See lidar3d.h.
 */
#include "mbot_sim/lidar3d.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <string>

namespace mbot_sim
{
namespace
{
constexpr double kInf = std::numeric_limits<double>::infinity();
constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr float kWallIntensity = 100.0f;
constexpr float kFloorIntensity = 40.0f;
constexpr double kGolden = 0.6180339887498949;  // the golden ratio's fraction

bool finite(double v) { return std::isfinite(v); }

/// sin and cos of |x| <= pi/2 by their Taylor series (error below 1e-11 there; the pattern's
/// deflections stay within half the vertical field): no libm call per point.
inline void sinCosSmall(double x, double& s, double& c)
{
  // Horner form with the reciprocals as constants: no division per point.
  constexpr double k6 = 1.0 / 6, k20 = 1.0 / 20, k42 = 1.0 / 42, k72 = 1.0 / 72, k110 = 1.0 / 110, k156 = 1.0 / 156,
                   k210 = 1.0 / 210;
  constexpr double k2 = 1.0 / 2, k12 = 1.0 / 12, k30 = 1.0 / 30, k56 = 1.0 / 56, k90 = 1.0 / 90, k132 = 1.0 / 132,
                   k182 = 1.0 / 182, k240 = 1.0 / 240;
  const double x2 = x * x;
  s = x *
      (1.0 -
       x2 * k6 *
           (1.0 - x2 * k20 *
                      (1.0 - x2 * k42 * (1.0 - x2 * k72 * (1.0 - x2 * k110 * (1.0 - x2 * k156 * (1.0 - x2 * k210)))))));
  c = 1.0 -
      x2 * k2 *
          (1.0 -
           x2 * k12 *
               (1.0 -
                x2 * k30 *
                    (1.0 - x2 * k56 * (1.0 - x2 * k90 * (1.0 - x2 * k132 * (1.0 - x2 * k182 * (1.0 - x2 * k240)))))));
}

/// The horizontal interval [t_in, t_out] of the line o + t d inside the prism's footprint;
/// false when the line misses it.
bool footprintInterval(const PrismQuery::Near& n, double x, double y, double dx, double dy, double& t_in, double& t_out)
{
  const Prism& p = n.p;
  const double ox = x - p.x;
  const double oy = y - p.y;
  if (!p.is_box)
  {
    const double b = ox * dx + oy * dy;
    const double c = ox * ox + oy * oy - p.radius * p.radius;
    const double disc = b * b - c;
    if (disc < 0.0) return false;
    const double s = std::sqrt(disc);
    t_in = -b - s;
    t_out = -b + s;
    return true;
  }
  // Into the box frame, then the slab test on both axes.
  const double lx = n.cos_yaw * ox + n.sin_yaw * oy;
  const double ly = -n.sin_yaw * ox + n.cos_yaw * oy;
  const double ldx = n.cos_yaw * dx + n.sin_yaw * dy;
  const double ldy = -n.sin_yaw * dx + n.cos_yaw * dy;
  t_in = -kInf;
  t_out = kInf;
  auto slab = [&](double o, double d, double half) {
    if (std::abs(d) < 1e-15) return std::abs(o) <= half;
    double a = (-half - o) / d;
    double b = (half - o) / d;
    if (a > b) std::swap(a, b);
    t_in = std::max(t_in, a);
    t_out = std::min(t_out, b);
    return t_in <= t_out;
  };
  return slab(lx, ldx, p.half_length) && slab(ly, ldy, p.half_width);
}

/// Where the ray's height z + t tan_e lies within [0, top]: [lo, hi] (empty: lo > hi).
void heightInterval(double z, double tan_e, double top, double& lo, double& hi)
{
  if (tan_e > 0.0)
  {
    lo = -z / tan_e;
    hi = (top - z) / tan_e;
  }
  else if (tan_e < 0.0)
  {
    lo = (top - z) / tan_e;
    hi = -z / tan_e;
  }
  else
  {
    lo = (z >= 0.0 && z <= top) ? -kInf : kInf;
    hi = kInf;
  }
}

bool insidePrism(const Prism& p, double x, double y)
{
  const double ox = x - p.x;
  const double oy = y - p.y;
  if (!p.is_box) return ox * ox + oy * oy <= p.radius * p.radius;
  const double c = std::cos(p.yaw), s = std::sin(p.yaw);
  return std::abs(c * ox + s * oy) <= p.half_length && std::abs(-s * ox + c * oy) <= p.half_width;
}
}  // namespace

// ---- scene -----------------------------------------------------------------------------------

Scene25D::Scene25D(const GridRaycaster* walls, double wall_height) : walls_(walls), wall_height_(wall_height)
{
  if (!walls) throw std::invalid_argument("Scene25D: walls must not be null");
  if (!(wall_height > 0.0) || !finite(wall_height))
    throw std::invalid_argument("Scene25D: wall_height must be > 0 [m], got " + std::to_string(wall_height));
}

void Scene25D::addPrism(const Prism& p)
{
  if (!finite(p.x) || !finite(p.y) || !finite(p.yaw) || !(p.radius >= 0.0) || !(p.half_length >= 0.0) ||
      !(p.half_width >= 0.0) || !finite(p.radius) || !finite(p.half_length) || !finite(p.half_width) ||
      !(p.height > 0.0) || !finite(p.height))
    throw std::invalid_argument("Scene25D::addPrism: finite pose, sizes >= 0 and height > 0 [m] expected");
  prisms_.push_back(p);
}

void PrismQuery::prepare(const Scene25D& scene, double x, double y, double reach, int ignore_owner)
{
  near_.clear();
  for (const Prism& p : scene.prisms())
  {
    if (ignore_owner >= 0 && p.owner == ignore_owner) continue;
    const double extent = p.is_box ? std::hypot(p.half_length, p.half_width) : p.radius;
    const double dx = p.x - x, dy = p.y - y;
    const double lim = reach + extent;
    if (dx * dx + dy * dy > lim * lim) continue;
    Near n;
    n.p = p;
    n.cos_yaw = std::cos(p.yaw);
    n.sin_yaw = std::sin(p.yaw);
    near_.push_back(n);
  }
}

// ---- one ray ---------------------------------------------------------------------------------

RayHit castRay3D(const Scene25D& scene, const PrismQuery& near, double x, double y, double z, double dir_x,
                 double dir_y, double elevation, double max_range)
{
  return castRay3DTrig(scene, near, x, y, z, dir_x, dir_y, std::cos(elevation), std::tan(elevation), max_range);
}

RayHit castRay3DTrig(const Scene25D& scene, const PrismQuery& near, double x, double y, double z, double dir_x,
                     double dir_y, double cos_e, double tan_e, double max_range)
{
  const double max_h = max_range * cos_e;  // horizontal reach [m]
  const double wall_top = scene.wallHeight();

  RayHit hit;
  double best = kInf;  // horizontal distance of the nearest hit [m]
  double wall_limit = max_h;
  if (tan_e < 0.0)
  {
    const double t_floor = z / -tan_e;
    if (t_floor < max_h)
    {
      best = t_floor;
      hit.surface = Surface::kFloor;
      hit.intensity = kFloorIntensity;
      wall_limit = t_floor;
    }
  }
  else if (tan_e > 0.0)
  {
    // Beyond this the ray is above every wall and never comes down.
    wall_limit = std::min(wall_limit, (wall_top - z) / tan_e);
  }
  if (wall_limit > 0.0)
  {
    const double d = scene.walls().castDirection(x, y, dir_x, dir_y, wall_limit);
    if (d < wall_limit)
    {
      best = d;
      hit.surface = Surface::kWall;
      hit.intensity = kWallIntensity;
    }
  }
  for (const PrismQuery::Near& n : near.near())
  {
    double t_in = 0.0, t_out = 0.0;
    if (!footprintInterval(n, x, y, dir_x, dir_y, t_in, t_out)) continue;
    double lo = 0.0, hi = 0.0;
    heightInterval(z, tan_e, n.p.height, lo, hi);
    const double enter = std::max(std::max(t_in, lo), 0.0);
    const double leave = std::min(t_out, hi);
    if (enter <= leave && enter < best && enter < max_h)
    {
      best = enter;
      hit.surface = Surface::kPrism;
      hit.intensity = n.p.intensity;
    }
  }
  if (hit.surface == Surface::kNone)
  {
    hit.range = kInf;
    return hit;
  }
  hit.range = best / cos_e;
  return hit;
}

RayHit castRay3DBruteForce(const Scene25D& scene, double x, double y, double z, double dir_x, double dir_y,
                           double elevation, double max_range, double step, int ignore_owner)
{
  const double ce = std::cos(elevation), se = std::sin(elevation);
  RayHit hit;
  hit.range = kInf;
  for (double s = 0.0; s <= max_range; s += step)
  {
    const double px = x + s * ce * dir_x, py = y + s * ce * dir_y, pz = z + s * se;
    if (pz < 0.0)
    {
      hit.range = s;
      hit.surface = Surface::kFloor;
      return hit;
    }
    if (pz <= scene.wallHeight() && scene.walls().occupiedAt(px, py))
    {
      hit.range = s;
      hit.surface = Surface::kWall;
      return hit;
    }
    for (const Prism& p : scene.prisms())
    {
      if (ignore_owner >= 0 && p.owner == ignore_owner) continue;
      if (pz <= p.height && insidePrism(p, px, py))
      {
        hit.range = s;
        hit.surface = Surface::kPrism;
        return hit;
      }
    }
  }
  return hit;
}

// ---- the pattern -----------------------------------------------------------------------------

LidarPattern::LidarPattern(const LidarSpec& spec) : spec_(spec)
{
  auto bad = [](const std::string& what) { throw std::invalid_argument("LidarSpec: " + what); };
  if (!(spec.rate > 0.0) || !finite(spec.rate)) bad("rate must be > 0 [Hz]");
  if (spec.points_per_frame < 1) bad("points_per_frame must be >= 1");
  if (!(spec.min_elevation >= -kPi / 2 + 1e-3) || !(spec.max_elevation <= kPi / 2 - 1e-3) ||
      !(spec.max_elevation > spec.min_elevation))
    bad("elevations must satisfy -90 deg < min_elevation < max_elevation < 90 deg");
  if (!(spec.range_min >= 0.0) || !(spec.range_max > spec.range_min) || !finite(spec.range_max))
    bad("ranges must satisfy 0 <= range_min < range_max");
  if (!(spec.range_noise >= 0.0) || !finite(spec.range_noise)) bad("range_noise must be >= 0 [m]");
  if (!(spec.range_quantization >= 0.0) || !finite(spec.range_quantization)) bad("range_quantization must be >= 0 [m]");
  dt_ = 1.0 / (spec.rate * spec.points_per_frame);
  // Two counter-rotating phasors (a Risley-prism rosette), about 124 and 76 turns per frame:
  // their ratio is the golden ratio and neither is a whole multiple of the frame rate, so the
  // pattern never repeats.
  w1_ = kTwoPi * spec.rate * 123.60679774997897;
  w2_ = kTwoPi * spec.rate * 76.39320225002103;
  e_mid_ = 0.5 * (spec.max_elevation + spec.min_elevation);
  e_half_ = 0.5 * (spec.max_elevation - spec.min_elevation);
  step1_c_ = std::cos(w1_ * dt_);
  step1_s_ = std::sin(w1_ * dt_);
  step2_c_ = std::cos(w2_ * dt_);
  step2_s_ = std::sin(w2_ * dt_);
  steph_c_ = std::cos(kTwoPi * spec.rate * dt_);
  steph_s_ = std::sin(kTwoPi * spec.rate * dt_);
  for (int j = 0; j < 4; ++j)
  {
    phase_c_[j] = std::cos(kTwoPi * kGolden * j);
    phase_s_[j] = std::sin(kTwoPi * kGolden * j);
  }
  cos_mid_ = std::cos(e_mid_);
  sin_mid_ = std::sin(e_mid_);
}

void LidarPattern::seek(uint64_t n, Cursor& c) const
{
  const double t = static_cast<double>(n) * dt_;
  const double a1 = std::fmod(w1_ * t, kTwoPi), a2 = std::fmod(w2_ * t, kTwoPi);
  const double head = kTwoPi * std::fmod(spec_.rate * t, 1.0);
  c.n = n;
  c.c1 = std::cos(a1);
  c.s1 = std::sin(a1);
  c.c2 = std::cos(a2);
  c.s2 = std::sin(a2);
  c.ch = std::cos(head);
  c.sh = std::sin(head);
}

void LidarPattern::next(Cursor& c) const
{
  auto turn = [](double& re, double& im, double sc, double ss) {
    const double r = re * sc - im * ss;
    im = im * sc + re * ss;
    re = r;
  };
  turn(c.c1, c.s1, step1_c_, step1_s_);
  turn(c.c2, c.s2, step2_c_, step2_s_);
  turn(c.ch, c.sh, steph_c_, steph_s_);
  ++c.n;
}

void LidarPattern::unitDirection(const Cursor& c, double& cos_az, double& sin_az, double& cos_el, double& sin_el) const
{
  const int j = static_cast<int>(c.n & 3u);
  const double pc = phase_c_[j], ps = phase_s_[j];
  const double cos_a1 = c.c1 * pc - c.s1 * ps, sin_a1 = c.s1 * pc + c.c1 * ps;
  const double cos_a2 = c.c2 * pc - c.s2 * ps, sin_a2 = c.s2 * pc + c.c2 * ps;
  const double r = 0.5 * e_half_;
  double sd, cd, se, ce;
  sinCosSmall(r * (cos_a1 + cos_a2), sd, cd);  // the azimuth's deflection
  sinCosSmall(r * (sin_a1 - sin_a2), se, ce);  // the elevation's
  // the head turned by j quarter turns
  double hc = c.ch, hs = c.sh;
  for (int q = 0; q < j; ++q)
  {
    const double tmp = hc;
    hc = -hs;
    hs = tmp;
  }
  cos_az = hc * cd - hs * sd;
  sin_az = hs * cd + hc * sd;
  cos_el = cos_mid_ * ce - sin_mid_ * se;
  sin_el = sin_mid_ * ce + cos_mid_ * se;
}

void LidarPattern::direction(uint64_t n, double& azimuth, double& elevation) const
{
  const int channel = static_cast<int>(n & 3u);
  const double t = static_cast<double>(n) * dt_;
  const double phase = kTwoPi * kGolden * channel;
  // Phases wrapped before sin/cos: t * w grows without bound over a long run.
  const double a1 = std::fmod(w1_ * t, kTwoPi) + phase;
  const double a2 = std::fmod(w2_ * t, kTwoPi) + phase;
  const double r = 0.5 * e_half_;
  // Head: one turn per frame; the four channels a quarter turn apart.
  const double head = kTwoPi * (std::fmod(spec_.rate * t, 1.0) + 0.25 * channel);
  azimuth = head + r * (std::cos(a1) + std::cos(a2));
  elevation = e_mid_ + r * (std::sin(a1) - std::sin(a2));
}

// ---- frames over time ------------------------------------------------------------------------

LidarScanner::LidarScanner(const LidarSpec& spec, double mount_x, double mount_y, double mount_z, double mount_yaw,
                           double start)
    : spec_(spec),
      pattern_(spec),
      mount_x_(mount_x),
      mount_y_(mount_y),
      mount_z_(mount_z),
      mount_yaw_(mount_yaw),
      start_(start),
      frame_start_(start),
      next_point_(0)
{
  frame_.points.reserve(static_cast<size_t>(spec.points_per_frame));
}

void LidarScanner::restart(double t)
{
  // The next frame starts on the first frame boundary from t: frames keep their phase.
  const double period = 1.0 / spec_.rate;
  const double k = std::ceil((t - start_) / period - 1e-9);
  frame_start_ = start_ + std::max(0.0, k) * period;
  in_frame_ = 0;
  frame_.points.clear();
}

size_t LidarScanner::advance(const Scene25D& scene, const PrismQuery& near, double t0, const PlanarPose& p0, double t1,
                             const PlanarPose& p1, std::mt19937& rng, std::vector<LidarFrame>& done)
{
  const double dt = 1.0 / (spec_.rate * spec_.points_per_frame);
  const double period = 1.0 / spec_.rate;
  const double span = t1 - t0;
  const double dtheta = std::remainder(p1.theta - p0.theta, kTwoPi);
  size_t cast = 0;
  bool started = false;
  LidarPattern::Cursor cursor;
  double rc = 1.0, rs = 0.0;          // e^{i robot heading} at the point's time
  double turn_c = 1.0, turn_s = 0.0;  // its turn per point
  const double yc = std::cos(mount_yaw_), ys = std::sin(mount_yaw_);
  for (;;)
  {
    const double t = frame_start_ + in_frame_ * dt;
    if (t >= t1) break;
    const double alpha = span > 0.0 ? std::min(1.0, std::max(0.0, (t - t0) / span)) : 1.0;
    if (!started)
    {
      // Exact at the step's first point, then turned point by point (no trigonometry per point).
      pattern_.seek(next_point_, cursor);
      const double heading = p0.theta + alpha * dtheta;
      rc = std::cos(heading);
      rs = std::sin(heading);
      const double per_point = span > 0.0 ? dtheta * dt / span : 0.0;
      turn_c = std::cos(per_point);
      turn_s = std::sin(per_point);
      started = true;
    }
    const double rx = p0.x + alpha * (p1.x - p0.x);
    const double ry = p0.y + alpha * (p1.y - p0.y);
    const double sx = rx + rc * mount_x_ - rs * mount_y_;  // the lidar in the world
    const double sy = ry + rs * mount_x_ + rc * mount_y_;
    const double lc = rc * yc - rs * ys, ls = rs * yc + rc * ys;  // its heading
    double ca = 1.0, sa = 0.0, ce = 1.0, se = 0.0;
    pattern_.unitDirection(cursor, ca, sa, ce, se);
    const double dir_x = lc * ca - ls * sa, dir_y = ls * ca + lc * sa;
    const RayHit hit = castRay3DTrig(scene, near, sx, sy, mount_z_, dir_x, dir_y, ce, se / ce, spec_.range_max);
    ++cast;
    if (hit.surface != Surface::kNone)
    {
      double range = hit.range;
      if (spec_.range_noise > 0.0) range += spec_.range_noise * gauss_(rng);
      if (spec_.range_quantization > 0.0)
        range = std::round(range / spec_.range_quantization) * spec_.range_quantization;
      if (range >= spec_.range_min && range <= spec_.range_max)
      {
        LidarPoint p;
        p.x = static_cast<float>(range * ce * ca);
        p.y = static_cast<float>(range * ce * sa);
        p.z = static_cast<float>(range * se);
        p.intensity = hit.intensity;
        p.time = static_cast<float>(in_frame_ * dt);
        frame_.points.push_back(p);
      }
    }
    ++next_point_;
    pattern_.next(cursor);
    const double r = rc * turn_c - rs * turn_s;
    rs = rs * turn_c + rc * turn_s;
    rc = r;
    if (++in_frame_ == spec_.points_per_frame)
    {
      frame_.stamp = frame_start_;
      done.push_back(std::move(frame_));
      frame_ = LidarFrame();
      frame_.points.reserve(static_cast<size_t>(spec_.points_per_frame));
      frame_start_ = start_ + std::round((frame_start_ - start_) / period + 1.0) * period;
      in_frame_ = 0;
    }
  }
  return cast;
}

}  // namespace mbot_sim
