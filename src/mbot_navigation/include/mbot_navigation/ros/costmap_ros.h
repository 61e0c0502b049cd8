/**
 * @file costmap_ros.h
 * @brief The ROS edge of one layered costmap (costmap_2d's Costmap2DROS): reads its parameters
 *        with costmap_2d's names, feeds the layers from the map, the laser (via tf2) and the
 *        teammates, and publishes the grid as nav_msgs/OccupancyGrid (costmap_2d's 0..100
 *        translation). The layers themselves (layer.h) know nothing of ROS.
 *
 * Layers, bottom to top: static (the map), obstacle (laser), moving obstacles (people, from the
 * same laser), robots (teammates), inflation, or
 * in the order that `plugins` lists them (each layer works on the grid that the layers below it
 * made: an inflation layer inflates only what is below it). The
 * nav node owns two: `global_costmap` (the size of the map) and `local_costmap` (a rolling window
 * around the robot). Both must use the same global_frame (the plan is shared between them).
 *
 * Parameters (in ~<name>/, all optional), in either of costmap_2d's two forms (move_base_params.h
 * tells how standard keys this node does not implement are treated; docs/move_base_keys.md lists them):
 *   - `plugins: [{name: N, type: T}, ...]`: the layers listed, T one of costmap_2d::StaticLayer,
 *     costmap_2d::ObstacleLayer (VoxelLayer: read as a 2-D obstacle layer), costmap_2d::InflationLayer,
 *     mbot_navigation::RobotsLayer, mbot_navigation::MovingObstaclesLayer (it tracks the obstacle
 *     layer's LaserScan source, so it needs that layer); each layer's keys in ~<name>/N/ (`enabled:
 *     false` leaves it out);
 *   - flat, costmap_2d's pre-layer style (the keys below); `static_map` and `map_type` as there.
 * Flat keys:
 *   global_frame (map), robot_base_frame (<robot>/base_footprint), update_frequency [Hz],
 *   publish_frequency [Hz], transform_tolerance [s], rolling_window, width [m], height [m],
 *   resolution [m/cell], origin_x [m], origin_y [m], robot_radius [m] (default: the URDF's),
 *   track_unknown_space,
 *   static_map (use the static layer), map_topic (/map), lethal_cost_threshold,
 *   unknown_cost_value, trinary_costmap,
 *   scan_topic (LaserScan topic in the robot's namespace; "" turns the obstacle layer off),
 *   obstacle_range [m], raytrace_range [m], footprint_clearing_enabled,
 *   inflation_radius [m], cost_scaling_factor [1/m], inflate_unknown,
 *   robots_layer (draw teammates), robots_prediction_time [s], robots_prediction_step [s],
 *   robots_prediction_cost [0..252], robots_padding [m] (teammates are drawn this much bigger
 *   than their footprint: their reported pose is a little old, and two robots passing each other
 *   keep this gap more), robots_scan_margin [m] (laser hits this close to a teammate's footprint
 *   are not marked as obstacles: the robots layer draws the teammate),
 *   moving_obstacles_layer (track people in the scans; off without scan_topic), and the keys of
 *   moving_obstacles_layer.h prefixed `moving_obstacles_` (moving_obstacles_prediction_time [s], ...).
 */
#pragma once

#include <deque>
#include <memory>
#include <string>
#include <vector>

#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>

#include "mbot_navigation/costmap/inflation_layer.h"
#include "mbot_navigation/costmap/layered_costmap.h"
#include "mbot_navigation/costmap/moving_obstacles_layer.h"
#include "mbot_navigation/costmap/obstacle_layer.h"
#include "mbot_navigation/costmap/robots_layer.h"
#include "mbot_navigation/costmap/static_layer.h"

