/**
 * @file critics.h
 * @brief The DWA critics: each scores a simulated trajectory. Free of ROS types.
 *
 * Model: base_local_planner/trajectory_cost_function.h and its implementations
 * (obstacle_cost_function, map_grid_cost_function, oscillation_cost_function,
 * twirling_cost_function). A critic is prepared once per control cycle, then scores every
 * sample; a negative score rejects the trajectory, a non-negative one is multiplied by the
 * critic's scale and added to the trajectory's cost (lower is better).
 */
#pragma once

#include <cstdint>
#include <string>
#include <utility>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/local_planner/trajectory.h"

namespace mbot_navigation
{
/// @brief What the critics may look at in one control cycle (all in the costmap's frame).
struct CriticContext
{
  const Costmap2D& costmap;
  const std::vector<Pose2D>& plan;  ///< the global plan, pruned behind the robot; not empty
  const Pose2D& robot_pose;         ///< [m, m, rad]
  const Twist2D& robot_velocity;    ///< [m/s, m/s, rad/s]
};

/// @brief Base of all critics: prepare() once per cycle, then score() each trajectory.
class TrajectoryCritic
{
public:
  explicit TrajectoryCritic(double scale) : scale_(scale) {}
  virtual ~TrajectoryCritic() = default;

  /// @brief Short name, used in error messages ("obstacle", "path_dist", ...).
  virtual std::string name() const = 0;

  /**
   * @brief Get ready to score trajectories of this cycle (e.g. compute a distance map).
   * @return false, with `error` set, when the critic cannot score in this situation
   */
  virtual bool prepare(const CriticContext& context, std::string& error) = 0;

  /// @brief Score of one trajectory: >= 0 is a cost (before scaling), < 0 rejects it.
  virtual double score(const Trajectory& trajectory) = 0;

  double scale() const { return scale_; }
  void setScale(double scale) { scale_ = scale; }

private:
  double scale_;
};

/**
 * @brief Rejects trajectories that collide; otherwise scores the highest cell cost under the
 *        footprint's centre along the trajectory (base_local_planner's ObstacleCostFunction).
 *
 * A pose collides when the cell under the centre has a cost >= INSCRIBED (this includes
 * NO_INFORMATION) or the circular footprint overlaps a LETHAL cell. The overlap test is made
 * per cell of the centre, for any centre within that cell (so it may see up to one cell more
 * than the exact disc), and memoised. Leaving the map rejects too.
 */
class ObstacleCritic : public TrajectoryCritic
{
public:
  /// @param footprint_radius the robot's circular footprint [m]
  ObstacleCritic(double scale, double footprint_radius);

  std::string name() const override { return "obstacle"; }
  bool prepare(const CriticContext& context, std::string& error) override;
  double score(const Trajectory& trajectory) override;

  /// @brief Cost of one pose: the centre cell's cost, or < 0 for a collision or leaving the map.
  double poseCost(double x, double y);

private:
  /// True when a LETHAL cell lies within the footprint of a robot centred anywhere in cell
  /// (mx, my). Memoised per cell for the cycle: many samples pass over the same cells.
  bool footprintHitsLethal(unsigned mx, unsigned my);

  double footprint_radius_;                        ///< [m]
  const Costmap2D* costmap_ = nullptr;             ///< the costmap of this cycle (set by prepare)
  double offsets_resolution_ = 0.0;                ///< [m/cell] the offsets below were computed for
  std::vector<std::pair<int, int>> disc_offsets_;  ///< cells under the footprint, relative [cells]
  std::vector<uint8_t> lethal_memo_;               ///< per cell: 0 unknown, 1 clear, 2 a lethal cell underneath
};

/**
 * @brief Distance map from the plan or from the local goal, by a 4-connected wavefront over the
 *        costmap (base_local_planner's MapGrid), and the critic that reads it at the last pose
 *        of a trajectory (MapGridCostFunction with the "Last" aggregation).
 *
 * The map holds distances in cells (wavefront steps); the score is that distance times the
 * resolution [m], so that the scale is the bias itself (dwa scales by bias * resolution instead).
 * Cells with a cost >= INSCRIBED are obstacles (and never targets, unlike MapGrid's), cells the
 * wavefront does not reach are unreachable. With `stop_on_failure`, a trajectory that touches an obstacle or an
 * unreachable cell is rejected. `forward_shift` [m] scores the point that far ahead of the pose (the robot's "nose")
 * instead of the pose itself. A scored point off the map rejects the trajectory.
 */
class MapGridCritic : public TrajectoryCritic
{
public:
  enum class Target
  {
    PATH,        ///< every plan cell inside the costmap is a target
    LOCAL_GOAL,  ///< only the last plan cell inside the costmap (the local goal) is
  };

  MapGridCritic(double scale, Target target, double forward_shift, bool stop_on_failure);

  double score(const Trajectory& trajectory) override;

