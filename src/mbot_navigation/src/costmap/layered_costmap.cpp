#include "mbot_navigation/costmap/layered_costmap.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot_navigation
{
namespace
{
unsigned cellsFor(double metres, double resolution, const char* key)
{
  if (!(metres > 0.0) || !(resolution > 0.0))
    throw std::invalid_argument(std::string("LayeredCostmapConfig: '") + key + "' and 'resolution' must be > 0");
  return static_cast<unsigned>(std::lround(metres / resolution));
}
}  // namespace

LayeredCostmap::LayeredCostmap(const LayeredCostmapConfig& config) : config_(config)
{
  if (!(config.robot_radius >= 0.0))
    throw std::invalid_argument("LayeredCostmapConfig: 'robot_radius' must be >= 0 [m]");
  costmap_ = Costmap2D(cellsFor(config.width, config.resolution, "width"),
                       cellsFor(config.height, config.resolution, "height"), config.resolution, config.origin_x,
                       config.origin_y, defaultValue());
}

Layer& LayeredCostmap::addLayer(std::unique_ptr<Layer> layer)
{
  if (!layer) throw std::invalid_argument("LayeredCostmap::addLayer: null layer");
  layer->layered_costmap_ = this;
  layer->onFootprintChanged(config_.robot_radius);
  layer->matchSize(costmap_);
  layers_.push_back(std::move(layer));
  full_update_ = true;
  return *layers_.back();
}

void LayeredCostmap::resizeMap(unsigned size_x, unsigned size_y, double resolution, double origin_x, double origin_y)
{
  costmap_ = Costmap2D(size_x, size_y, resolution, origin_x, origin_y, defaultValue());
  config_.resolution = resolution;
  config_.width = size_x * resolution;
  config_.height = size_y * resolution;
  for (auto& layer : layers_) layer->matchSize(costmap_);
  full_update_ = true;
}

void LayeredCostmap::setRobotRadius(double robot_radius)
{
  config_.robot_radius = robot_radius;
  for (auto& layer : layers_) layer->onFootprintChanged(robot_radius);
  full_update_ = true;
}

void LayeredCostmap::reset()
{
  costmap_.fill(defaultValue());
  for (auto& layer : layers_) layer->reset();
  full_update_ = true;
}

CellWindow LayeredCostmap::toCells(const Bounds& b) const
{
  CellWindow w;
  if (b.empty()) return w;
  const double res = costmap_.resolution();
  // floor() of both corners, then +1 on the max side: the cell holding max_x is included.
  auto cell = [res](double v, double origin) {
    const double c = std::floor((v - origin) / res);
    return static_cast<int>(std::max(-1.0, std::min(c, 1e9)));
  };
  w.x0 = std::max(0, cell(b.min_x, costmap_.originX()));
  w.y0 = std::max(0, cell(b.min_y, costmap_.originY()));
  w.xn = std::min(static_cast<int>(costmap_.sizeX()), cell(b.max_x, costmap_.originX()) + 1);
  w.yn = std::min(static_cast<int>(costmap_.sizeY()), cell(b.max_y, costmap_.originY()) + 1);
  return w;
}

void LayeredCostmap::updateMap(const Pose2D& robot)
{
  if (config_.rolling_window)
  {
    const double ox = robot.x - 0.5 * costmap_.sizeX() * costmap_.resolution();
    const double oy = robot.y - 0.5 * costmap_.sizeY() * costmap_.resolution();
    const double old_x = costmap_.originX(), old_y = costmap_.originY();
    costmap_.updateOrigin(ox, oy, defaultValue());
    if (costmap_.originX() != old_x || costmap_.originY() != old_y)
    {
      for (auto& layer : layers_) layer->updateOrigin(costmap_.originX(), costmap_.originY());
      // Cells that entered the window hold nothing yet: rewrite all of it (a local window is small).
      full_update_ = true;
    }
  }

  Bounds bounds;
  for (auto& layer : layers_) layer->updateBounds(robot, bounds);
  if (full_update_)
  {
    bounds.include(costmap_.originX(), costmap_.originY());
    bounds.include(costmap_.originX() + (costmap_.sizeX() - 0.5) * costmap_.resolution(),
                   costmap_.originY() + (costmap_.sizeY() - 0.5) * costmap_.resolution());
    full_update_ = false;
  }
  last_window_ = toCells(bounds);
  if (last_window_.empty()) return;

  costmap_.resetWindow(last_window_.x0, last_window_.y0, last_window_.xn, last_window_.yn, defaultValue());
  for (auto& layer : layers_) layer->updateCosts(costmap_, last_window_);
}

}  // namespace mbot_navigation
