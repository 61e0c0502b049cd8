/**
 * @file internal.h
 * @brief (private to the ray casting) What its files share: the beams of a scan as angles
 *        (BeamFan) and the angular sweep over the beams inside an interval of bearings, a fast
 *        atan2, and small numeric helpers. See raycast.h for the public API.
 */
#pragma once

#include <mbot_common/geometry.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>

namespace mbot_sim
{
namespace detail
{
using mbot_common::kPi;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

/// pick ? a : b without a branch. For "did this beam hit?" a branch is mispredicted for about
/// one beam in five, which costs more than this bit-mask select.
template <typename Float, typename Bits>
inline Float selectNoBranch(bool pick, Float a, Float b)
{
  static_assert(sizeof(Float) == sizeof(Bits), "Bits must be as wide as Float");
  Bits ia;
  Bits ib;
  std::memcpy(&ia, &a, sizeof ia);
  std::memcpy(&ib, &b, sizeof ib);
  const Bits mask = Bits{0} - static_cast<Bits>(pick);
  const Bits bits = (ia & mask) | (ib & ~mask);
  Float out;
  std::memcpy(&out, &bits, sizeof out);
  return out;
}

inline int floorToInt(double v)
{
  const int i = static_cast<int>(v);  // truncates towards zero
  return i - (v < i ? 1 : 0);
}

inline int ceilToInt(double v)
{
  const int i = static_cast<int>(v);
  return i + (v > i ? 1 : 0);
}

// Error bound of approxAtan2 [rad] (the polynomial's is 2.5e-7), with room for rounding.
constexpr double kApproxAtan2Error = 1e-6;

/// atan2(y, x) [rad] within kApproxAtan2Error, several times cheaper than std::atan2. Used only
/// to choose which beams a shape may cover: intervals are widened by the error, and every
/// chosen beam gets the exact intersection test.
inline double approxAtan2(double y, double x)
{
  const double ax = std::abs(x);
  const double ay = std::abs(y);
  const double big = std::max(ax, ay);
  const double a = big > 0.0 ? std::min(ax, ay) / big : 0.0;  // in [0, 1]
  const double s = a * a;
  // Minimax fit of atan(a) / a as a polynomial in a^2 on [0, 1].
  double r = 0.0068119531;
  r = r * s - 0.0336046959;
  r = r * s + 0.0796242110;
  r = r * s - 0.1323337105;
  r = r * s + 0.1980782302;
  r = r * s - 0.3331736886;
  r = (r * s + 0.9999961118) * a;
  r = ay > ax ? 0.5 * kPi - r : r;
  r = x < 0.0 ? kPi - r : r;
  return y < 0.0 ? -r : r;
}

/// The beams of a scan as angles: beam i points along first + i * increment [rad].
struct BeamFan
{
  double first;     ///< angle of beam 0 [rad]
  double sign;      ///< +1: beams advance counter-clockwise; -1: clockwise
  double step;      ///< |increment| [rad]
  double inv_step;  ///< [1/rad]
  double span;      ///< (beams - 1) * step [rad]
  int beams;
  bool parallel;  ///< increment ~ 0: every beam points the same way

  BeamFan(double first_angle, double increment, int n)
      : first(std::remainder(first_angle, kTwoPi))  // into [-pi, pi]: keeps the sweep's winding small
        ,
        sign(increment < 0.0 ? -1.0 : 1.0),
        step(std::abs(increment)),
        inv_step(step > 0.0 ? 1.0 / step : 0.0),
        span((n - 1) * step),
        beams(n),
        parallel(step < 1e-12)
  {}
};

/// Calls visit(i) for every beam i whose angle lies in [lo, hi] (world angles [rad], any
/// winding, hi - lo <= pi). This is the angular sweep: a shape covering a few degrees costs a
/// few beam tests, not one per beam of the scan. A beam may be visited twice when the fan spans
/// more than a full turn; visitors keep the nearest return, so that is harmless.
template <typename Visit>
void forEachBeamBetween(const BeamFan& fan, double lo, double hi, Visit&& visit)
{
  if (fan.parallel)
  {
    for (int i = 0; i < fan.beams; ++i)  // let the exact test decide for every beam
      visit(i);
    return;
  }
  // Angles relative to beam 0, measured in the direction the beams advance.
  double a = (lo - fan.first) * fan.sign;
  double b = (hi - fan.first) * fan.sign;
  if (a > b) std::swap(a, b);
  const double turns = floorToInt(a * (1.0 / kTwoPi));  // wind a into [0, 2 pi)
  a -= turns * kTwoPi;
  b -= turns * kTwoPi;
  // The interval, its copy one turn earlier (for an interval straddling beam 0), and later
  // copies for fans longer than a turn.
  for (double shift = -kTwoPi; a + shift <= fan.span; shift += kTwoPi)
  {
    const double hi_i = std::min((b + shift) * fan.inv_step, fan.beams - 1.0);
    if (hi_i < 0.0) continue;
    const double lo_i = (a + shift) * fan.inv_step;
    const int i0 = lo_i <= 0.0 ? 0 : ceilToInt(lo_i);
    const int i1 = floorToInt(hi_i);
    for (int i = i0; i <= i1; ++i) visit(i);
  }
}

}  // namespace detail
}  // namespace mbot_sim
