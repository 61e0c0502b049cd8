/**
 * @file nav_node.h
 * @brief The move_base-compatible nav node of one robot: the ROS edge around Navigator
 *        (navigator.h), two CostmapRos, the goal checks and the teammates.
 *
 * Run as node `move_base` in the robot's namespace `<ns>`, so that move_base's names fall out:
 *   action  /<ns>/move_base (move_base_msgs/MoveBaseAction): SUCCEEDED, ABORTED (text says why),
 *           PREEMPTED (cancel, or a new goal)
 *   sub     /<ns>/move_base_simple/goal (PoseStamped: rviz's "2D Nav Goal"; sent on as an action goal)
 *           /<ns>/odom (the robot's velocity), /<ns>/scan, /map, teammates' topics
 *   srv     /<ns>/move_base/make_plan (nav_msgs/GetPlan), /<ns>/move_base/clear_costmaps (std_srvs/Empty)
 *   pub     /<ns>/cmd_vel, /<ns>/move_base/global_plan (latched), /<ns>/move_base/local_plan
 *           (nav_msgs/Path; while someone subscribes), /<ns>/move_base/global_costmap/costmap,
 *           /<ns>/move_base/local_costmap/costmap (nav_msgs/OccupancyGrid; the current grid to a
 *           new subscriber, then while someone subscribes)
 * The robot's pose is tf's global_frame -> robot_base_frame (map -> <ns>/base_footprint), latest,
 * no older than global_costmap/transform_tolerance; without it the robot stands still, and after
 * controller_patience the goal is aborted.
 * The action server starts once the map and the robot's pose are there (clients' wait_for_server
 * waits for that). A new goal is accepted (or rejected) by the next control cycle, not inside the
 * goal callback, as move_base does: a SimpleActionClient stores its goal handle only after
 * send_goal returns, and an instant status would reach it before that.
 * Live tuning (dynamic_reconfigure): ~DWAPlannerROS (cfg/DWAPlanner.cfg) and
 * ~global_costmap/inflation_layer, ~local_costmap/inflation_layer (cfg/Inflation.cfg).
 *
 * Parameters (~, all optional; see config/nav_*.yaml for the values the launch files use; read by
 * move_base_params.h, which also takes move_base's standard keys and planner names):
 *   robot (the namespace), model (mbot): the robot model (mbot_description) that gives the
 *     footprint radius and the velocity and acceleration limits;
 *   base_global_planner ("astar" | "ompl"; navfn/NavfnROS and global_planner/GlobalPlanner run
 *   the A*), base_local_planner ("dwa" | dwa_local_planner/DWAPlannerROS);
 *   controller_frequency [Hz] 20, planner_frequency [Hz] 0, planner_patience [s] 5,
 *   controller_patience [s] 15, oscillation_timeout [s] 0, oscillation_distance [m] 0.5,
 *   recovery_behavior_enabled (true), clearing_rotation_allowed (true), back_up_distance [m] 0.3,
 *   back_up_speed [m/s] 0.1, shutdown_costmaps (false; see below);
 *   robots (list of teammates' names; default: the simulator's /stage/robots, a cached parameter
 *   looked at every 2 s wall; without it the master's /<name>/odom topics every 10 s),
 *   robots_source ("ground_truth": /<name>/base_pose_ground_truth | "odom": /<name>/odom for the
 *   velocity + tf global_frame -> <name>/base_footprint for the pose), robots_timeout [s] 1,
 *   (the costmaps' robots_padding draws them bigger than their footprint);
 *   global_costmap/..., local_costmap/... (costmap_ros.h);
 *   DWAPlannerROS/<key> or <key> (flat) for the DWA settings, with dwa_local_planner's names
 *     (trajectory.h DwaConfig; a key set in both places must agree; limits default to the
 *     robot model's);
 *   GlobalPlanner/<key>: the A* settings (astar_planner.h AStarConfig, global_planner's names);
 *   OmplPlanner/<key>: the OMPL planner's (ompl_planner.h OmplConfig).
 * Unknown keys and wrong types stop the node with a message naming the parameter; a standard
 * move_base key that this node does not implement is one warning (docs/move_base_keys.md).
 *
 * shutdown_costmaps (move_base's): while no goal is active the node sleeps. The costmaps stop,
 * and so does everything that only feeds them and the controller: the laser, the teammates'
 * topics and their discovery, the odometry and the tf listener. What stays is the action server,
 * move_base_simple/goal, the services and the map. A new goal is accepted at once, and what can
 * be checked without tf is checked before waking (values, a goal in the global frame off the map
 * or in a wall: rejected, and the node sleeps on). Then the node wakes and sends zero velocities
 * until tf gives the robot's pose again (at most kWakeTimeout of wall time: subscribing takes wall
 * time; meanwhile each cycle waits for tf as a steering one does, so that under lockstep sim time
 * waits too), checks the rest (other frames, the path from the robot) and drives. The costmaps
 * update every cycle until their first scan. make_plan wakes the node for the call. When the goal
 * ends, the node sleeps again.
 * A sleeping node costs a timer and /clock: an idle robot of a fleet (a formation's follower,
 * driven by its own controller) does not pay for the whole fleet's /tf and teammates.
 */
#pragma once

#include <functional>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <actionlib/server/simple_action_server.h>
#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/PoseStamped.h>
#include <move_base_msgs/MoveBaseAction.h>
#include <nav_msgs/GetPlan.h>
#include <nav_msgs/Odometry.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <std_srvs/Empty.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

