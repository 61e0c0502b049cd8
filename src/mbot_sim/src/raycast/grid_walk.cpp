/**
 * @file grid_walk.cpp
 * @brief GridRaycaster, the walls as a grid: its clearance maps (how far every cell is from the
 *        walls), and rays traced through the cells, with long steps through open space and an
 *        exact cell walk next to walls (cast, castFan). The sweep over wall faces is in
 *        wall_sweep.cpp. See raycast.h.
 */
#include "mbot_sim/raycast.h"

#include "internal.h"

#include <mbot_common/distance_transform.h>

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <stdexcept>
#include <string>

namespace mbot_sim
{
using namespace detail;

namespace
{
// ----- clearance maps -----
// Clearances are stored in quarter cells in one byte (0 .. 63.75 cells): a quarter cell lost to
// rounding down costs little, and one byte per cell keeps a map in the CPU cache.
constexpr double kClearanceUnit = 0.25;  // [cells] per stored unit
constexpr unsigned kClearanceMaxUnits = 255;
// Clearances are rounded down after subtracting this margin [cells], so that a long step
// always ends strictly outside every wall despite rounding.
constexpr double kClearanceMargin = 1e-3;
// In the maps the ray tracing reads, a wall cell is marked 0 and a free cell is at least 1:
// values below kMinLongStep never make a ray jump, so this costs nothing, and a cell walk then
// reads one byte per cell to learn both "wall?" and "open space again?".
constexpr uint8_t kWallCell = 0;

// ----- ray tracing -----
// A long step is taken when the clearance is at least this [units]. Exact clearances are
// distances between cells (0, 1, sqrt(2), 2, ...), so 3 units = "not right next to a wall".
constexpr unsigned kMinLongStep = 3;
static_assert(kWallCell + 1 < kMinLongStep, "free cells next to a wall (1) must not jump");
// While walking cell by cell, go back to long steps once a cell's clearance reaches this
// [units] (3 cells): switching back costs about as much as walking a few cells, so short jumps
// do not pay. (Measured: 7 to 28 units are within 10% of each other, in the benchmark room and
// in a map of narrow corridors.)
constexpr unsigned kResumeLongSteps = 12;
// Long steps track the ray's position in fixed point, 32 integer + 32 fractional bits [cells].
constexpr int kFixedShift = 32;
constexpr double kFixedOne = 4294967296.0;  // 2^32
}  // namespace

// =============================================================================================
// GridRaycaster
// =============================================================================================

GridRaycaster::GridRaycaster(std::vector<uint8_t> occupied, unsigned size_x, unsigned size_y, double resolution,
                             double origin_x, double origin_y)
    : size_x_(size_x),
      size_y_(size_y),
      resolution_(resolution),
      inv_resolution_(1.0 / resolution),
      origin_x_(origin_x),
      origin_y_(origin_y),
      occupied_(std::move(occupied))
{
  if (!(resolution > 0.0))
    throw std::invalid_argument("GridRaycaster: resolution must be > 0 [m], got " + std::to_string(resolution));
  if (occupied_.size() != static_cast<size_t>(size_x) * size_y)
    throw std::invalid_argument("GridRaycaster: occupied has " + std::to_string(occupied_.size()) +
                                " cells, expected size_x * size_y = " + std::to_string(size_x) + " * " +
                                std::to_string(size_y));
  computeClearance();
  extractWallFaces();
}

// The clearance of a cell C is the smallest distance from ANY point of C to ANY occupied cell
// (both are solid squares of side 1). For an occupied cell offset by (dx, dy) cells that
// square-to-square distance is hypot(g(dx), g(dy)) with g(d) = max(|d| - 1, 0): neighbours,
// diagonal ones included, touch C. (The centre-to-centre distance minus 1 is NOT safe: a
// diagonal neighbour is sqrt(2) away centre to centre, yet touches C at a corner.)
//
// It is computed like a Euclidean distance transform, one axis at a time:
// 1. along each line (row or column), the gap g to the nearest occupied cell of that line
//    looking only ahead (increasing index) or only behind;
// 2. across the lines, d^2(C) = min over cells O of the line gap at O plus g(offset across)^2,
//    which is the 1D squared distance transform of Felzenszwalb & Huttenlocher once g is
//    written as min(|offset - e|) for e in {-1, 0, 1}: a 3-wide min filter first.
//
// Quadrant maps: a ray heading right and up (dir_x >= 0, dir_y >= 0) from a point of cell C
// only ever enters cells at or right of C's column and at or above C's row. So for it, the
// clearance over the occupied cells at or right of C (a one-sided gap along rows), and the
// one over the cells at or above C (one-sided along columns), are both safe jumps: it takes
// the larger. A ray running beside a wall, or away from one, then jumps as if it were not there.
namespace
{
enum class Look
{
  kAhead,   ///< only occupied cells at or after this one (increasing index)
  kBehind,  ///< only at or before
};

constexpr double kFar = 1e20;  // "no occupied cell": finite, as the transform needs [cells^2]

/// Step 1: per cell, g^2 of the gap to the nearest occupied cell of its line (rows when
/// along_x, columns otherwise) looking one way, or kFar.
std::vector<double> lineGaps(const std::vector<uint8_t>& occupied, int w, int h, bool along_x, Look look)
{
  std::vector<double> gap2(occupied.size(), kFar);
  const int lines = along_x ? h : w;
  const int len = along_x ? w : h;
  auto at = [&](int line, int i) {
    return along_x ? static_cast<size_t>(line) * w + i : static_cast<size_t>(i) * w + line;
  };
  auto store = [&](size_t idx, int cells_between) {
    const double g = std::max(cells_between - 1, 0);
    gap2[idx] = g * g;
  };
  for (int line = 0; line < lines; ++line)
  {
    if (look == Look::kAhead)
      for (int i = len - 1, next = -1; i >= 0; --i)  // nearest occupied at or after i
      {
        if (occupied[at(line, i)]) next = i;
        if (next >= 0) store(at(line, i), next - i);
      }
    else
      for (int i = 0, prev = -1; i < len; ++i)  // nearest occupied at or before i
      {
        if (occupied[at(line, i)]) prev = i;
        if (prev >= 0) store(at(line, i), i - prev);
      }
  }
  return gap2;
}

/// Step 2: combine the line gaps across the lines (along columns when the gaps were taken
/// along rows, and vice versa); d2 becomes the squared clearance [cells^2].
void spreadAcrossLines(std::vector<double>& d2, int w, int h, bool gaps_along_x)
{
  const int lines = gaps_along_x ? w : h;  // we now run across: along columns for row gaps
  const int len = gaps_along_x ? h : w;
  std::vector<double> in(len), out(len), z(len + 1);
  std::vector<int> v(len);
  auto at = [&](int line, int i) {
    return gaps_along_x ? static_cast<size_t>(i) * w + line : static_cast<size_t>(line) * w + i;
  };
  for (int line = 0; line < lines; ++line)
  {
    for (int i = 0; i < len; ++i)  // the 3-wide min filter
    {
      double m = d2[at(line, i)];
      if (i > 0) m = std::min(m, d2[at(line, i - 1)]);
      if (i + 1 < len) m = std::min(m, d2[at(line, i + 1)]);
      in[i] = m;
    }
    mbot_common::squaredDistanceTransform1d(in.data(), len, out.data(), v.data(), z.data());
    for (int i = 0; i < len; ++i) d2[at(line, i)] = out[i];
  }
}

/// Squared clearances [cells^2] -> stored map [quarter cells], rounded down after the margin.
std::vector<uint8_t> quantizeClearance(const std::vector<double>& d2)
{
  std::vector<uint8_t> units(d2.size());
  for (size_t i = 0; i < d2.size(); ++i)
  {
    const double u = std::floor((std::sqrt(d2[i]) - kClearanceMargin) / kClearanceUnit);
    units[i] = static_cast<uint8_t>(std::clamp(u, 0.0, static_cast<double>(kClearanceMaxUnits)));
  }
  return units;
}

std::vector<uint8_t> clearanceMap(const std::vector<uint8_t>& occupied, int w, int h, bool along_x, Look look)
{
  std::vector<double> d2 = lineGaps(occupied, w, h, along_x, look);
  spreadAcrossLines(d2, w, h, along_x);
  return quantizeClearance(d2);
}
}  // namespace

void GridRaycaster::computeClearance()
{
  const int w = static_cast<int>(size_x_);
  const int h = static_cast<int>(size_y_);
  if (occupied_.empty()) return;  // an empty grid: every ray reads max range, no map needed
  const std::vector<uint8_t> right = clearanceMap(occupied_, w, h, true, Look::kAhead);
  const std::vector<uint8_t> left = clearanceMap(occupied_, w, h, true, Look::kBehind);
  const std::vector<uint8_t> up = clearanceMap(occupied_, w, h, false, Look::kAhead);
  const std::vector<uint8_t> down = clearanceMap(occupied_, w, h, false, Look::kBehind);
  // Every occupied cell is at or right of C, or at or left of it: the nearest of all is the
  // nearer of the two.
  clearance_.resize(occupied_.size());
  for (size_t i = 0; i < occupied_.size(); ++i) clearance_[i] = std::min(right[i], left[i]);
  const std::vector<uint8_t>* horizontal[4] = {&right, &left, &right, &left};  // bit 0: dir_x < 0
  const std::vector<uint8_t>* vertical[4] = {&up, &up, &down, &down};          // bit 1: dir_y < 0
  // The quadrant maps get a border of one free cell all around (stride w + 2), which lets the
  // tracer skip bounds checks (see longSteps). A free cell is at least kWallCell + 1.
  for (int q = 0; q < 4; ++q)
  {
    std::vector<uint8_t>& map = quadrant_clearance_[q];
    map.assign(static_cast<size_t>(w + 2) * (h + 2), kWallCell + 1);
    for (int y = 0; y < h; ++y)
      for (int x = 0; x < w; ++x)
      {
        const size_t i = static_cast<size_t>(y) * w + x;
        const uint8_t c = std::max((*horizontal[q])[i], (*vertical[q])[i]);
        map[static_cast<size_t>(y + 1) * (w + 2) + x + 1] =
            occupied_[i] ? kWallCell : std::max<uint8_t>(c, kWallCell + 1);
      }
  }
}

// ---------------------------------------------------------------------------------------------
// Tracing rays through the cells
//
// A ray alternates between two modes:
//
// 1. Long steps ("sphere tracing"). The clearance c of the current cell says no wall the ray
//    could meet is within c of any point of that cell, so the ray may jump c at once without
//    missing a wall. In open space c is large and an 8 m ray needs only a few jumps;
//    approaching a wall, c shrinks with the distance to it.
// 2. Cell walk (Amanatides & Woo, "A Fast Voxel Traversal Algorithm", 1987). Right next to a
//    wall the clearance is 0, so the ray visits the cells it crosses one by one, in order, and
//    stops at the first occupied one. The distance returned is where the ray crosses that
//    cell's boundary, computed from the ray's origin, so it is exact no matter how the ray got
//    there. Once the walk reaches a cell far enough from the walls, it goes back to jumping.
//
// Units: cells. The grid is [0, w] x [0, h], cell (i, j) is [i, i+1] x [j, j+1], a ray is
// p + t * u for t up to t_end: the max range, or where the ray leaves the grid if sooner.
// ---------------------------------------------------------------------------------------------
namespace
{
/// The maps the tracer reads: the quadrant clearance maps, walls marked kWallCell, each with a
/// border of one free cell around the grid (see longSteps for why).
struct CellMaps
{
  /// Per quadrant, where cell (0, 0) is: cell (cx, cy) is at cell00[q][cy * stride + cx], for
  /// -1 <= cx <= w, -1 <= cy <= h (the border included). Indexing from cell (0, 0) rather than
  /// from the border's corner saves two additions per cell looked at.
  const uint8_t* cell00[4];
  ptrdiff_t stride;  ///< w + 2
  int w;
  int h;
};

/// The clearance map of the quadrant a direction heads into (bit 0: u_x < 0, bit 1: u_y < 0).
inline int quadrantOf(double ux, double uy) { return (ux < 0.0 ? 1 : 0) | (uy < 0.0 ? 2 : 0); }

/// A ray and its per-ray constants [cells].
struct Ray
{
  double px, py;          ///< origin
  double ux, uy;          ///< unit direction (never -0.0: see makeRay)
  double inv_ux, inv_uy;  ///< 1 / u (+Inf for a zero component: never crosses on that axis)
  double t_end;           ///< the max range, or where the ray leaves the grid if sooner
  const uint8_t* map;     ///< cell (0, 0) of the clearance map of the ray's direction quadrant
};

/// The ray p + t u, t <= t_max. p may be outside the grid (the caller then starts the ray
/// where it enters); t_end is cut where the ray leaves the grid.
inline Ray makeRay(const CellMaps& m, double px, double py, double ux, double uy, double t_max)
{
  // -0.0 + 0.0 is +0.0: a zero component then has 1 / u = +Inf, so that the cell walk, which
  // goes by the sign of 1 / u, never crosses on that axis, and t_end below ignores that axis.
  ux += 0.0;
  uy += 0.0;
  Ray r{px, py, ux, uy, 1.0 / ux, 1.0 / uy, t_max, m.cell00[quadrantOf(ux, uy)]};
  // Where the ray leaves the grid on each axis (+Inf for a zero component; written with
  // selects and min, no branches: this runs for every beam).
  r.t_end = std::min(r.t_end, (r.inv_ux > 0.0 ? m.w - px : -px) * r.inv_ux);
  r.t_end = std::min(r.t_end, (r.inv_uy > 0.0 ? m.h - py : -py) * r.inv_uy);
  return r;
}

/// Where a ray is: at parameter t, in cell (cx, cy).
struct RayPosition
{
  double t;
  int cx, cy;
  bool finished;  ///< reached t_end without a hit
};

/// The cell holding coordinate v [cells] of a point, or the cell just behind it when v is
/// within rounding of a boundary (behind = against the direction component u). Rays must only
/// be placed in their true cell or behind it: a cell ahead could make a quadrant map ignore a
/// wall the ray can still meet, and would make the cell walk skip the true cell, whereas from
/// a cell behind the walk simply crosses into the true one at once.
inline int cellBehind(double v, double u)
{
  return static_cast<int>(std::floor(v - (u > 0.0 ? 1e-9 : u < 0.0 ? -1e-9 : 0.0)));
}

// Long steps track the ray's position in fixed point, 32 integer + 32 fractional bits [cells],
// kept a little behind the true position (kFixedBehind): the rounding of the start and the
// moves (truncated towards zero) then never puts it in a cell ahead of the ray, and it stays
// far closer to the ray than the clearance margin.
constexpr int64_t kFixedBehind = int64_t{1} << 12;  // 2^-20 cells
// Beams whose long steps are interleaved, and for how many steps at most (see
// LongSteps::runGroup). Most rays need at most 6 steps; groups of 2 to 8 and 4 to 99 steps
// measured within noise of each other in the benchmark room.
constexpr int kGroup = 4;
constexpr int kLockstepSteps = 6;

/// Coordinate v [cells] in fixed point, moved a hair behind along direction component u.
inline int64_t toFixedBehind(double v, double u)
{
  return static_cast<int64_t>(v * kFixedOne) - (u > 0.0 ? kFixedBehind : u < 0.0 ? -kFixedBehind : 0);
}

/// A ray during its long steps. Position in fixed point: the cell of a point is then a shift,
/// not a float-to-int conversion, on the chain of memory reads every step waits for. The
/// distance travelled is counted in whole clearance units, and each step is cut to the units
/// left (`room`: up to t_end, plus one), so a ray stops at most a quarter cell past t_end.
/// Until t_end it is inside the grid, so it is never more than a hair outside, in the maps'
/// border (whose free cells stop the long steps): no bounds checks are needed.
struct LongSteps
{
  int64_t fx, fy;          ///< position, a hair behind the ray [cells, 32.32 fixed point]
  int64_t move_x, move_y;  ///< one clearance unit along the ray, in fixed point
  int64_t room;            ///< units left: 0 once the ray is past t_end

