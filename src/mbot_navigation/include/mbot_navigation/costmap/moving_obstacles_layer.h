/**
 * @file moving_obstacles_layer.h
 * @brief "Moving obstacles" layer: people (and anything else unmapped that moves) predicted ahead
 *        of where the laser sees them, as the robots layer predicts teammates.
 *
 * The obstacle layer marks a walking person as LETHAL cells where the beams hit, one scan late,
 * and says nothing about where the person is heading. This layer takes the same scans (already
 * without the beams on teammates, see withoutTeammateHits()) and, per scan:
 *   1. keeps the hits that are not on the static map (further than `static_margin` from its walls);
 *   2. clusters them: hits closer than `cluster_distance` to each other are one obstacle; a
 *      cluster wider than `max_size` (a wall the map lacks, furniture) or with its centre further
 *      than `obstacle_range` from the sensor is not tracked;
 *   3. associates the clusters with the tracks: nearest neighbour to a track's predicted position,
 *      within `association_gate`; a cluster left over starts a new track, and a track not seen
 *      for `track_timeout` is dropped;
 *   4. estimates each track's velocity as the straight-line fit of its positions over the last
 *      `velocity_window` seconds.
 * A track at least `min_track_age` old moving at `min_speed`..`max_speed` gets its predicted
 * sweep drawn (sweep.h, as the robots layer does for teammates): `prediction_cost`, passable,
 * over `prediction_time` ahead, grown by this robot's radius. The first `blocked_time` of it is
 * not a guess to weigh but the body's next steps: there the body itself is drawn LETHAL (the
 * inflation layer then keeps our robot's radius off it), so the planners cannot cut in front of a
 * person who would walk into the robot before it is across; they wait or pass behind. Unlike a
 * teammate, a person does not see our plan, and a passable cost weighs little in DWA's score.
 * A robot caught well inside the blocked part (its centre within the body's radius plus half its
 * own: the body came at it, or it was crossing when the part moved onto it) gets only the passable
 * sweep of that track: a LETHAL body on it would leave it no move, not even out of the way. A
 * robot waiting beside the part stays at least the body's radius plus its own from it (DWA keeps
 * its footprint off LETHAL cells), so the exception does not let it creep into the path.
 * Obstacles standing still get no sweep:
 * the obstacle layer marks them as it always did. Every update erases the previous drawing.
 */
#pragma once

#include <deque>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/layer.h"
#include "mbot_navigation/costmap/obstacle_layer.h"
#include "mbot_navigation/costmap/sweep.h"

namespace mbot_navigation
{
/// @brief MovingObstaclesLayer settings (the keys of the file comment) and its sweep (sweep.h).
struct MovingObstaclesConfig : SweepPrediction
{
  double obstacle_range = 2.5;    ///< obstacles further from the sensor are not tracked [m] (the obstacle layer's)
  double static_margin = 0.15;    ///< hits this close to a wall of the static map are the wall [m]
  double cluster_distance = 0.2;  ///< hits closer than this to each other are one obstacle [m]
  double max_size = 1.0;          ///< wider clusters are not tracked [m] (a person is 0.3-0.5 m)
  double association_gate = 0.5;  ///< how far a cluster may be from a track's predicted position [m]
  double velocity_window = 0.5;   ///< the velocity fit covers this much of a track's history [s]
  double min_track_age = 0.3;     ///< a younger track is not predicted [s]
  double track_timeout = 0.5;     ///< a track not seen for this long is dropped [s]
  double min_speed = 0.15;        ///< slower tracks stand still (no sweep) [m/s]
  double max_speed = 2.0;         ///< faster tracks are wrong associations (no sweep) [m/s]
  double blocked_time = 1.0;      ///< the sweep's first seconds are the body's: LETHAL [s] (0: none)
};

/// @brief Throw std::invalid_argument naming the first key of `c` that is out of range.
void checkMovingObstaclesConfig(const MovingObstaclesConfig& c);

/// @brief One tracked obstacle, in the costmap frame.
struct MovingTrack
{
  /// @brief A position seen at a time.
  struct Sample
  {
    double t, x, y;  ///< [s], [m], [m]
  };
  int id = 0;                  ///< for messages and tests; new tracks count up
  double x = 0.0, y = 0.0;     ///< the newest cluster's centre [m]
  double vx = 0.0, vy = 0.0;   ///< estimated velocity [m/s] (0 until two samples)
  double radius = 0.0;         ///< the widest the cluster was seen, half of it [m]
  double first_seen = 0.0;     ///< [s]
  double last_seen = 0.0;      ///< [s]
  std::deque<Sample> history;  ///< the samples of the last velocity_window
};

/// @brief Tracks moving obstacles from laser scans and draws their predicted sweep.
class MovingObstaclesLayer : public Layer
{
public:
  explicit MovingObstaclesLayer(const MovingObstaclesConfig& config = MovingObstaclesConfig());

  std::string name() const override { return "moving_obstacles_layer"; }

  /// @brief Queue a scan (with its stamp); it is applied at the next updateMap().
  void addObservation(const ScanObservation& scan) { pending_.push_back(scan); }
  /// @brief The walls the obstacles are told apart from (the static layer's grid, kept alive by
  ///        the caller); nullptr: no map, every hit may be an obstacle.
  void setStaticMap(const Costmap2D* map) { static_map_ = map; }

  void onFootprintChanged(double robot_radius) override { robot_radius_ = robot_radius; }
  void updateBounds(const Pose2D& robot, Bounds& bounds) override;
  void updateCosts(Costmap2D& master, const CellWindow& window) override;
  void reset() override;

  const std::vector<MovingTrack>& tracks() const { return tracks_; }
  /// @brief True when `track` is old enough and moves at a believable speed (its sweep is drawn).
  bool predicted(const MovingTrack& track) const;
  /// @brief The poses a track is predicted at, from its newest position to prediction_time ahead.
  std::vector<Pose2D> predict(const MovingTrack& track) const;
  /// @brief The predicted poses (after the newest position) within blocked_time, where the
  ///        track's body is drawn LETHAL; none when the robot is caught well inside them.
  std::vector<Pose2D> blocked(const MovingTrack& track) const;

private:
  /// @brief A cluster of hits: its centre and half its width [m].
  struct Cluster
  {
    double x, y, radius;
  };
  std::vector<Cluster> clusters(const ScanObservation& scan) const;
  bool onStaticMap(double x, double y) const;
  void track(const ScanObservation& scan);

  MovingObstaclesConfig config_;
  const Costmap2D* static_map_ = nullptr;
  std::vector<ScanObservation> pending_;
  std::vector<MovingTrack> tracks_;
  int next_id_ = 1;
  double latest_stamp_ = -1.0;  ///< of the newest scan applied [s]
  double robot_radius_ = 0.0;   ///< this robot's radius [m]
  Pose2D robot_;                ///< this robot, at the last updateBounds()
  Bounds last_bounds_;          ///< what the previous update drew, to erase it
};

}  // namespace mbot_navigation
