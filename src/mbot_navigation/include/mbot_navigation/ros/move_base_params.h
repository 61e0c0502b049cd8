/**
 * @file move_base_params.h
 * @brief The nav node's parameters as move_base reads them: move_base's own keys, the two
 *        costmaps (costmap_ros.h), global_planner / navfn and dwa_local_planner keys, with their
 *        meanings and units, so that a parameter set written for move_base loads unchanged.
 *
 * Keys are (the tables are docs/move_base_keys.md):
 *   - implemented: read, with move_base's meaning;
 *   - approximated: read, and one note (ROS_INFO) says how this node differs;
 *   - accepted and ignored: a standard key this node does not implement (say
 *     DWAPlannerROS/publish_traj_pc): one note naming it;
 *   - unknown: one warning naming it and the nearest known key, then ignored, as move_base
 *     ignores keys it does not read. Only a wrong value (type, range) stops the node.
 * Standard planner names map to ours: navfn/NavfnROS and global_planner/GlobalPlanner -> astar,
 * dwa_local_planner/DWAPlannerROS -> dwa. base_local_planner/TrajectoryPlannerROS is not supported.
 */
#pragma once

#include <string>
#include <vector>

#include <ros/node_handle.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include "mbot_navigation/DWAPlannerConfig.h"
#include "mbot_navigation/InflationConfig.h"
#include "mbot_navigation/ros/costmap_ros.h"
#include <mbot_common/ros_edge.h>
#include "mbot_navigation/navigator/navigator.h"
#include "mbot_navigation/global_planner/planner_factory.h"
#include "mbot_navigation/navigator/recovery.h"

namespace mbot_description
{
struct RobotModel;
}

namespace mbot_navigation
{
/// @brief What reading the parameters has to tell, besides errors (which throw); the node logs it.
struct ParamReport
{
  std::vector<std::string> warnings;  ///< unknown keys, each with the nearest known key (ROS_WARN)
  std::vector<std::string> notes;     ///< standard keys ignored or approximated here (ROS_INFO)
};

/**
 * @brief Keys of `p`'s namespace that are standard but not implemented: each is counted as known
 *        (also for the suggestions), and each one that is set gives one note
 *        "parameter <full name>: <what> that this node does not implement; ignored".
 * @param what e.g. "a dwa_local_planner key"
 */
void ignoreStandardKeys(mbot_common::StrictParams& p, const ros::NodeHandle& nh, const std::vector<std::string>& keys,
                        const std::string& what, ParamReport& report);

/// @brief Add a warning for each key of `p`'s namespace that nobody read (`p` in UnknownKeys::WARN).
void reportUnknownKeys(const mbot_common::StrictParams& p, ParamReport& report);

/**
 * @brief costmap_2d's searchParam(): the value of `key` in `from`'s namespace or the nearest one
 *        above it (the node's, the robot's, ...).
 * @param found the full name found ("" when none: then `default_value`)
 * @throws std::runtime_error naming the parameter when it is not a number
 */
double searchDouble(const ros::NodeHandle& from, const std::string& key, double default_value,
                    std::string* found = nullptr);

/// @brief "astar" or "ompl" for move_base's `base_global_planner` (our names or the standard
///        plugin names); @throws std::runtime_error naming the parameter otherwise.
std::string globalPlannerFor(const std::string& name, const std::string& param);
/// @brief "dwa" for "dwa" or dwa_local_planner/DWAPlannerROS; @throws std::runtime_error otherwise.
std::string localPlannerFor(const std::string& name, const std::string& param);

/// @brief The radius [m] of the circle around (0, 0) that holds costmap_2d's `footprint` (a list
///        of [x, y] points, or the same as a string "[[x, y], ...]"); @throws std::runtime_error
///        naming `param` for a malformed footprint (fewer than 3 points, not numbers).
double footprintRadius(const XmlRpc::XmlRpcValue& footprint, const std::string& param);

/// @brief Everything the nav node reads from its parameters (see nav_node.h), read once at start.
struct NavParams
{
  std::string robot;                     ///< namespace name, e.g. robot_0
  std::string model = "mbot";            ///< robot model (mbot_description)
  double footprint_radius = 0.15;        ///< of the model [m]
  std::string global_planner = "astar";  ///< ours: astar | ompl
  double controller_frequency = 20.0;    ///< [Hz]
  NavigatorConfig nav;
  bool clearing_rotation_allowed = true;
  bool shutdown_costmaps = false;   ///< stop the costmaps (and what feeds them) while no goal is active
  BackUpRecoveryConfig back_up;     ///< distance, speed (footprint filled by the node)
  double model_min_vel_x = -0.2;    ///< the model's (how fast it may back up) [m/s]
  std::vector<std::string> robots;  ///< teammates; empty: discover
  std::string robots_source = "ground_truth";
  double robots_timeout = 1.0;  ///< [s]
  CostmapRosSettings global_costmap, local_costmap;
  GlobalPlannerParams planners;
  DwaConfig dwa;
  std::string odom_topic = "odom";  ///< DWAPlannerROS/odom_topic: the velocity, in the robot's namespace
};

/**
 * @brief Read and check every parameter of the nav node in `private_nh` (the robot's namespace
 *        is `nh`), strictly (see the file comment).
 * @param description_dir the mbot_description package (robot models)
 * @throws std::runtime_error naming the parameter for a wrong type or a bad value
 */
NavParams readNavParams(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                        const std::string& description_dir, ParamReport& report);

// dynamic_reconfigure (cfg/DWAPlanner.cfg, cfg/Inflation.cfg) <-> the settings structs.
/// @brief The reconfigurable DWA settings of `dwa`, with dwa_local_planner's names.
DWAPlannerConfig toReconfigure(const DwaConfig& dwa);
/// @brief `base` with the reconfigurable settings from `config` (the footprint and the control
///        rate stay `base`'s); not validated (DwaPlanner's constructor does that).
DwaConfig fromReconfigure(const DWAPlannerConfig& config, const DwaConfig& base);
InflationConfig toReconfigure(const InflationLayerConfig& inflation);
InflationLayerConfig fromReconfigure(const InflationConfig& config);

}  // namespace mbot_navigation