  /// One long step: returns the units moved, 0 when next to a wall (clearance below
  /// kMinLongStep) or out of room. Selects, no branches.
  int64_t step(const uint8_t* map, ptrdiff_t stride)
  {
    const int64_t c = map[(fy >> kFixedShift) * stride + (fx >> kFixedShift)];
    const int64_t units = c >= kMinLongStep ? std::min(c, room) : 0;
    fx += units * move_x;
    fy += units * move_y;
    room -= units;
    return units;
  }

  /// Long steps until next to a wall or out of room.
  void run(const uint8_t* map, ptrdiff_t stride)
  {
    while (step(map, stride) != 0)
    {}
  }

  /// run() for N rays at once. Each step needs the clearance of the cell the previous step
  /// landed in, so one ray is a chain of memory reads that each wait for the one before;
  /// stepping a few independent rays in turn lets the processor overlap those waits. A ray
  /// that has stopped takes steps of 0 until the others stop too, for at most kLockstepSteps
  /// steps: the few rays that need many more (running almost along a wall) go on alone.
  template <int N, typename RayT>
  static void runGroup(const RayT* rays, LongSteps* s, ptrdiff_t stride)
  {
    for (int iteration = 0; iteration < kLockstepSteps; ++iteration)
    {
      int64_t moved = 0;
      for (int k = 0; k < N; ++k) moved |= s[k].step(rays[k].map, stride);
      if (moved == 0) return;
    }
    for (int k = 0; k < N; ++k) s[k].run(rays[k].map, stride);
  }
};

/// Long steps for ray r from pos, whose cell has a clearance of at least kMinLongStep.
/// Afterwards the ray is either next to a wall (to be walked) or finished.
inline void longSteps(const Ray& r, ptrdiff_t stride, RayPosition& pos)
{
  // The first jump, from anywhere in the cell: in floating point, since pos may lie right on
  // the cell's boundary, where the fixed point could fall into the cell behind.
  const unsigned c = r.map[pos.cy * stride + pos.cx];
  const double t0 = pos.t + c * kClearanceUnit;
  const int64_t room0 = t0 <= r.t_end ? static_cast<int64_t>((r.t_end - t0) * (1.0 / kClearanceUnit)) + 1 : 0;
  LongSteps s{toFixedBehind(r.px + t0 * r.ux, r.ux), toFixedBehind(r.py + t0 * r.uy, r.uy),
              static_cast<int64_t>(r.ux * kClearanceUnit * kFixedOne),
              static_cast<int64_t>(r.uy * kClearanceUnit * kFixedOne), room0};
  s.run(r.map, stride);
  pos.finished = s.room == 0;
  pos.t = t0 + (room0 - s.room) * kClearanceUnit;
  pos.cx = static_cast<int>(s.fx >> kFixedShift);
  pos.cy = static_cast<int>(s.fy >> kFixedShift);
}

/// The exact cell walk of ray r from pos (not in a wall; in the border at worst). Returns true
/// with `t_hit` = the t of the first occupied cell's boundary, or t_end when there is none
/// before; false when the ray reached open space again first: pos is then that cell's entry,
/// from where long steps go on.
inline bool walkCells(const Ray& r, ptrdiff_t stride, RayPosition& pos, double& t_hit)
{
  // The walk moves a map index: one cell along x is +-1, along y +-stride. Directions go by the
  // sign of 1 / u, which is +Inf for a zero component (see makeRay): never crossed.
  const bool right = r.inv_ux > 0.0;
  const bool up = r.inv_uy > 0.0;
  const double delta_x = std::abs(r.inv_ux);  // t between two vertical boundaries
  const double delta_y = std::abs(r.inv_uy);  // t between two horizontal boundaries
  double t = pos.t;
  int cx = pos.cx;
  int cy = pos.cy;
  // Ray parameter of the next vertical (x) and horizontal (y) cell boundary.
  double next_x = (cx + (right ? 1 : 0) - r.px) * r.inv_ux;
  double next_y = (cy + (up ? 1 : 0) - r.py) * r.inv_uy;
  // Placed a cell behind (see cellBehind), the ray is already past that boundary: move the cell
  // up without moving t (for a ray almost parallel to the boundary, the crossing lies far back
  // along the line).
  if (next_x < t || next_y < t)
  {
    if (next_x < t)
    {
      cx += right ? 1 : -1;
      next_x += delta_x;
    }
    if (next_y < t)
    {
      cy += up ? 1 : -1;
      next_y += delta_y;
    }
    if (r.map[cy * stride + cx] == kWallCell)
    {
      t_hit = t;
      return true;
    }
  }
  const ptrdiff_t index_step_x = right ? 1 : -1;
  const ptrdiff_t index_step_y = up ? stride : -stride;
  ptrdiff_t cell = cy * stride + cx;
  for (;;)
  {
    // Cross into the next cell through whichever boundary comes first. Written as selects
    // rather than if/else: the choice is close to random, so a branch would often be
    // mispredicted, which costs more than computing both.
    const bool cross_x = next_x < next_y;
    t = cross_x ? next_x : next_y;
    // Before t_end the ray is inside the grid, and the walk at worst one cell behind it, in
    // the border: the cell index needs no bounds check.
    if (t >= r.t_end)
    {
      t_hit = r.t_end;
      return true;
    }
    next_x += cross_x ? delta_x : 0.0;
    next_y += cross_x ? 0.0 : delta_y;
    cell += cross_x ? index_step_x : index_step_y;
    const unsigned c = r.map[cell];
    if (c == kWallCell)
    {
      t_hit = t;
      return true;
    }
    if (c >= kResumeLongSteps) break;  // open space again
  }
  // (Rare: the cell's coordinates from its index, counted from the border's corner.)
  const ptrdiff_t from_corner = cell + stride + 1;
  pos = RayPosition{t, static_cast<int>(from_corner % stride) - 1, static_cast<int>(from_corner / stride) - 1, false};
  return false;
}

/// Trace ray r from pos (not in a wall; in the border at worst) to the end: the t of the first
/// occupied cell's boundary, or t_end when there is none.
inline double traceRay(const Ray& r, ptrdiff_t stride, RayPosition pos)
{
  for (;;)
  {
    if (r.map[pos.cy * stride + pos.cx] >= kMinLongStep)
    {
      longSteps(r, stride, pos);
      if (pos.finished) return r.t_end;
    }
    double t_hit;
    if (walkCells(r, stride, pos, t_hit)) return t_hit;
  }
}
}  // namespace

double GridRaycaster::cast(double x, double y, double theta, double max_range) const
{
  return castDirection(x, y, std::cos(theta), std::sin(theta), max_range);
}

double GridRaycaster::castDirection(double x, double y, double dir_x, double dir_y, double max_range) const
{
  double range = max_range;
  castFan(x, y, &dir_x, &dir_y, 1, max_range, &range);
  return range;
}

void GridRaycaster::castFan(double x, double y, const double* dir_x, const double* dir_y, int n, double max_range,
                            double* ranges) const
{
  if (!(max_range > 0.0) || occupied_.empty() || !std::isfinite(x) || !std::isfinite(y))
  {
    std::fill(ranges, ranges + n, max_range);
    return;
  }
  // Directions must be finite: they become cell indices.
  for (int i = 0; i < n; ++i)
    if (!std::isfinite(dir_x[i]) || !std::isfinite(dir_y[i]))
      throw std::invalid_argument("GridRaycaster: ray direction " + std::to_string(i) + " is not finite");
  const ptrdiff_t stride = static_cast<ptrdiff_t>(size_x_) + 2;
  CellMaps maps;
  for (int q = 0; q < 4; ++q) maps.cell00[q] = quadrant_clearance_[q].data() + stride + 1;
  maps.stride = stride;
  maps.w = static_cast<int>(size_x_);
  maps.h = static_cast<int>(size_y_);
  const double px = (x - origin_x_) * inv_resolution_;  // [cells]
  const double py = (y - origin_y_) * inv_resolution_;
  const double t_max = max_range * inv_resolution_;
  auto toRange = [&](double t_hit, const Ray& r) {
    return selectNoBranch<double, uint64_t>(t_hit < r.t_end, t_hit * resolution_, max_range);
  };

  if (px >= 0.0 && py >= 0.0 && px < maps.w && py < maps.h)
  {
    // The usual case, a sensor inside the grid. Every beam starts in the sensor's cell, so
    // what depends only on that cell is looked up once per scan: its clearance in each
    // quadrant (the first long step of every beam), and the sensor in fixed point.
    const int cx = static_cast<int>(px);
    const int cy = static_cast<int>(py);
    if (occupied_[static_cast<size_t>(cy) * size_x_ + cx])
    {
      std::fill(ranges, ranges + n, 0.0);  // the sensor is inside a wall
      return;
    }
    int64_t first_jump[4];
    for (int q = 0; q < 4; ++q)
    {
      const int64_t c = maps.cell00[q][cy * stride + cx];
      first_jump[q] = c >= kMinLongStep ? c : 0;  // (next to a wall: none)
    }
    const int64_t fx0 = static_cast<int64_t>(px * kFixedOne);  // exact: px >= 0, times 2^32
    const int64_t fy0 = static_cast<int64_t>(py * kFixedOne);
    // Beams go in groups of kGroup, whose long steps are interleaved (see LongSteps::run).
    for (int i0 = 0; i0 < n; i0 += kGroup)
    {
      const int count = std::min(kGroup, n - i0);
      Ray rays[kGroup];
      LongSteps steps[kGroup];
      int64_t room0[kGroup];
      for (int k = 0; k < count; ++k)
      {
        const Ray& r = rays[k] = makeRay(maps, px, py, dir_x[i0 + k], dir_y[i0 + k], t_max);
        // The first long step, from anywhere in the sensor's cell: the sensor point moved by
        // first_jump units (cut short by t_end only), kept a hair behind the ray.
        room0[k] = static_cast<int64_t>(r.t_end * (1.0 / kClearanceUnit)) + 1;
        const int64_t first = std::min(first_jump[quadrantOf(r.ux, r.uy)], room0[k]);
        LongSteps& s = steps[k];
        s.move_x = static_cast<int64_t>(r.ux * kClearanceUnit * kFixedOne);
        s.move_y = static_cast<int64_t>(r.uy * kClearanceUnit * kFixedOne);
        s.fx = fx0 + first * s.move_x - (r.ux > 0.0 ? kFixedBehind : r.ux < 0.0 ? -kFixedBehind : 0);
        s.fy = fy0 + first * s.move_y - (r.uy > 0.0 ? kFixedBehind : r.uy < 0.0 ? -kFixedBehind : 0);
        s.room = room0[k] - first;
      }
      if (count == kGroup)
        LongSteps::runGroup<kGroup>(rays, steps, stride);
      else
        for (int k = 0; k < count; ++k) steps[k].run(rays[k].map, stride);
      for (int k = 0; k < count; ++k)
      {
        const Ray& r = rays[k];
        const LongSteps& s = steps[k];
        if (s.room == 0)
        {
          ranges[i0 + k] = max_range;  // past t_end without meeting a wall
          continue;
        }
        // Next to a wall: the exact walk (and, rarely, more long steps after it).
        RayPosition pos{(room0[k] - s.room) * kClearanceUnit, static_cast<int>(s.fx >> kFixedShift),
                        static_cast<int>(s.fy >> kFixedShift), false};
        double t_hit;
        if (!walkCells(r, stride, pos, t_hit)) t_hit = traceRay(r, stride, pos);
        ranges[i0 + k] = toRange(t_hit, r);
      }
    }
    return;
  }
  // A sensor outside the grid (which counts as free): a ray starts where it enters the grid.
  for (int i = 0; i < n; ++i)
  {
    const Ray r = makeRay(maps, px, py, dir_x[i], dir_y[i], t_max);
    // The entry: the last of the two slab entries (a zero component never leaves its slab).
    double t_start = 0.0;
    if (r.ux != 0.0)
      t_start = std::max(t_start, ((r.ux > 0.0 ? 0 : maps.w) - px) * r.inv_ux);
    else if (px < 0.0 || px > maps.w)
      t_start = kInf;
    if (r.uy != 0.0)
      t_start = std::max(t_start, ((r.uy > 0.0 ? 0 : maps.h) - py) * r.inv_uy);
    else if (py < 0.0 || py > maps.h)
      t_start = kInf;
    if (!(t_start <= r.t_end))
    {
      ranges[i] = max_range;  // misses the grid, or enters it beyond max range
      continue;
    }
    // The entry point lies on the grid's edge: its cell "behind" is the border cell outside,
    // a free cell from which the walk crosses into the grid at t_start, where a wall cell is
    // hit at once.
    const RayPosition start{t_start, std::clamp(cellBehind(px + t_start * r.ux, r.ux), -1, maps.w),
                            std::clamp(cellBehind(py + t_start * r.uy, r.uy), -1, maps.h), false};
    ranges[i] = toRange(traceRay(r, stride, start), r);
  }
}

bool GridRaycaster::occupiedAt(double x, double y) const
{
  const double fx = std::floor((x - origin_x_) * inv_resolution_);
  const double fy = std::floor((y - origin_y_) * inv_resolution_);
  if (fx < 0.0 || fy < 0.0 || fx >= size_x_ || fy >= size_y_) return false;
  return occupied_[static_cast<size_t>(fy) * size_x_ + static_cast<size_t>(fx)] != 0;
}

double GridRaycaster::clearanceAt(double x, double y) const
{
  const double fx = std::floor((x - origin_x_) * inv_resolution_);
  const double fy = std::floor((y - origin_y_) * inv_resolution_);
  if (fx < 0.0 || fy < 0.0 || fx >= size_x_ || fy >= size_y_) return 0.0;
  const size_t idx = static_cast<size_t>(fy) * size_x_ + static_cast<size_t>(fx);
  return clearance_[idx] * kClearanceUnit * resolution_;
}

double GridRaycaster::clearanceAlong(double x, double y, double dir_x, double dir_y) const
{
  const double fx = std::floor((x - origin_x_) * inv_resolution_);
  const double fy = std::floor((y - origin_y_) * inv_resolution_);
  if (fx < 0.0 || fy < 0.0 || fx >= size_x_ || fy >= size_y_) return 0.0;
  const size_t idx = (static_cast<size_t>(fy) + 1) * (size_x_ + 2) + static_cast<size_t>(fx) + 1;
  const int quadrant = (dir_x < 0.0 ? 1 : 0) | (dir_y < 0.0 ? 2 : 0);
  const unsigned c = quadrant_clearance_[quadrant][idx];
  return c < kMinLongStep ? 0.0 : c * kClearanceUnit * resolution_;  // (1, 2: free, next to a wall)
}

}  // namespace mbot_sim
