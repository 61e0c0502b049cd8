/**
 * @file raycast.h
 * @brief 2D laser ray casting against an occupancy grid and against moving shapes (robots,
 *        boxes, cylinders). Free of ROS types; the hot path of the simulator.
 *
 * Ranges follow REP-117: a beam with no return within range_max reads +Inf; a return closer
 * than range_min reads -Inf.
 *
 * How it is fast (details in src/raycast/: grid_walk.cpp, wall_sweep.cpp, scan.cpp):
 * - whole scans against the walls are an angular sweep: at map load the boundary between free
 *   and occupied cells is cut into axis-aligned wall faces, bucketed in tiles; a scan visits
 *   the faces in range that face the sensor, and each face tests only the beams inside the
 *   angle it covers, keeping the nearest hit per beam (an angular z-buffer);
 * - single rays, and scans among very many faces (cave-like maps), walk the grid instead: the
 *   grid keeps clearance maps (how far every cell is from the walls a ray could still
 *   hit), so a ray jumps through open space in a few long steps and walks cell by cell only
 *   next to walls; the sensor cell's clearances are looked up once per scan, and the long
 *   steps of a few beams at a time are interleaved;
 * - a scan tests each nearby shape only against the few beams inside the angle the shape
 *   covers as seen from the sensor, and shapes sit in spatial buckets so far ones are never
 *   looked at.
 */
#pragma once

#include <array>
#include <cstddef>
#include <cstdint>
#include <unordered_map>
#include <vector>

namespace mbot_sim
{
class GridRaycaster;
class ShapeSet;
struct ScanSpec;

/// @brief How GridRaycaster::castScanWalls() finds the walls. Both give the same ranges.
enum class WallMethod
{
  kAuto,      ///< the sweep, unless the grid walk is expected to be faster (many faces in range)
  kSweep,     ///< angular sweep over the wall faces (falls back to the walk where it cannot work)
  kGridWalk,  ///< trace every beam through the cells (castFan)
};

/// @brief Cast a whole scan against the grid and the shapes. `ranges` gets `beams` values [m]
///        (+Inf: no return within range_max; -Inf: return closer than range_min).
///        Beam i points along spec.yaw + spec.min_angle + i * spec.angle_increment.
/// @throws std::invalid_argument for beams < 0, range_max <= 0 or a yaw or angle that is not
///         finite
void castScan(const GridRaycaster& grid, const ShapeSet& shapes, const ScanSpec& spec, std::vector<float>& ranges);

/// @brief Casts rays against the static occupancy grid (the map walls).
///
/// A cell is a solid square; the range is the exact distance from the ray origin to the first
/// occupied cell's boundary. A ray that starts inside an occupied cell reads 0.
class GridRaycaster
{
public:
  GridRaycaster() = default;
  /// @param occupied size_x * size_y cells, row-major, row 0 at origin_y (non-zero = occupied)
  /// @param resolution cell side [m]; origin_x, origin_y: lower-left corner of cell (0, 0) [m]
  /// @throws std::invalid_argument when occupied.size() != size_x * size_y or resolution <= 0
  GridRaycaster(std::vector<uint8_t> occupied, unsigned size_x, unsigned size_y, double resolution, double origin_x,
                double origin_y);

  /// @brief Distance [m] along heading `theta` [rad] from (x, y) [m] to the first occupied cell,
  ///        or `max_range` when there is none closer. Outside the grid counts as free.
  /// @throws std::invalid_argument for a heading that is not finite
  double cast(double x, double y, double theta, double max_range) const;

  /// @brief As cast(), with the heading given as a unit vector (dir_x, dir_y) so that callers
  ///        casting many beams can rotate directions instead of calling cos/sin per beam.
  double castDirection(double x, double y, double dir_x, double dir_y, double max_range) const;

  /// @brief Cast n rays from (x, y) [m] along the unit vectors (dir_x[i], dir_y[i]); ranges[i]
  ///        gets what castDirection() would return. Faster per ray than n single casts: the
  ///        rays are traced interleaved (see grid_walk.cpp).
  /// @throws std::invalid_argument for a direction that is not finite
  void castFan(double x, double y, const double* dir_x, const double* dir_y, int n, double max_range,
               double* ranges) const;

  /// @brief As castFan() for the beams of a scan: beam i points along the world angle
  ///        first_angle + i * increment [rad] and (dir_x[i], dir_y[i]) is its unit vector.
  ///        The angles let the sweep compute which beams a wall face covers directly.
  /// @throws std::invalid_argument for a direction that is not finite
  void castScanWalls(double x, double y, const double* dir_x, const double* dir_y, double first_angle, double increment,
                     int n, double max_range, double* ranges, WallMethod method = WallMethod::kAuto) const;

  /// @brief Number of wall faces (merged runs of cell edges between a free and an occupied
  ///        cell) the sweep works with.
  size_t wallFaceCount() const { return wall_face_count_; }

  /// @brief True when the point (x, y) [m] is inside an occupied cell.
  bool occupiedAt(double x, double y) const;

  /// @brief Smallest distance [m] from any point of the cell containing (x, y) to any occupied
  ///        cell (0 next to a wall), rounded down to a quarter cell and capped at 63.75 cells
  ///        (the clearance map used for long steps); 0 outside the grid.
  double clearanceAt(double x, double y) const;

  /// @brief As clearanceAt(), counting only the walls a ray along (dir_x, dir_y) can still
  ///        meet: those not behind the cell on either axis. This is how far such a ray may
  ///        jump from anywhere in the cell [m].
  double clearanceAlong(double x, double y, double dir_x, double dir_y) const;

