#include "mbot_navigation/costmap/static_layer.h"

#include <stdexcept>

#include "mbot_navigation/costmap/layered_costmap.h"

namespace mbot_navigation
{
uint8_t StaticLayer::interpretValue(int8_t value) const
{
  if (value == config_.unknown_cost_value) return config_.track_unknown_space ? cost::NO_INFORMATION : cost::FREE;
  if (value >= config_.lethal_cost_threshold) return cost::LETHAL;
  if (config_.trinary_costmap || value <= 0) return cost::FREE;
  // Scaled mode, as costmap_2d: the occupancy fraction of LETHAL.
  return static_cast<uint8_t>(static_cast<double>(value) / config_.lethal_cost_threshold * cost::LETHAL);
}

void StaticLayer::setMap(unsigned width, unsigned height, double resolution, double origin_x, double origin_y,
                         const int8_t* data)
{
  if (width == 0 || height == 0 || !(resolution > 0.0) || data == nullptr)
    throw std::invalid_argument("StaticLayer::setMap: empty map or resolution <= 0");
  map_ = Costmap2D(width, height, resolution, origin_x, origin_y);
  uint8_t* out = map_.data();
  const size_t n = static_cast<size_t>(width) * height;
  for (size_t i = 0; i < n; ++i) out[i] = interpretValue(data[i]);
  has_map_ = true;
  has_updated_data_ = true;

  // A static (global) costmap takes the map's geometry, as costmap_2d's StaticLayer does.
  if (layered_costmap_ && !layered_costmap_->isRolling())
  {
    const Costmap2D& m = layered_costmap_->costmap();
    if (m.sizeX() != width || m.sizeY() != height || m.resolution() != resolution || m.originX() != origin_x ||
        m.originY() != origin_y)
      layered_costmap_->resizeMap(width, height, resolution, origin_x, origin_y);
  }
}

void StaticLayer::updateBounds(const Pose2D& /*robot*/, Bounds& bounds)
{
  if (!has_map_) return;
  // A rolling window moves over the map every update: the whole window is handled by the
  // LayeredCostmap when it moves. A static costmap only needs rewriting after a new map.
  if (!has_updated_data_) return;
  bounds.include(map_.originX(), map_.originY());
  bounds.include(map_.originX() + (map_.sizeX() - 0.5) * map_.resolution(),
                 map_.originY() + (map_.sizeY() - 0.5) * map_.resolution());
  has_updated_data_ = false;
}

void StaticLayer::updateCosts(Costmap2D& master, const CellWindow& w)
{
  if (!has_map_) return;
  const bool same_grid = master.sizeX() == map_.sizeX() && master.sizeY() == map_.sizeY() &&
                         master.originX() == map_.originX() && master.originY() == map_.originY() &&
                         master.resolution() == map_.resolution();
  for (int y = w.y0; y < w.yn; ++y)
  {
    for (int x = w.x0; x < w.xn; ++x)
    {
      uint8_t c;
      if (same_grid)
      {
        c = map_.cost(x, y);
      }
      else
      {
        // Rolling window: look the cell centre up in the map; outside the map means unknown.
        double wx, wy;
        unsigned mx, my;
        master.mapToWorld(x, y, wx, wy);
        c = map_.worldToMap(wx, wy, mx, my) ? map_.cost(mx, my) : cost::NO_INFORMATION;
      }
      updateWithMax(master.data()[master.index(x, y)], c);
    }
  }
}

}  // namespace mbot_navigation
