/**
 * @file map_io.h
 * @brief Reads occupancy maps in map_server format (yaml + PGM/PNG-free: PGM only), free of ROS
 *        types. Used by the simulator and by mbot_navigation's map server.
 */
#pragma once

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbot_sim
{
/// @brief Raised for a missing or invalid map; the message names the file, key and problem.
class MapError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// @brief An occupancy map as map_server publishes it (trinary mode).
struct OccupancyMap
{
  unsigned width = 0;        ///< [cells]
  unsigned height = 0;       ///< [cells]
  double resolution = 0.05;  ///< [m/cell]
  double origin_x = 0.0;     ///< lower-left corner of cell (0, 0) in the map frame [m]
  double origin_y = 0.0;     ///< [m]
  double origin_yaw = 0.0;   ///< [rad]
  /// width * height values, row-major, row 0 at origin_y (the image's bottom row, as
  /// map_server flips it): 100 occupied, 0 free, -1 unknown.
  std::vector<int8_t> data;

  bool inBounds(int mx, int my) const { return mx >= 0 && my >= 0 && mx < (int)width && my < (int)height; }
  int8_t at(unsigned mx, unsigned my) const { return data[static_cast<size_t>(my) * width + mx]; }
};

/// @brief Load a map_server yaml (image, resolution, origin, occupied_thresh, free_thresh,
///        negate; mode trinary) and its PGM image (P2 or P5, path relative to the yaml).
/// @throws MapError naming the file, the key and the problem
OccupancyMap loadMap(const std::string& yaml_path);

}  // namespace mbot_sim