  unsigned sizeX() const { return size_x_; }
  unsigned sizeY() const { return size_y_; }
  double resolution() const { return resolution_; }
  double originX() const { return origin_x_; }
  double originY() const { return origin_y_; }

  /// @brief One wall face [cells]: the cell edges on grid line `line` (x = line for a
  ///        vertical face, y = line for a horizontal one) from `lo` to `hi`, between free and
  ///        occupied cells. `id` tells copies of a face in several tiles apart.
  struct WallFace
  {
    int32_t line;
    int32_t lo;
    int32_t hi;
    uint32_t id;
  };

private:
  void computeClearance();
  void extractWallFaces();
  /// The angular sweep of castScanWalls(); false (nothing done) where the walk is to be used.
  bool sweepWalls(double x, double y, const double* dir_x, const double* dir_y, double first_angle, double increment,
                  int n, double max_range, double* ranges, WallMethod method) const;

  unsigned size_x_ = 0;
  unsigned size_y_ = 0;
  double resolution_ = 0.05;
  double inv_resolution_ = 20.0;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  std::vector<uint8_t> occupied_;
  /// Clearance map: per cell, a lower bound of the distance from any point of the cell to any
  /// occupied cell, in quarter cells (255 = 63.75 cells or more). One byte per cell keeps a
  /// map small enough for the CPU cache. (With the four below: 6 bytes per cell in all.)
  std::vector<uint8_t> clearance_;
  /// The same counting only the walls ahead of a ray heading into quadrant q (bit 0: dir_x < 0,
  /// bit 1: dir_y < 0): a ray heading up and right never meets a wall below or left of its
  /// cell, so it may jump farther. These are what the ray tracing reads: (size_x + 2) x
  /// (size_y + 2) with a border of free cells, wall cells marked 0 (see grid_walk.cpp).
  std::array<std::vector<uint8_t>, 4> quadrant_clearance_;

  /// Wall faces by tile (kTileCells square, see wall_sweep.cpp) and by side, the way the free
  /// side looks (0: -x, 1: +x, 2: -y, 3: +y): tile t's faces of side s are
  /// tile_faces_[tile_start_[4 t + s] .. tile_start_[4 t + s + 1]). A face crossing tiles is
  /// copied into each.
  std::vector<WallFace> tile_faces_;
  std::vector<uint32_t> tile_start_;
  int tiles_x_ = 0;
  int tiles_y_ = 0;
  size_t wall_face_count_ = 0;
};

/// @brief A circle [m] (robot, cylinder); `owner` lets a robot's laser ignore its own body.
struct Circle
{
  double x = 0.0;
  double y = 0.0;
  double radius = 0.0;
  int owner = -1;
};

/// @brief An oriented rectangle [m, rad] (box obstacle, cart).
struct OrientedBox
{
  double x = 0.0;
  double y = 0.0;
  double yaw = 0.0;
  double half_length = 0.0;  ///< half size along its own x [m]
  double half_width = 0.0;   ///< half size along its own y [m]
  int owner = -1;
};

/// @brief The shapes a laser sees besides the map: rebuilt (clear + add) when bodies move.
///        Shapes are bucketed in a uniform grid so a scan only looks at shapes near the sensor.
class ShapeSet
{
public:
  /// @param bucket_size side of a spatial hash bucket [m] (about half the laser range works well)
  /// @throws std::invalid_argument for bucket_size <= 0
  explicit ShapeSet(double bucket_size = 4.0);
  /// @brief Remove every shape (keeps the buckets' memory, so a rebuild allocates nothing).
  void clear();
  /// @throws std::invalid_argument for a position that is not finite or a negative radius
  void addCircle(const Circle& c);
  /// @throws std::invalid_argument for a pose that is not finite or a negative half size
  void addBox(const OrientedBox& b);
  size_t size() const;

private:
  friend void castScan(const GridRaycaster&, const ShapeSet&, const ScanSpec&, std::vector<float>&);

  /// A box with its rotation precomputed once per rebuild instead of once per beam.
  struct PreparedBox
  {
    OrientedBox box;
    double cos_yaw = 1.0;
    double sin_yaw = 0.0;
  };
  /// Shapes whose centre lies in one bucket.
  struct Bucket
  {
    std::vector<Circle> circles;
    std::vector<PreparedBox> boxes;
  };
  Bucket& bucketAt(double x, double y);
  const Bucket* findBucket(int64_t bx, int64_t by) const;
  int64_t bucketIndex(double v) const;

  double bucket_size_;
  size_t count_ = 0;
  /// Largest distance [m] from a shape's centre to its farthest point: a scan looks at buckets
  /// up to range_max + max_extent_ from the sensor, since shapes are bucketed by centre only.
  double max_extent_ = 0.0;
  std::unordered_map<int64_t, Bucket> buckets_;  ///< key: packed (bucket x, bucket y)
};

/// @brief One laser scan request: sensor pose in the world and the beam layout.
struct ScanSpec
{
  double x = 0.0;  ///< sensor position [m]
  double y = 0.0;
  double yaw = 0.0;              ///< sensor heading [rad]
  double min_angle = 0.0;        ///< angle of beam 0 relative to the sensor heading [rad]
  double angle_increment = 0.0;  ///< [rad]
  int beams = 0;
  double range_min = 0.0;  ///< [m]
  double range_max = 0.0;  ///< [m]
  int ignore_owner = -1;   ///< shapes with this owner are not seen (the robot's own body); -1: none
};

}  // namespace mbot_sim