  /// @brief Distance of a cell to the targets [cells], or obstacle() / unreachable().
  uint32_t distance(unsigned mx, unsigned my) const { return dist_[my * size_x_ + mx]; }
  uint32_t obstacle() const { return obstacle_; }
  uint32_t unreachable() const { return unreachable_; }

protected:
  /// @brief Compute the distance map from `targets` (a path, in order).
  bool computeMap(const Costmap2D& costmap, const std::vector<Pose2D>& targets, std::string& error);

private:
  Target target_;
  double forward_shift_;  ///< [m]
  bool stop_on_failure_;
  const Costmap2D* costmap_ = nullptr;
  unsigned size_x_ = 0;
  uint32_t obstacle_ = 0;        ///< map value of an obstacle cell (cells in the map)
  uint32_t unreachable_ = 0;     ///< map value of a cell the wavefront did not reach (obstacle_ + 1)
  std::vector<uint32_t> dist_;   ///< [cells]
  std::vector<uint32_t> queue_;  ///< wavefront queue (cell indices), kept to avoid reallocation
};

/// @brief Keeps the robot's centre on the plan (dwa's path_costs_, scale path_distance_bias).
class PathDistCritic : public MapGridCritic
{
public:
  explicit PathDistCritic(double scale) : MapGridCritic(scale, Target::PATH, 0.0, true) {}
  std::string name() const override { return "path_dist"; }
  bool prepare(const CriticContext& context, std::string& error) override;
};

/// @brief Draws the robot's centre towards the local goal (dwa's goal_costs_).
class GoalDistCritic : public MapGridCritic
{
public:
  explicit GoalDistCritic(double scale) : MapGridCritic(scale, Target::LOCAL_GOAL, 0.0, true) {}
  std::string name() const override { return "goal_dist"; }
  bool prepare(const CriticContext& context, std::string& error) override;
};

/**
 * @brief Keeps the robot's nose on the plan, so that it faces along the path (dwa's
 *        alignment_costs_). Switched off within forward_point_distance of the goal, where
 *        holding the nose on the path would fight the final approach.
 */
class PathAlignCritic : public MapGridCritic
{
public:
  PathAlignCritic(double scale, double forward_point_distance)
      : MapGridCritic(scale, Target::PATH, forward_point_distance, false),
        forward_point_distance_(forward_point_distance)
  {}
  std::string name() const override { return "path_align"; }
  bool prepare(const CriticContext& context, std::string& error) override;
  double score(const Trajectory& trajectory) override;

private:
  double forward_point_distance_;  ///< [m]
  bool active_ = true;
};

/**
 * @brief Draws the robot's nose towards a point forward_point_distance beyond the goal, on the
 *        line from the robot to the goal (dwa's goal_front_costs_), so that it arrives facing it.
 */
class GoalAlignCritic : public MapGridCritic
{
public:
  GoalAlignCritic(double scale, double forward_point_distance)
      : MapGridCritic(scale, Target::LOCAL_GOAL, forward_point_distance, false),
        forward_point_distance_(forward_point_distance)
  {}
  std::string name() const override { return "goal_align"; }
  bool prepare(const CriticContext& context, std::string& error) override;

private:
  double forward_point_distance_;   ///< [m]
  std::vector<Pose2D> front_plan_;  ///< the plan with its last pose moved forward
};

/**
 * @brief Forbids reversing a motion (forward/backward, left/right, turning) until the robot has
 *        moved oscillation_reset_dist or turned oscillation_reset_angle (OscillationCostFunction).
 *        Stateful: update() after each cycle with the chosen trajectory.
 */
class OscillationCritic : public TrajectoryCritic
{
public:
  /// @param reset_dist [m] @param reset_angle [rad]
  OscillationCritic(double reset_dist, double reset_angle)
      : TrajectoryCritic(1.0), reset_dist_(reset_dist), reset_angle_(reset_angle)
  {}
  std::string name() const override { return "oscillation"; }
  bool prepare(const CriticContext&, std::string&) override { return true; }
  double score(const Trajectory& trajectory) override;

  /// @brief Record the chosen command of this cycle; `min_vel_trans` [m/s] below which v_x
  ///        counts as "not driving" (only then strafing and turning set flags).
  void update(const Pose2D& robot_pose, const Trajectory& chosen, double min_vel_trans);
  /// @brief Clear all flags (new plan).
  void reset();

private:
  bool setFlags(const Trajectory& chosen, double min_vel_trans);

  double reset_dist_;   ///< [m]
  double reset_angle_;  ///< [rad]
  Pose2D flag_pose_;    ///< where the last flag was set
  // Direction of the last motion on each axis.
  bool forward_pos_ = false, forward_neg_ = false;
  bool strafe_pos_ = false, strafe_neg_ = false;
  bool rot_pos_ = false, rot_neg_ = false;
  // Restrictions: after a reversal, only this direction is allowed until the robot has moved.
  bool forward_pos_only_ = false, forward_neg_only_ = false;
  bool strafe_pos_only_ = false, strafe_neg_only_ = false;
  bool rot_pos_only_ = false, rot_neg_only_ = false;
};

/// @brief Penalises rotation: |omega| (TwirlingCostFunction). Off by default (twirling_scale 0).
class TwirlingCritic : public TrajectoryCritic
{
public:
  explicit TwirlingCritic(double scale) : TrajectoryCritic(scale) {}
  std::string name() const override { return "twirling"; }
  bool prepare(const CriticContext&, std::string&) override { return true; }
  double score(const Trajectory& trajectory) override;
};

}  // namespace mbot_navigation
