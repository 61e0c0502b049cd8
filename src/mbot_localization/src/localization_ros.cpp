#include "mbot_localization/localization_ros.h"

#include <cmath>
#include <stdexcept>
#include <string>

#include <tf2/utils.h>

namespace mbot_localization
{
LaserScanData toLaserScanData(const sensor_msgs::LaserScan& scan)
{
  LaserScanData out;
  out.ranges = scan.ranges;
  out.angle_min = scan.angle_min;
  out.angle_increment = scan.angle_increment;
  out.range_min = scan.range_min;
  out.range_max = scan.range_max;
  return out;
}

OccupancyGridData toOccupancyGridData(const nav_msgs::OccupancyGrid& grid)
{
  OccupancyGridData out;
  out.width = grid.info.width;
  out.height = grid.info.height;
  out.resolution = grid.info.resolution;
  out.origin_x = grid.info.origin.position.x;
  out.origin_y = grid.info.origin.position.y;
  if (grid.data.size() != static_cast<size_t>(out.width) * out.height)
    throw std::runtime_error("map: " + std::to_string(out.width) + " x " + std::to_string(out.height) + " cells but " +
                             std::to_string(grid.data.size()) + " values");
  if (std::fabs(tf2::getYaw(grid.info.origin.orientation)) > 1e-6)
    throw std::runtime_error("map: a rotated origin (yaw " + std::to_string(tf2::getYaw(grid.info.origin.orientation)) +
                             " rad) is not supported; rotate the image instead");
  out.data = grid.data;
  return out;
}

}  // namespace mbot_localization
