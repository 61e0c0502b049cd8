#include "mbot_navigation/costmap/sweep.h"

#include <cmath>
#include <stdexcept>

namespace mbot_navigation
{
void checkSweepPrediction(const SweepPrediction& p, const std::string& who)
{
  if (!(p.prediction_time >= 0.0) || !(p.prediction_step > 0.0))
    throw std::invalid_argument(who + ": 'prediction_time' must be >= 0 [s] and 'prediction_step' > 0 [s]");
  if (p.prediction_cost >= cost::INSCRIBED)
    throw std::invalid_argument(who + ": 'prediction_cost' must be < 253 (passable)");
}

std::vector<Pose2D> predictPoses(const Pose2D& start, double vx, double vy, double wz, const SweepPrediction& pr)
{
  std::vector<Pose2D> poses{start};
  Pose2D p = start;
  const int steps = static_cast<int>(std::ceil(pr.prediction_time / pr.prediction_step - 1e-9));
  for (int i = 0; i < steps; ++i)
  {
    const double dt = std::min(pr.prediction_step, pr.prediction_time - i * pr.prediction_step);
    // Constant body twist, integrated at the middle heading of the step.
    const double th = p.theta + 0.5 * wz * dt;
    p.x += (vx * std::cos(th) - vy * std::sin(th)) * dt;
    p.y += (vx * std::sin(th) + vy * std::cos(th)) * dt;
    p.theta += wz * dt;
    poses.push_back(p);
  }
  return poses;
}

void includeDiscs(const std::vector<Pose2D>& poses, double radius, Bounds& bounds)
{
  for (const Pose2D& p : poses)
  {
    bounds.include(p.x - radius, p.y - radius);
    bounds.include(p.x + radius, p.y + radius);
  }
}

void drawDisc(Costmap2D& master, const CellWindow& w, double x, double y, double radius, uint8_t c)
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
  // A body smaller than a cell still occupies the cell under its centre.
  unsigned cx, cy;
  if (master.worldToMap(x, y, cx, cy) && static_cast<int>(cx) >= w.x0 && static_cast<int>(cx) < w.xn &&
      static_cast<int>(cy) >= w.y0 && static_cast<int>(cy) < w.yn)
    updateWithMax(master.data()[master.index(cx, cy)], c);
}

void drawSweep(Costmap2D& master, const CellWindow& window, const std::vector<Pose2D>& poses, double radius, uint8_t c)
{
  for (size_t i = 1; i < poses.size(); ++i) drawDisc(master, window, poses[i].x, poses[i].y, radius, c);
}

}  // namespace mbot_navigation
