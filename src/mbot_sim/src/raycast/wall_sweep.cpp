/**
 * @file wall_sweep.cpp
 * @brief Whole scans against the walls, face by face (GridRaycaster::castScanWalls): the wall
 *        faces cut from the grid at load, bucketed in tiles, and the angular sweep over them.
 *        Where the sweep cannot work, or would be slower, the grid walk (grid_walk.cpp) does it.
 */
#include "mbot_sim/raycast.h"

#include "internal.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

namespace mbot_sim
{
using namespace detail;

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

}  // namespace mbot_sim
