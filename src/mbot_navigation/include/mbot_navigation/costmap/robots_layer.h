/**
 * @file robots_layer.h
 * @brief "Other robots" layer: teammates as moving obstacles, not as static walls.
 *
 * A teammate seen by the laser would be marked by the obstacle layer and stay there until a beam
 * clears it. This layer instead draws each teammate from its reported state at every update:
 * its footprint as LETHAL (the inflation layer, added after this one, inflates it like any
 * obstacle) and the area it will sweep in the next `prediction_time` seconds, grown by this robot's
 * own radius, as a high but passable cost, so that planners prefer to pass behind it. Nothing is
 * remembered: every update erases the previous drawing.
 */
#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/layer.h"
#include "mbot_navigation/costmap/obstacle_layer.h"
#include "mbot_navigation/costmap/sweep.h"

namespace mbot_navigation
{
/// @brief RobotsLayer settings: how far ahead a teammate's sweep is drawn and its cost (sweep.h).
struct RobotsLayerConfig : SweepPrediction
{};

/// @brief What the fleet reports about one teammate.
struct TeammateState
{
  std::string name;     ///< for messages, e.g. "robot_1"
  Pose2D pose;          ///< in the costmap frame [m, m, rad]
  double radius = 0.2;  ///< footprint radius [m]
  double vx = 0.0;      ///< forward velocity, body frame [m/s]
  double vy = 0.0;      ///< sideways velocity, body frame [m/s] (omni robots; 0 for diff drive)
  double wz = 0.0;      ///< yaw rate [rad/s]
};

/// @brief Draws teammates (footprint LETHAL, predicted sweep `prediction_cost`) at every update.
class RobotsLayer : public Layer
{
public:
  explicit RobotsLayer(const RobotsLayerConfig& config = RobotsLayerConfig());

  std::string name() const override { return "robots_layer"; }

  /// @brief Replace the teammates drawn from the next update on (not this robot itself).
  void setTeammates(const std::vector<TeammateState>& teammates) { teammates_ = teammates; }
  const std::vector<TeammateState>& teammates() const { return teammates_; }

  void onFootprintChanged(double robot_radius) override { robot_radius_ = robot_radius; }
  void updateBounds(const Pose2D& robot, Bounds& bounds) override;
  void updateCosts(Costmap2D& master, const CellWindow& window) override;
  void reset() override { teammates_.clear(); }

  /// @brief The poses a teammate is predicted at, from now to prediction_time (constant twist).
  std::vector<Pose2D> predict(const TeammateState& mate) const;

private:
  RobotsLayerConfig config_;
  std::vector<TeammateState> teammates_;
  double robot_radius_ = 0.0;  ///< this robot's radius [m]
  Bounds last_bounds_;         ///< what the previous update drew, to erase it
};

/**
 * @brief `scan` without the beams that hit a teammate: a hit within `margin` [m] of a teammate's
 *        footprint is the robots layer's business (it moves; the obstacle layer would leave a
 *        trail of marks behind it, and the moving obstacles layer would track it twice).
 */
ScanObservation withoutTeammateHits(const ScanObservation& scan, const std::vector<TeammateState>& teammates,
                                    double margin);

}  // namespace mbot_navigation
