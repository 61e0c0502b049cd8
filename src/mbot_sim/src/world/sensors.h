/**
 * @file sensors.h
 * @brief (private to the world) The sensors of every robot, each on its own timer in sim time:
 *        ground truth, odometry with joint states, and the laser (cast against the walls and
 *        the bodies, raycast.h). Samples go to the SensorListener at once or, with a latency
 *        fault, when they are due.
 */
#pragma once

#include "bodies.h"

namespace mbot_sim
{
namespace detail
{
class Sensors
{
public:
  Sensors();
  /// The walls the lasers see (the map's occupied cells).
  void setWalls(GridRaycaster grid) { grid_ = std::move(grid); }
  /// The walls' height [m] for the 3D lidars (> 0).
  void setWallHeight(double height) { scene_ = Scene25D(&grid_, height); }

  /// After a step at sim time `now`: every robot's sensors that are due measure, and samples
  /// held back by a latency fault that are due now are handed over.
  void run(double now, const NoiseConfig& noise, SensorListener* listener,
           const std::vector<std::unique_ptr<Robot>>& robots, const std::vector<std::unique_ptr<Obstacle>>& obstacles,
           const std::vector<std::unique_ptr<Mover>>& movers);

  unsigned long long raysCast() const { return rays_cast_; }
  unsigned long long lidarRaysCast() const { return lidar_rays_; }

private:
  /// The shapes the lasers see besides the walls, where the bodies are now.
  void buildShapes(const std::vector<std::unique_ptr<Robot>>& robots,
                   const std::vector<std::unique_ptr<Obstacle>>& obstacles,
                   const std::vector<std::unique_ptr<Mover>>& movers);
  void addShape(const Outline& outline, const Pose2D& pose, int owner);
  void measureScan(Robot& r, double now, const NoiseConfig& noise);
  /// The 3D lidar points whose time fell in the step that ended at `now`; finished frames go
  /// to the listener. The prisms (bodies with their heights) are built once per step.
  void runLidar(Robot& r, double now, SensorListener* listener, const std::vector<std::unique_ptr<Robot>>& robots,
                const std::vector<std::unique_ptr<Obstacle>>& obstacles,
                const std::vector<std::unique_ptr<Mover>>& movers, bool& prisms_built);
  void addPrism(const Outline& outline, const Pose2D& pose, double height, int owner, float intensity);
  /// The IMU samples due in the step that ended at `now` (several per step when its rate is
  /// above the physics rate), each at its own time on the IMU's grid.
  void runImu(Robot& r, double now, SensorListener* listener);

  GridRaycaster grid_;
  ShapeSet shapes_;
  Scene25D scene_{&grid_, 2.5};
  PrismQuery near_;
  std::vector<LidarFrame> frames_;
  unsigned long long lidar_rays_ = 0;
  unsigned long long rays_cast_ = 0;
};

}  // namespace detail
}  // namespace mbot_sim
