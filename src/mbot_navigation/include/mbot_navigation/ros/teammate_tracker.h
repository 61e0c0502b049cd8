/**
 * @file teammate_tracker.h
 * @brief The nav node's view of its teammates, for the costmaps' robots layers: which robots
 *        there are, where they are, how fast they move and how big they are.
 */
#pragma once

#include <functional>
#include <map>
#include <string>
#include <vector>

#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "mbot_navigation/costmap/robots_layer.h"

namespace mbot_navigation
{
/**
 * @brief The teammates' states from their topics, for the robots layers: which robots (a fixed
 *        list, or discovered: the simulator's /stage/robots, else the /<name>/odom topics),
 *        their poses and velocities, and which of them reported recently enough to be trusted.
 */
class TeammateTracker
{
public:
  enum class Source
  {
    GROUND_TRUTH,  ///< /<name>/base_pose_ground_truth: pose (global frame) and velocity
    ODOM,          ///< /<name>/odom for the velocity, tf global_frame -> <name>/base_footprint for the pose
  };

  /**
   * @param nh a handle of the node (its callback queue; the topics are absolute)
   * @param self this robot's name (never a teammate)
   * @param names a fixed list of teammates; empty: discover them (discover())
   * @param radius_of footprint radius [m] of a teammate, by name
   * @param timeout a teammate not heard of for this long [s] is left out
   */
  TeammateTracker(const ros::NodeHandle& nh, tf2_ros::Buffer& tf, const std::string& self,
                  const std::string& global_frame, Source source, const std::vector<std::string>& names, double timeout,
                  std::function<double(const std::string&)> radius_of);

  /**
   * @brief Track robots not tracked yet: the simulator's list (parameter /stage/robots, cached:
   *        the master pushes its changes, so this asks the master nothing), else, at most every
   *        kTopicPollPeriod, the /<name>/odom topics (nav_msgs/Odometry) the master knows.
   */
  void discover(const ros::WallTime& now = ros::WallTime::now());
  /// Without the simulator's list: the master's topic list at most this often [s wall].
  static constexpr double kTopicPollPeriod = 10.0;
  /// @brief Unsubscribe every teammate and forget their states (the costmaps are stopped).
  void stop();
  /// @brief Subscribe them again after stop().
  void start();
  /// @brief The teammates that reported within `timeout` of `now`, in the global frame.
  std::vector<TeammateState> states(const ros::Time& now) const;
  /// @brief Names tracked so far.
  std::vector<std::string> names() const;

private:
  struct Mate
  {
    ros::Subscriber sub;
    nav_msgs::Odometry::ConstPtr last;
    double radius = 0.2;  ///< [m]
  };
  void track(const std::string& name);
  void subscribe(const std::string& name, Mate& mate);

  ros::NodeHandle nh_;
  tf2_ros::Buffer& tf_;
  std::string self_;
  std::string global_frame_;
  Source source_;
  double timeout_;
  std::function<double(const std::string&)> radius_of_;
  std::map<std::string, Mate> mates_;
  bool stopped_ = false;
  ros::WallTime next_topic_poll_;  ///< discover(): the master's topic list not before this
};

/**
 * @brief A teammate's footprint radius [m], by name: its model from the simulator's list
 *        (/stage/robots: [{name, model}]; a robot not listed has this robot's model), read once
 *        per model from mbot_description.
 */
class TeammateRadii
{
public:
  /// @param description_dir mbot_description's folder; @param own_model, own_radius this robot's
  TeammateRadii(const std::string& description_dir, const std::string& own_model, double own_radius);
  double operator()(const std::string& name);

private:
  std::string description_dir_;
  std::string own_model_;
  double own_radius_;
  std::map<std::string, double> model_radius_;  ///< cache: model name -> footprint radius [m]
};

}  // namespace mbot_navigation