namespace mbot_navigation
{
/// @brief The kinds of layer a CostmapRos can stack (at most one of each).
enum class LayerKind
{
  STATIC,     ///< the map (StaticLayer)
  OBSTACLE,   ///< the laser (ObstacleLayer)
  ROBOTS,     ///< the teammates (RobotsLayer)
  MOVING,     ///< people and other moving obstacles the laser tracks (MovingObstaclesLayer)
  INFLATION,  ///< InflationLayer
};

/// @brief Everything a CostmapRos is configured with (read once, at start-up).
struct CostmapRosSettings
{
  std::string global_frame = "map";
  std::string robot_base_frame = "base_footprint";
  double update_frequency = 5.0;     ///< [Hz] sim time
  double publish_frequency = 1.0;    ///< [Hz] sim time; 0: never
  double transform_tolerance = 0.5;  ///< a scan older than this that tf cannot place is dropped [s]
  LayeredCostmapConfig costmap;      ///< rolling_window, width, height, resolution, origin, robot_radius

  bool static_map = true;
  std::string map_topic = "/map";
  StaticLayerConfig static_layer;

  std::string scan_topic = "scan";  ///< "" = no obstacle layer
  ObstacleLayerConfig obstacle_layer;

  bool inflation = true;  ///< false only when `plugins` leaves the inflation layer out
  InflationLayerConfig inflation_layer;
  std::string inflation_layer_name = "inflation_layer";  ///< its namespace (dynamic_reconfigure)

  bool robots_layer = true;
  RobotsLayerConfig robots;
  double robots_padding = 0.1;       ///< [m]
  double robots_scan_margin = 0.15;  ///< [m]

  bool moving_obstacles = true;  ///< built only with a scan source (scan_topic)
  MovingObstaclesConfig moving;  ///< its obstacle_range is the obstacle layer's

  /// The layers bottom to top: costmap_2d's pre-layer order, or the order of `plugins`. A layer
  /// listed here is built only when it is on (static_map, scan_topic, moving_obstacles, robots_layer,
  /// inflation).
  std::vector<LayerKind> layer_order{LayerKind::STATIC, LayerKind::OBSTACLE, LayerKind::MOVING, LayerKind::ROBOTS,
                                     LayerKind::INFLATION};
};

struct ParamReport;  // move_base_params.h

/**
 * @brief Read ~<name>/ (see the file comment): a wrong type or a bad value throws
 *        std::runtime_error naming the parameter; an unknown key adds a warning to `report` (when
 *        given), a standard costmap_2d key that this node ignores or approximates a note.
 * @param defaults the values of keys that are not set (the caller fills robot_radius, frames...)
 */
CostmapRosSettings readCostmapSettings(const ros::NodeHandle& costmap_nh, const CostmapRosSettings& defaults,
                                       ParamReport* report = nullptr);

/// @brief costmap_2d's translation of a cost to an OccupancyGrid value: 0 -> 0, 1..252 -> 1..98,
///        INSCRIBED -> 99, LETHAL -> 100, NO_INFORMATION -> -1.
int8_t occupancyFromCost(uint8_t cost);

/// @brief Fill an OccupancyGrid (info and data) from a costmap.
void toOccupancyGrid(const Costmap2D& costmap, nav_msgs::OccupancyGrid& grid);

/**
 * @brief The teammates as the robots layer should draw them for a robot at `robot` [m, m, rad]:
 *        `padding` [m] bigger than their footprint, except that the padding shrinks for a teammate
 *        so close that it would put this robot's own cell into its INSCRIBED zone, where the
 *        local planner rejects every trajectory (they all start in collision) and the robot could
 *        not even move away. The footprint itself is never shrunk.
 * @param robot_radius this robot's radius [m]; @param resolution of the costmap [m/cell]
 */
std::vector<TeammateState> drawableTeammates(const std::vector<TeammateState>& teammates, const Pose2D& robot,
                                             double robot_radius, double resolution, double padding);

/// @brief One layered costmap with its subscriptions and its publisher; see the file comment.
class CostmapRos
{
public:
  /**
   * @param name "global_costmap" or "local_costmap": the topic is ~<name>/costmap
   * @param nh the robot's namespace (scan_topic is resolved in it)
   * @param private_nh the nav node's private namespace
   */
  CostmapRos(const std::string& name, const CostmapRosSettings& settings, ros::NodeHandle& nh,
             ros::NodeHandle& private_nh, tf2_ros::Buffer& tf);

  /// @brief True once the map has arrived (always true without a static layer).
  bool ready() const { return !settings_.static_map || map_count_ > 0; }

