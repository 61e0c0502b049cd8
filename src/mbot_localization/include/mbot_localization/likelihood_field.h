/**
 * @file likelihood_field.h
 * @brief Distance from every map cell to the nearest obstacle (an exact Euclidean distance
 *        transform), the lookup table of the likelihood-field laser model. Free of ROS types.
 *
 * amcl builds the same table with a brushfire (map_update_cspace); here the exact two-pass
 * transform of Felzenszwalb and Huttenlocher ("Distance Transforms of Sampled Functions", 2012)
 * is used: it is O(cells), exact, and easy to test against a brute-force search.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <vector>

namespace mbot_localization
{
/// @brief An occupancy grid as map_server publishes it: -1 unknown, 0 free, 100 occupied.
struct OccupancyGridData
{
  unsigned width = 0;        ///< [cells]
  unsigned height = 0;       ///< [cells]
  double resolution = 0.05;  ///< [m/cell]
  double origin_x = 0.0;     ///< lower-left corner of cell (0, 0) in the map frame [m]
  double origin_y = 0.0;     ///< [m]
  std::vector<int8_t> data;  ///< width * height values, row-major, row 0 at origin_y
};

/// @brief Per-cell distance [m] to the nearest occupied cell, capped at a maximum distance.
///
/// Distances are measured between cell centres, as amcl does. A cell is occupied when its value
/// is above 50 (so both trinary and scaled maps work); unknown cells count as free space here.
class LikelihoodField
{
public:
  /// @param grid the map; max_distance: cap of the table, amcl's laser_likelihood_max_dist [m]
  /// @throws std::invalid_argument when the grid's size does not match its data
  LikelihoodField(const OccupancyGridData& grid, double max_distance);

  /// @brief Distance [m] from the point (x, y) [m] in the map frame to the nearest obstacle;
  ///        maxDistance() off the map (amcl treats off-map beam endpoints the same way).
  double distance(double x, double y) const;

  /// @brief Distance [m] from the point (x, y) to the nearest obstacle's surface (cell edge),
  ///        interpolated between cell centres; 0 inside obstacles, maxDistance() off the map.
  ///
  /// distance() is a step function of cell size that is 0 at obstacle cell centres, half a cell
  /// behind the surface that a laser sees: scored with it, the filter cannot place the robot
  /// closer than about a cell and is pulled towards the walls. Bilinear interpolation of the
  /// centre distances minus half a cell is continuous and 0 at a straight wall's surface.
  double surfaceDistance(double x, double y) const;

  /// @brief Distance [m] stored for cell (mx, my); the cell must be inside the map.
  double cellDistance(unsigned mx, unsigned my) const { return distance_[index(mx, my)]; }

  /// @brief True when (x, y) [m] lies in a cell known to be free (value 0).
  bool isFree(double x, double y) const;

  /// @brief Cell of the point (x, y) [m]; false when it is off the map.
  bool worldToMap(double x, double y, unsigned& mx, unsigned& my) const;

  unsigned width() const { return width_; }
  unsigned height() const { return height_; }
  double resolution() const { return resolution_; }
  double originX() const { return origin_x_; }
  double originY() const { return origin_y_; }
  double maxDistance() const { return max_distance_; }

private:
  size_t index(unsigned mx, unsigned my) const { return static_cast<size_t>(my) * width_ + mx; }

  unsigned width_ = 0;
  unsigned height_ = 0;
  double resolution_ = 0.05;
  double origin_x_ = 0.0;
  double origin_y_ = 0.0;
  double max_distance_ = 2.0;
  std::vector<float> distance_;  ///< [m], capped at max_distance_
  std::vector<uint8_t> free_;    ///< 1 where the map says "free" (value 0)
};

/// @brief Exact squared Euclidean distance transform of a binary grid, in [cells^2].
/// @param occupied width * height flags, row-major; the result is 0 on occupied cells and the
///        squared distance to the nearest occupied cell centre elsewhere (a huge value when
///        there is no occupied cell at all)
std::vector<double> squaredDistanceTransform(const std::vector<uint8_t>& occupied, unsigned width, unsigned height);

}  // namespace mbot_localization
