/**
 * @file raycast.cpp
 * @brief Laser ray casting: grid walls by clearance-map stepping + exact cell walk, shapes by
 *        an angular sweep over the beams each shape covers.
 */
#include "mbot_sim/raycast.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <limits>
#include <stdexcept>
#include <string>

namespace mbot_sim
{
namespace
{
constexpr double kPi = 3.14159265358979323846;
constexpr double kTwoPi = 2.0 * kPi;
constexpr double kInf = std::numeric_limits<double>::infinity();

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

/// Squared 1D distance transform (Felzenszwalb & Huttenlocher, "Distance Transforms of Sampled
/// Functions", 2012): d[q] = min_p (q - p)^2 + f[p], in O(n). v, z are scratch of size n, n + 1.
void distanceTransform1d(const double* f, int n, double* d, int* v, double* z)
{
  int k = 0;
  v[0] = 0;
  z[0] = -kInf;
  z[1] = kInf;
  for (int q = 1; q < n; ++q)
  {
    double s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
    while (s <= z[k])
    {
      --k;
      s = ((f[q] + double(q) * q) - (f[v[k]] + double(v[k]) * v[k])) / (2.0 * (q - v[k]));
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = kInf;
  }
  k = 0;
  for (int q = 0; q < n; ++q)
  {
    while (z[k + 1] < q) ++k;
    d[q] = (double(q) - v[k]) * (double(q) - v[k]) + f[v[k]];
  }
}

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
    distanceTransform1d(in.data(), len, out.data(), v.data(), z.data());
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
// Wall faces for the angular sweep
//
// The walls a laser can see are the edges between a free and an occupied cell. Along one grid
// line, neighbouring edges with the occupied cell on the same side merge into one face, so a
// straight wall of any length is one face per side. A face remembers which way its free side
// looks: a sensor can only see it from that side (from behind, the face is inside the wall).
// Cells outside the grid count as free, like in the ray tracing, but no face is made on the
// grid's edge: a sensor outside the grid uses the ray tracing.
//
// Faces are bucketed in square tiles so a scan only looks at the faces in range.
// ---------------------------------------------------------------------------------------------
namespace
{
// Tile side [cells]: 3.2 m at 0.05 m cells. A scan visits the tiles within range and then
// culls faces one by one; smaller tiles cull fewer faces per tile but cost more tiles to visit
// and more copies of long faces (measured in the benchmark room: 64 cells take 8% fewer
// instructions per ray than 32).
constexpr int kTileCells = 64;

// Sides of a face, named by where its free side looks; which way rays hitting it move.
enum FaceSide : int
{
  kFreeMinusX = 0,  ///< vertical face, occupied cell on its right: hit by rays moving +x
  kFreePlusX = 1,   ///< vertical face, occupied cell on its left: hit by rays moving -x
  kFreeMinusY = 2,  ///< horizontal face, occupied cell above: hit by rays moving +y
  kFreePlusY = 3,   ///< horizontal face, occupied cell below: hit by rays moving -y
};

using WallFace = GridRaycaster::WallFace;

/// Merge the cell edges along one grid line into faces: edge_at(k) tells whether the edge
/// [k, k + 1] is a face of this side.
template <typename EdgeAt>
void appendRuns(int line, int length, EdgeAt&& edge_at, std::vector<WallFace>& out)
{
  int start = -1;
  for (int k = 0; k <= length; ++k)
  {
    const bool edge = k < length && edge_at(k);
    if (edge && start < 0) start = k;
    if (!edge && start >= 0)
    {
      out.push_back(WallFace{line, start, k, 0});
      start = -1;
    }
  }
}
}  // namespace

void GridRaycaster::extractWallFaces()
{
  const int w = static_cast<int>(size_x_);
  const int h = static_cast<int>(size_y_);
  auto occ = [&](int x, int y) { return occupied_[static_cast<size_t>(y) * w + x] != 0; };
  std::vector<WallFace> faces[4];
  for (int x = 1; x < w; ++x)  // vertical grid lines inside the grid
  {
    appendRuns(
        x, h, [&](int y) { return !occ(x - 1, y) && occ(x, y); }, faces[kFreeMinusX]);
    appendRuns(
        x, h, [&](int y) { return occ(x - 1, y) && !occ(x, y); }, faces[kFreePlusX]);
  }
  for (int y = 1; y < h; ++y)  // horizontal grid lines
  {
    appendRuns(
        y, w, [&](int x) { return !occ(x, y - 1) && occ(x, y); }, faces[kFreeMinusY]);
    appendRuns(
        y, w, [&](int x) { return occ(x, y - 1) && !occ(x, y); }, faces[kFreePlusY]);
  }

  // Bucket by tile: a face lies on its line's tile column (row) and is copied into every tile
  // its span crosses; copies share an id so that a scan uses each face once.
  tiles_x_ = (w + kTileCells - 1) / kTileCells;
  tiles_y_ = (h + kTileCells - 1) / kTileCells;
  std::vector<std::vector<WallFace>> buckets(static_cast<size_t>(tiles_x_) * tiles_y_ * 4);
  uint32_t id = 0;
  for (int side = 0; side < 4; ++side)
  {
    const bool vertical = side == kFreeMinusX || side == kFreePlusX;
    for (WallFace f : faces[side])
    {
      f.id = id++;
      const int across = f.line / kTileCells;
      for (int along = f.lo / kTileCells; along <= (f.hi - 1) / kTileCells; ++along)
      {
        const int tx = vertical ? across : along;
        const int ty = vertical ? along : across;
        buckets[(static_cast<size_t>(ty) * tiles_x_ + tx) * 4 + side].push_back(f);
      }
    }
  }
  wall_face_count_ = id;
  tile_faces_.clear();
  tile_start_.assign(1, 0);
  for (const std::vector<WallFace>& b : buckets)
  {
    tile_faces_.insert(tile_faces_.end(), b.begin(), b.end());
    tile_start_.push_back(static_cast<uint32_t>(tile_faces_.size()));
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

// =============================================================================================
// ShapeSet
// =============================================================================================

ShapeSet::ShapeSet(double bucket_size) : bucket_size_(bucket_size)
{
  if (!(bucket_size > 0.0))
    throw std::invalid_argument("ShapeSet: bucket_size must be > 0 [m], got " + std::to_string(bucket_size));
}

void ShapeSet::clear()
{
  for (auto& kv : buckets_)
  {
    kv.second.circles.clear();
    kv.second.boxes.clear();
  }
  count_ = 0;
  max_extent_ = 0.0;
}

int64_t ShapeSet::bucketIndex(double v) const { return static_cast<int64_t>(std::floor(v / bucket_size_)); }

namespace
{
/// One key for a bucket (bx, by): the low 32 bits of each index, side by side.
inline int64_t packBucketKey(int64_t bx, int64_t by)
{
  const uint64_t key = (static_cast<uint64_t>(bx) << 32) | (static_cast<uint64_t>(by) & 0xffffffffu);
  return static_cast<int64_t>(key);
}
}  // namespace

ShapeSet::Bucket& ShapeSet::bucketAt(double x, double y)
{
  return buckets_[packBucketKey(bucketIndex(x), bucketIndex(y))];
}

const ShapeSet::Bucket* ShapeSet::findBucket(int64_t bx, int64_t by) const
{
  const auto it = buckets_.find(packBucketKey(bx, by));
  return it == buckets_.end() ? nullptr : &it->second;
}

void ShapeSet::addCircle(const Circle& c)
{
  if (!std::isfinite(c.x) || !std::isfinite(c.y) || !(c.radius >= 0.0) || !std::isfinite(c.radius))
    throw std::invalid_argument("ShapeSet::addCircle: x, y must be finite and radius >= 0 [m]");
  bucketAt(c.x, c.y).circles.push_back(c);
  max_extent_ = std::max(max_extent_, c.radius);
  ++count_;
}

void ShapeSet::addBox(const OrientedBox& b)
{
  if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.yaw) || !(b.half_length >= 0.0) ||
      !(b.half_width >= 0.0) || !std::isfinite(b.half_length) || !std::isfinite(b.half_width))
    throw std::invalid_argument("ShapeSet::addBox: x, y, yaw must be finite and half sizes >= 0 [m]");
  PreparedBox p;
  p.box = b;
  p.cos_yaw = std::cos(b.yaw);
  p.sin_yaw = std::sin(b.yaw);
  bucketAt(b.x, b.y).boxes.push_back(p);
  max_extent_ = std::max(max_extent_, std::hypot(b.half_length, b.half_width));
  ++count_;
}

size_t ShapeSet::size() const { return count_; }

// =============================================================================================
// castScan
// =============================================================================================

namespace
{
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

// =============================================================================================
// Wall sweep: a whole scan against the walls, face by face
//
// Instead of tracing each beam through the cells, look at each wall face in range once: from
// the sensor it covers an interval of bearings, and only the beams inside it can hit it. The
// beams' angles are regular, so those beams are an index range computed directly. For each
// of them the exact distance to the face is computed, and each beam keeps the nearest (an
// angular z-buffer). A scan then costs a few tests per face and per beam, with no chains of
// memory reads as in the cell walk.
//
// Same answers as the walk: the distance to a face on the line x = X is t = (X - px) / u_x, the
// formula of the walk's boundary crossings, and whether the beam meets the face there is decided
// by comparing crossing parameters t like the walk does, including its tie rule: at a cell
// corner (a beam through it exactly) the walk crosses the row boundary before the column one.
// So a vertical face [lo, hi] is met when t(y = lo or hi, whichever comes first) <= t < t(the
// other), a horizontal one when t(x first) < t <= t(x other). Units are cells, like the walk.
// =============================================================================================
namespace
{
// kAuto uses the walk when the tiles in range hold more faces than this per beam: in a maze
// of small blobs (a cave) a beam walks only a few cells, which is cheaper than visiting all
// the faces around. Measured on 16 x 16 m cave maps of varying density (360 beams, 8 m): the
// two take the same time at about 4 faces per beam (at 2.4 the sweep takes 0.8 times the
// walk's time, at 5.2 1.2 times, at 23 4 times); the benchmark room has 1 face per beam.
constexpr double kSweepMaxFacesPerBeam = 4.0;
// Bearings come from approxAtan2 (error kApproxAtan2Error per end): widen a face's interval
// by that much on both sides; the exact test decides for every beam inside.
constexpr double kFacePad = 2.0 * kApproxAtan2Error;

/// Reused between scans (per thread), so that a scan allocates nothing.
struct SweepScratch
{
  std::vector<double> inv_x;  ///< per beam, 1 / direction (+Inf for a zero component)
  std::vector<double> inv_y;
  std::vector<double> t_end;   ///< per beam, max range or where it leaves the grid [cells]
  std::vector<double> best;    ///< per beam, nearest hit so far, or t_end [cells]
  std::vector<uint32_t> seen;  ///< per face id: the last scan that swept it (copies in tiles)
  uint32_t scan = 0;

  /// Start a new scan: a face is swept once even when it lies in several tiles.
  void nextScan(size_t faces)
  {
    if (seen.size() < faces) seen.resize(faces, 0);
    if (++scan == 0)  // wrapped around: forget all stamps
    {
      std::fill(seen.begin(), seen.end(), 0);
      scan = 1;
    }
  }
};

/// One scan's sweep [cells].
struct WallScan
{
  double px, py;  ///< sensor, strictly inside a free cell
  double t_max2;  ///< (max range)^2, with a hair of slack
  const BeamFan& fan;
  const double* inv_x;
  const double* inv_y;
  double* best;
};

/// Shorten the beams that hit face f, of side kSide (a FaceSide). The sensor is on f's free
/// side. Written once for all four sides: `across` is the coordinate across the face, `to_lo`
/// and `to_hi` those of its ends along it, from the sensor [cells].
template <int kSide>
void sweepFace(const WallScan& s, const WallFace& f)
{
  constexpr bool kVertical = kSide == kFreeMinusX || kSide == kFreePlusX;
  const double across = f.line - (kVertical ? s.px : s.py);  // never 0: sensor not on a line
  const double to_lo = f.lo - (kVertical ? s.py : s.px);
  const double to_hi = f.hi - (kVertical ? s.py : s.px);
  const double along = std::max(std::max(to_lo, -to_hi), 0.0);
  if (across * across + along * along > s.t_max2) return;  // the nearest point of the face is out of range
  // Bearings of the face's ends relative to looking straight at the face: in (-pi/2, pi/2)
  // and in order, so the interval never wraps around. Then turned into world bearings.
  const double rel_lo = approxAtan2(to_lo, std::abs(across));
  const double rel_hi = approxAtan2(to_hi, std::abs(across));
  double lo = rel_lo;  // kFreeMinusX: the beams hitting it head along +x (bearing 0)
  double hi = rel_hi;
  if (kSide == kFreePlusX)  // along -x: bearing pi - rel
  {
    lo = kPi - rel_hi;
    hi = kPi - rel_lo;
  }
  else if (kSide == kFreeMinusY)  // along +y: bearing pi/2 - rel
  {
    lo = 0.5 * kPi - rel_hi;
    hi = 0.5 * kPi - rel_lo;
  }
  else if (kSide == kFreePlusY)  // along -y: bearing -pi/2 + rel
  {
    lo = -0.5 * kPi + rel_lo;
    hi = -0.5 * kPi + rel_hi;
  }
  lo -= kFacePad;
  hi += kFacePad;
  const double* inv_a = kVertical ? s.inv_x : s.inv_y;
  const double* inv_b = kVertical ? s.inv_y : s.inv_x;
  forEachBeamBetween(s.fan, lo, hi, [&](int i) {
    const double t = across * inv_a[i];       // where the beam crosses the face's line
    if (!(t > 0.0 && t < s.best[i])) return;  // moving away from it, or a nearer hit already
    const double t_lo = to_lo * inv_b[i];     // where it passes the face's ends (along b)
    const double t_hi = to_hi * inv_b[i];
    const double enter = std::min(t_lo, t_hi);
    const double leave = std::max(t_lo, t_hi);
    // The walk's tie rule (see above): rows before columns.
    const bool on_face = kVertical ? (enter <= t && t < leave) : (enter < t && t <= leave);
    if (on_face) s.best[i] = t;
  });
}

/// Whether a face of this side on grid line `line` can be seen from (px, py) [cells]: only
/// from its free side (from behind, it is inside the wall).
inline bool facesSensor(int side, double line, double px, double py)
{
  switch (side)
  {
    case kFreeMinusX: return px < line;
    case kFreePlusX: return px > line;
    case kFreeMinusY: return py < line;
    default: return py > line;
  }
}

/// Squared distance [cells^2] from (px, py) to the square tile (tx, ty), 0 inside.
inline double squaredDistanceToTile(int tx, int ty, double px, double py)
{
  const double dx = std::max({tx * kTileCells - px, px - (tx + 1) * kTileCells, 0.0});
  const double dy = std::max({ty * kTileCells - py, py - (ty + 1) * kTileCells, 0.0});
  return dx * dx + dy * dy;
}
}  // namespace

void GridRaycaster::castScanWalls(double x, double y, const double* dir_x, const double* dir_y, double first_angle,
                                  double increment, int n, double max_range, double* ranges, WallMethod method) const
{
  if (method != WallMethod::kGridWalk &&
      sweepWalls(x, y, dir_x, dir_y, first_angle, increment, n, max_range, ranges, method))
    return;
  castFan(x, y, dir_x, dir_y, n, max_range, ranges);
}

/// The sweep; false (nothing done) where the walk is to be used: odd cases the walk handles
/// (sensor outside the grid, in a wall or exactly on a grid line, where ties at t = 0 would
/// need the walk's rules for its starting cell), and, for kAuto, many faces in range.
bool GridRaycaster::sweepWalls(double x, double y, const double* dir_x, const double* dir_y, double first_angle,
                               double increment, int n, double max_range, double* ranges, WallMethod method) const
{
  if (n <= 0 || !(max_range > 0.0) || occupied_.empty() || !std::isfinite(x) || !std::isfinite(y) ||
      !std::isfinite(first_angle) || !std::isfinite(increment))
    return false;
  const double px = (x - origin_x_) * inv_resolution_;  // [cells], as in castFan
  const double py = (y - origin_y_) * inv_resolution_;
  const int w = static_cast<int>(size_x_);
  const int h = static_cast<int>(size_y_);
  if (!(px > 0.0 && py > 0.0 && px < w && py < h) || px == std::floor(px) || py == std::floor(py) ||
      occupied_[static_cast<size_t>(py) * size_x_ + static_cast<size_t>(px)])
    return false;
  const double t_max = max_range * inv_resolution_;

  // The tiles within range (clamped in double first: a huge range must not overflow an int).
  auto tileRange = [&](double p, int tiles, int& t0, int& t1) {
    t0 = static_cast<int>(std::clamp(std::floor((p - t_max) / kTileCells), 0.0, tiles - 1.0));
    t1 = static_cast<int>(std::clamp(std::floor((p + t_max) / kTileCells), 0.0, tiles - 1.0));
  };
  int tx0, tx1, ty0, ty1;
  tileRange(px, tiles_x_, tx0, tx1);
  tileRange(py, tiles_y_, ty0, ty1);
  if (method == WallMethod::kAuto)
  {
    size_t faces = 0;
    for (int ty = ty0; ty <= ty1; ++ty)
      faces += tile_start_[(static_cast<size_t>(ty) * tiles_x_ + tx1) * 4 + 4] -
               tile_start_[(static_cast<size_t>(ty) * tiles_x_ + tx0) * 4];
    if (faces > kSweepMaxFacesPerBeam * n) return false;
  }

  // ---- per beam: the walk's ray constants (see makeRay)
  thread_local SweepScratch thread_scratch;
  SweepScratch& scratch = thread_scratch;  // (one thread-local lookup, not one per use)
  scratch.inv_x.resize(n);
  scratch.inv_y.resize(n);
  scratch.t_end.resize(n);
  scratch.best.resize(n);
  double not_finite = 0.0;  // stays 0 unless a direction is Inf or NaN (then x * 0 is NaN)
  for (int i = 0; i < n; ++i)
  {
    not_finite += dir_x[i] * 0.0 + dir_y[i] * 0.0;
    const double ix = 1.0 / (dir_x[i] + 0.0);  // -0.0 + 0.0 = +0.0: 1 / u = +Inf
    const double iy = 1.0 / (dir_y[i] + 0.0);
    scratch.inv_x[i] = ix;
    scratch.inv_y[i] = iy;
    double t_end = std::min(t_max, (ix > 0.0 ? w - px : -px) * ix);
    t_end = std::min(t_end, (iy > 0.0 ? h - py : -py) * iy);
    scratch.t_end[i] = t_end;
    scratch.best[i] = t_end;
  }
  if (not_finite != 0.0) return false;  // castFan reports it
  scratch.nextScan(wall_face_count_);

  // ---- every face in range, seen from its free side, once
  const BeamFan fan(first_angle, increment, n);
  const WallScan scan{
      px, py, t_max * t_max * (1.0 + 1e-9), fan, scratch.inv_x.data(), scratch.inv_y.data(), scratch.best.data()};
  for (int ty = ty0; ty <= ty1; ++ty)
    for (int tx = tx0; tx <= tx1; ++tx)
    {
      if (squaredDistanceToTile(tx, ty, px, py) > scan.t_max2) continue;
      const size_t tile = (static_cast<size_t>(ty) * tiles_x_ + tx) * 4;
      for (int side = 0; side < 4; ++side)
      {
        // The tile's faces of this side lie on lines from the tile's low edge to its high
        // one: skip them all when the sensor is behind every such line.
        const bool vertical = side <= kFreePlusX;
        const int tile_lo = (vertical ? tx : ty) * kTileCells;
        if (!facesSensor(side, tile_lo, px, py) && !facesSensor(side, tile_lo + kTileCells, px, py)) continue;
        const WallFace* f = tile_faces_.data() + tile_start_[tile + side];
        const WallFace* const end = tile_faces_.data() + tile_start_[tile + side + 1];
        for (; f != end; ++f)
        {
          if (!facesSensor(side, f->line, px, py) || scratch.seen[f->id] == scratch.scan) continue;
          scratch.seen[f->id] = scratch.scan;
          switch (side)  // (one copy of sweepFace per side, each with its constants)
          {
            case kFreeMinusX: sweepFace<kFreeMinusX>(scan, *f); break;
            case kFreePlusX: sweepFace<kFreePlusX>(scan, *f); break;
            case kFreeMinusY: sweepFace<kFreeMinusY>(scan, *f); break;
            default: sweepFace<kFreePlusY>(scan, *f);
          }
        }
      }
    }

  // ---- ranges, as the walk reports them
  for (int i = 0; i < n; ++i)
    ranges[i] = scratch.best[i] < scratch.t_end[i] ? scratch.best[i] * resolution_ : max_range;
  return true;
}

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
