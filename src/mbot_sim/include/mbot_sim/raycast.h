/**
 * @file raycast.h
 * @brief 2D laser ray casting against an occupancy grid and against moving shapes (robots,
 *        boxes, cylinders). Free of ROS types; the hot path of the simulator.
 *
 * Ranges follow REP-117: a beam with no return within range_max reads +Inf; a return closer
 * than range_min reads -Inf.
 */
#pragma once

#include <cstdint>
#include <vector>

namespace mbot_sim
{
/// @brief Casts rays against the static occupancy grid (the map walls).
///
/// A cell is a solid square; the range is the exact distance from the ray origin to the first
/// occupied cell's boundary.
class GridRaycaster
{
public:
  GridRaycaster() = default;
  /// @param occupied size_x * size_y cells, row-major, row 0 at origin_y (non-zero = occupied)
  /// @param resolution cell side [m]; origin_x, origin_y: lower-left corner of cell (0, 0) [m]
  GridRaycaster(std::vector<uint8_t> occupied, unsigned size_x, unsigned size_y, double resolution,
                double origin_x, double origin_y);

  /// @brief Distance [m] along heading `theta` [rad] from (x, y) [m] to the first occupied cell,
  ///        or `max_range` when there is none closer. Outside the grid counts as free.
  double cast(double x, double y, double theta, double max_range) const;

  /// @brief True when the point (x, y) [m] is inside an occupied cell.
  bool occupiedAt(double x, double y) const;

  unsigned sizeX() const { return size_x_; }
  unsigned sizeY() const { return size_y_; }
  double resolution() const { return resolution_; }
  double originX() const { return origin_x_; }
  double originY() const { return origin_y_; }

private:
  unsigned size_x_ = 0;
  unsigned size_y_ = 0;
  double resolution_ = 0.05;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  std::vector<uint8_t> occupied_;
  std::vector<float> clearance_;  ///< distance to the nearest occupied cell [cells], for long steps
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
  /// @param bucket_size side of a spatial hash bucket [m] (about the laser range works well)
  explicit ShapeSet(double bucket_size = 4.0);
  void clear();
  void addCircle(const Circle& c);
  void addBox(const OrientedBox& b);
  size_t size() const;

private:
  friend void castScan(const class GridRaycaster&, const ShapeSet&, const struct ScanSpec&,
                       std::vector<float>&);
  double bucket_size_;
  std::vector<Circle> circles_;
  std::vector<OrientedBox> boxes_;
  // spatial hash buckets: private detail of raycast.cpp (may change freely)
};

/// @brief One laser scan request: sensor pose in the world and the beam layout.
struct ScanSpec
{
  double x = 0.0;        ///< sensor position [m]
  double y = 0.0;
  double yaw = 0.0;      ///< sensor heading [rad]
  double min_angle = 0.0;        ///< angle of beam 0 relative to the sensor heading [rad]
  double angle_increment = 0.0;  ///< [rad]
  int beams = 0;
  double range_min = 0.0;  ///< [m]
  double range_max = 0.0;  ///< [m]
  int ignore_owner = -1;   ///< shapes with this owner are not seen (the robot's own body)
};

/// @brief Cast a whole scan against the grid and the shapes. `ranges` gets `beams` values [m]
///        (+Inf: no return within range_max; -Inf: return closer than range_min).
void castScan(const GridRaycaster& grid, const ShapeSet& shapes, const ScanSpec& spec,
              std::vector<float>& ranges);

}  // namespace mbot_sim