#include "mbot_navigation/DWAPlannerConfig.h"
#include "mbot_navigation/InflationConfig.h"
#include "mbot_navigation/ros/costmap_ros.h"
#include "mbot_navigation/ros/teammate_tracker.h"
#include "mbot_navigation/navigator/goal_checks.h"
#include "mbot_navigation/local_planner/trajectory.h"
#include "mbot_navigation/navigator/navigator.h"

namespace mbot_navigation
{
/// @brief The nav node (see the file comment).
class NavNode
{
public:
  /// @brief Read the parameters and set everything up.
  /// @throws std::runtime_error naming the parameter for a bad value (an unknown key is a warning)
  NavNode(ros::NodeHandle nh, ros::NodeHandle private_nh);

private:
  using ActionServer = actionlib::SimpleActionServer<move_base_msgs::MoveBaseAction>;

  // --- ROS callbacks
  void cycle(const ros::TimerEvent& event);
  /// Take the server's new goal: reject it, or make it the pending goal and start it when `ready`.
  void acceptGoal(bool ready);
  /// Check the pending goal with tf and the robot's pose, then drive it or reject it.
  void startPendingGoal();
  void rejectGoal(const std::string& error);
  void onPreempt();
  void onSimpleGoal(const geometry_msgs::PoseStamped::ConstPtr& goal);
  void onOdom(const nav_msgs::Odometry::ConstPtr& odom);
  bool onMakePlan(nav_msgs::GetPlan::Request& req, nav_msgs::GetPlan::Response& res);
  bool onClearCostmaps(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);

  // --- helpers
  /// The robot in the global frame from tf (latest); false and `error` when tf cannot tell.
  /// `stamp` (when given) is the transform's time. `wait`: give tf a little time to catch up
  /// (see the definition); an idle node does not wait.
  bool robotPose(Pose2D& pose, std::string& error, ros::Time* stamp = nullptr, bool wait = true) const;
  /// shutdown_costmaps: stop (sleep) and start (wake) the costmaps and their inputs.
  void sleep();
  void wake();
  /// tf gives the robot's pose (or it did not come within kWakeTimeout of waking): the pending
  /// goal can be checked and started.
  bool readyForGoal(bool has_pose) const;
  /// "" and `out` (global frame) for a usable goal, else the status text that says why not.
  std::string goalToGlobalFrame(const geometry_msgs::PoseStamped& goal, Pose2D& out) const;
  /// Why the goal cannot be taken ("" when it can); `out` is the goal in the global frame.
  std::string checkGoal(const geometry_msgs::PoseStamped& goal, Pose2D& out);
  void publishPath(const ros::Publisher& pub, const std::vector<Pose2D>& path, const ros::Time& stamp) const;
  void publishZero();
  /// Start the dynamic_reconfigure servers with the settings in force.
  void startReconfigureServers();
  void onDwaReconfigure(DWAPlannerConfig& config);
  void onInflationReconfigure(CostmapRos& costmap, InflationConfig& config);

  ros::NodeHandle nh_, private_nh_;
  std::string robot_;
  std::string odom_topic_;
  std::string global_frame_, robot_base_frame_;
  double controller_patience_ = 15.0;  ///< also how long a missing robot pose is tolerated [s]
  double transform_tolerance_ = 0.5;   ///< an older robot pose counts as missing [s] (global_costmap's)
  double control_period_ = 0.05;       ///< 1 / controller_frequency [s]
  DwaConfig dwa_config_;               ///< the settings of the local planner in force (a DwaPlanner)

  std::shared_ptr<tf2_ros::Buffer> tf_;                      ///< the process's (shared_tf.h)
  std::shared_ptr<tf2_ros::TransformListener> tf_listener_;  ///< held while awake
  std::unique_ptr<CostmapRos> global_costmap_, local_costmap_;
  std::unique_ptr<Navigator> navigator_;
  std::unique_ptr<TeammateTracker> teammates_;
  StaticGoalChecker goal_checker_;
  unsigned goal_checker_map_count_ = 0;

  std::unique_ptr<ActionServer> server_;
  bool server_started_ = false;
  ros::Publisher cmd_vel_pub_, global_plan_pub_, local_plan_pub_, action_goal_pub_;
  ros::Subscriber simple_goal_sub_, odom_sub_;
  ros::ServiceServer make_plan_srv_, clear_costmaps_srv_;
  ros::Timer cycle_timer_;
  ros::WallTimer discovery_timer_;
  boost::recursive_mutex reconfigure_mutex_;  ///< given to the servers, so that updateConfig() is safe
  std::unique_ptr<dynamic_reconfigure::Server<DWAPlannerConfig>> dwa_server_;
  std::vector<std::unique_ptr<dynamic_reconfigure::Server<InflationConfig>>> inflation_servers_;

  Twist2D velocity_;          ///< from the robot's odometry, robot frame
  ros::Time last_pose_time_;  ///< last time tf gave the robot's pose
  bool was_active_ = false;   ///< a goal was being driven in the previous cycle

  bool shutdown_costmaps_ = false;  ///< sleep while no goal is active (see the file comment)
  bool asleep_ = false;
  ros::WallTime woken_at_;  ///< of the last wake()
  /// A woken node starts its goal at the latest this long after wake() [s wall], with or without
  /// the robot's pose (a tf that never comes must not keep the goal waiting: the goal's own
  /// no-pose handling takes over).
  static constexpr double kWakeTimeout = 1.0;
  bool has_pending_goal_ = false;  ///< accepted, not checked against tf yet
  geometry_msgs::PoseStamped pending_goal_;
};

}  // namespace mbot_navigation