  /// @brief Stop updating (move_base's shutdown_costmaps): the laser is unsubscribed, what was
  ///        pending is dropped, and the grid keeps its last state; update() must not be called
  ///        until start(). The map subscription stays (it is latched: no traffic).
  void stop();
  /// @brief Start again after stop(): subscribe the laser and forget what the layers sensed
  ///        before the stop (the robot may have moved since; the grid shows the map until the
  ///        next update). Updates come every cycle until a scan has been applied.
  void start();
  bool stopped() const { return stopped_; }
  /// @brief Running and, with a laser, at least one scan applied since start(): the grid shows
  ///        what the robot sees now (until then only the map and the teammates).
  bool current() const { return !stopped_ && !warming_; }
  /// @brief Number of maps received so far (the nav node rebuilds its goal checks when it grows).
  unsigned mapCount() const { return map_count_; }

  /// @brief The teammates to draw (robots layer, see drawableTeammates()) and to keep out of the
  ///        obstacle and moving obstacles layers, from the next update() on.
  void setTeammates(const std::vector<TeammateState>& teammates);

  /// @brief True when update_frequency says that the next update is due at `now`, and every
  ///        cycle after start() until a scan has been applied (see current()).
  bool updateDue(const ros::Time& now) const { return now >= next_update_ || warming_; }
  /**
   * @brief Apply the scans received since the last update (transformed with tf2 into global_frame
   *        at their stamps) and update the grid around the robot at `robot` (global_frame).
   */
  void update(const Pose2D& robot, const ros::Time& now);
  /// @brief Publish the grid when publish_frequency says so and someone subscribes (a new
  ///        subscriber gets the current grid at once, as from costmap_2d).
  void publishIfDue(const ros::Time& now);

  /// @brief Forget what the laser and the teammates marked (clear_costmaps); the map stays.
  void clear();

  /// @brief New inflation settings (dynamic_reconfigure), in force from the next update().
  /// @throws std::invalid_argument for values out of range
  void setInflation(const InflationLayerConfig& config);

  const Costmap2D& costmap() const { return layered_->costmap(); }
  const CostmapRosSettings& settings() const { return settings_; }
  const std::string& name() const { return name_; }

  /// @brief The static map inflated as this costmap inflates it (static and inflation layers only):
  ///        what no sensor can change, for the goal checks. Empty before the map arrives.
  Costmap2D staticCostmap() const;

private:
  void mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& map);
  void scanCallback(const sensor_msgs::LaserScan::ConstPtr& scan);
  void subscribeScans();
  /// The grid to one new subscriber (nobody else gets a copy).
  void onSubscriber(const ros::SingleSubscriberPublisher& pub);
  /// Transform the pending scans into observations; keep those tf cannot place yet.
  void applyScans(const ros::Time& now);
  /// Forget what the layers sensed; the grid is redrawn from the map at once when the updates
  /// are stopped (nobody would redraw it), else at the next update.
  void resetLayers();

  std::string name_;
  CostmapRosSettings settings_;
  ros::NodeHandle nh_;  ///< the robot's namespace: the scan topic is resolved in it
  tf2_ros::Buffer& tf_;
  std::unique_ptr<LayeredCostmap> layered_;
  // Non-owning views of the layers (owned by layered_); nullptr when off.
  StaticLayer* static_layer_ = nullptr;
  ObstacleLayer* obstacle_layer_ = nullptr;
  RobotsLayer* robots_layer_ = nullptr;
  MovingObstaclesLayer* moving_layer_ = nullptr;
  InflationLayer* inflation_layer_ = nullptr;

  ros::Subscriber map_sub_, scan_sub_;
  ros::Publisher costmap_pub_;
  nav_msgs::OccupancyGrid::ConstPtr last_map_;
  unsigned map_count_ = 0;
  std::deque<sensor_msgs::LaserScan::ConstPtr> pending_scans_;
  std::vector<TeammateState> teammates_;
  ros::Time next_update_, next_publish_;
  nav_msgs::OccupancyGrid grid_msg_;  ///< reused
  bool stopped_ = false;
  bool warming_ = false;  ///< started, and no scan applied since
  bool updated_ = false;  ///< update() ran once: last_robot_ is set
  Pose2D last_robot_;     ///< the robot's pose at the last update()
};

}  // namespace mbot_navigation
