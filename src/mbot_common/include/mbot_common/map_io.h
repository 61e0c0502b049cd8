/**
 * @file map_io.h
 * @brief Occupancy maps in map_server format: the yaml (image, resolution [m/cell], origin
 *        [m, m, rad], occupied_thresh, free_thresh, negate, mode trinary/scale/raw) and its PGM
 *        image (P5 or P2), turned into the values map_server publishes. Free of ROS types (the
 *        Python twin is mbot_common.maps).
 *
 * As map_server's image_loader: grey v in 0..255 (scaled from the PGM's maxval), v = 255 - v if
 * negate, p = (255 - v) / 255; trinary: p > occupied_thresh -> 100, p < free_thresh -> 0, else
 * -1; scale: between the thresholds 1 + 98 (p - free) / (occupied - free) (truncated); raw: v
 * itself, stored as map_server stores it (an unsigned char in an int8: 200 reads as -56).
 */
#pragma once

#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "mbot_common/geometry.h"
#include "mbot_common/strict_yaml.h"

namespace mbot_common
{
/// @brief A missing or invalid map; the message names the file, the key and the problem.
class MapError : public ConfigError
{
public:
  using ConfigError::ConfigError;
};

/// @brief How grey values become occupancy values (map_server's `mode`).
enum class MapMode
{
  TRINARY,  ///< 100 occupied, 0 free, -1 unknown (the default)
  SCALE,    ///< 100, 0, and 1..99 between the thresholds
  RAW       ///< the grey value itself
};

/// @brief "trinary", "scale" or "raw".
const char* mapModeName(MapMode mode);

/// @brief An occupancy map as map_server publishes it, and the yaml fields it came from.
struct OccupancyMap
{
  std::string yaml_path;          ///< the map yaml as given
  std::string image_path;         ///< the PGM (relative to the yaml's directory when relative there)
  unsigned width = 0;             ///< [cells]
  unsigned height = 0;            ///< [cells]
  double resolution = 0.05;       ///< [m/cell]
  double origin_x = 0.0;          ///< lower-left corner of cell (0, 0) in the map frame [m]
  double origin_y = 0.0;          ///< [m]
  double origin_yaw = 0.0;        ///< [rad]
  double occupied_thresh = 0.65;  ///< occupancy probability above which a cell is occupied [0, 1]
  double free_thresh = 0.196;     ///< occupancy probability below which a cell is free [0, 1]
  bool negate = false;            ///< true: white is occupied, black free
  MapMode mode = MapMode::TRINARY;
  /// width * height values, row-major, row 0 at origin_y (the image's bottom row, as
  /// map_server flips it): 100 occupied, 0 free, -1 unknown (trinary).
  std::vector<int8_t> data;

  /// @brief True if cell (mx column, my row) is inside the map.
  bool inBounds(int mx, int my) const { return mx >= 0 && my >= 0 && mx < (int)width && my < (int)height; }
  /// @brief The value of cell (mx, my); it must be inBounds().
  int8_t at(unsigned mx, unsigned my) const { return data[static_cast<size_t>(my) * width + mx]; }
  /// @brief The cell {column, row} holding the map-frame point (x, y) [m]; may be out of bounds.
  std::array<int, 2> worldToCell(double x, double y) const;
  /// @brief The map-frame centre [m] of cell (mx column, my row).
  Point2D cellToWorld(int mx, int my) const;
};

/// @brief The occupancy value map_server computes for one grey value (0..255, before negate).
int8_t occupancyValue(uint8_t grey, double occupied_thresh, double free_thresh, bool negate, MapMode mode);

/// @brief A PGM (P5 or P2) as grey values 0..255, top row first (scaled v * 255 / maxval for a
///        maxval other than 255, as SDL_image scales them for map_server).
/// @param yaml_path shown in the message when the file cannot be read ("" = none)
/// @throws MapError naming the file and the problem
std::vector<uint8_t> readPgm(const std::string& path, unsigned& width, unsigned& height,
                             const std::string& yaml_path = "");

/// @brief Load a map_server yaml (strictly: every key, types, ranges) and its PGM image.
/// @throws MapError naming the file, the key and the problem
OccupancyMap loadMap(const std::string& yaml_path);

}  // namespace mbot_common
