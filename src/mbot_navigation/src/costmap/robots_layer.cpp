#include "mbot_navigation/costmap/robots_layer.h"

#include <cmath>

namespace mbot_navigation
{
RobotsLayer::RobotsLayer(const RobotsLayerConfig& config) : config_(config)
{
  checkSweepPrediction(config, "RobotsLayerConfig");
}

std::vector<Pose2D> RobotsLayer::predict(const TeammateState& mate) const
{
  return predictPoses(mate.pose, mate.vx, mate.vy, mate.wz, config_);
}

void RobotsLayer::updateBounds(const Pose2D& /*robot*/, Bounds& bounds)
{
  // Erase what was drawn last time, and draw the current teammates.
  bounds.include(last_bounds_);
  Bounds now;
  for (const TeammateState& mate : teammates_) includeDiscs(predict(mate), mate.radius + robot_radius_, now);
  bounds.include(now);
  last_bounds_ = now;
}

void RobotsLayer::updateCosts(Costmap2D& master, const CellWindow& w)
{
  for (const TeammateState& mate : teammates_)
  {
    // The predicted sweep, grown by this robot's radius: where our centre would touch it.
    drawSweep(master, w, predict(mate), mate.radius + robot_radius_, config_.prediction_cost);
    drawDisc(master, w, mate.pose.x, mate.pose.y, mate.radius, cost::LETHAL);
  }
}

ScanObservation withoutTeammateHits(const ScanObservation& scan, const std::vector<TeammateState>& teammates,
                                    double margin)
{
  ScanObservation out = scan;
  if (teammates.empty()) return out;
  out.beams.clear();
  for (const ScanBeam& beam : scan.beams)
  {
    if (std::isfinite(beam.range))
    {
      const double hx = scan.origin_x + beam.range * std::cos(beam.angle);
      const double hy = scan.origin_y + beam.range * std::sin(beam.angle);
      bool on_mate = false;
      for (const TeammateState& m : teammates)
        on_mate = on_mate || std::hypot(hx - m.pose.x, hy - m.pose.y) <= m.radius + margin;
      if (on_mate) continue;
    }
    out.beams.push_back(beam);
  }
  return out;
}

}  // namespace mbot_navigation
