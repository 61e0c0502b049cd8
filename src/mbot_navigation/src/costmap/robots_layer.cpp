#include "mbot_navigation/costmap/robots_layer.h"

#include <cmath>
#include <stdexcept>

namespace mbot_navigation
{
RobotsLayer::RobotsLayer(const RobotsLayerConfig& config) : config_(config)
{
  if (!(config.prediction_time >= 0.0) || !(config.prediction_step > 0.0))
    throw std::invalid_argument("RobotsLayerConfig: 'prediction_time' must be >= 0 [s] and 'prediction_step' > 0 [s]");
  if (config.prediction_cost >= cost::INSCRIBED)
    throw std::invalid_argument("RobotsLayerConfig: 'prediction_cost' must be < 253 (passable)");
}

std::vector<Pose2D> RobotsLayer::predict(const TeammateState& mate) const
{
  std::vector<Pose2D> poses{mate.pose};
  Pose2D p = mate.pose;
  const int steps = static_cast<int>(std::ceil(config_.prediction_time / config_.prediction_step - 1e-9));
  for (int i = 0; i < steps; ++i)
  {
    const double dt = std::min(config_.prediction_step, config_.prediction_time - i * config_.prediction_step);
    // Constant body twist, integrated at the middle heading of the step.
    const double th = p.theta + 0.5 * mate.wz * dt;
    p.x += (mate.vx * std::cos(th) - mate.vy * std::sin(th)) * dt;
    p.y += (mate.vx * std::sin(th) + mate.vy * std::cos(th)) * dt;
    p.theta += mate.wz * dt;
    poses.push_back(p);
  }
  return poses;
}

void RobotsLayer::updateBounds(const Pose2D& /*robot*/, Bounds& bounds)
{
  // Erase what was drawn last time, and draw the current teammates.
  bounds.include(last_bounds_);
  Bounds now;
  for (const TeammateState& mate : teammates_)
  {
    const double r = mate.radius + robot_radius_;
    for (const Pose2D& p : predict(mate))
    {
      now.include(p.x - r, p.y - r);
      now.include(p.x + r, p.y + r);
    }
  }
  bounds.include(now);
  last_bounds_ = now;
}

void RobotsLayer::drawDisc(Costmap2D& master, const CellWindow& w, double x, double y, double radius, uint8_t c)
{
  const double res = master.resolution();
  // Cell range of the disc's box, clipped to the window.
  const int x0 = std::max(w.x0, static_cast<int>(std::floor((x - radius - master.originX()) / res)));
  const int y0 = std::max(w.y0, static_cast<int>(std::floor((y - radius - master.originY()) / res)));
  const int xn = std::min(w.xn, static_cast<int>(std::floor((x + radius - master.originX()) / res)) + 1);
  const int yn = std::min(w.yn, static_cast<int>(std::floor((y + radius - master.originY()) / res)) + 1);
  for (int my = y0; my < yn; ++my)
    for (int mx = x0; mx < xn; ++mx)
    {
      double wx, wy;
      master.mapToWorld(mx, my, wx, wy);
      if ((wx - x) * (wx - x) + (wy - y) * (wy - y) <= radius * radius)
        updateWithMax(master.data()[master.index(mx, my)], c);
    }
  // A teammate smaller than a cell still occupies the cell under its centre.
  unsigned cx, cy;
  if (master.worldToMap(x, y, cx, cy) && static_cast<int>(cx) >= w.x0 && static_cast<int>(cx) < w.xn &&
      static_cast<int>(cy) >= w.y0 && static_cast<int>(cy) < w.yn)
    updateWithMax(master.data()[master.index(cx, cy)], c);
}

void RobotsLayer::updateCosts(Costmap2D& master, const CellWindow& w)
{
  for (const TeammateState& mate : teammates_)
  {
    const std::vector<Pose2D> poses = predict(mate);
    // The predicted sweep, grown by this robot's radius: where our centre would touch it.
    for (size_t i = 1; i < poses.size(); ++i)
      drawDisc(master, w, poses[i].x, poses[i].y, mate.radius + robot_radius_, config_.prediction_cost);
    drawDisc(master, w, mate.pose.x, mate.pose.y, mate.radius, cost::LETHAL);
  }
}

}  // namespace mbot_navigation
