/**
 * @file fake_localization.h
 * @brief fake_localization for one robot (run it in the robot's namespace): the simulator's
 *        ground truth and the robot's odometry give the map -> <ns>/odom transform, as
 *        fake_localization does. A node (fake_localization_node.cpp) or a nodelet,
 *        mbot_localization/FakeLocalization (fake_localization_nodelet.cpp).
 *
 * Subscribes `odom` and `base_pose_ground_truth` (nav_msgs/Odometry); publishes tf
 * `map -> <ns>/odom` at most ~tf_publish_rate times per sim second (10 Hz; 0: for every odometry
 * message), post-dated by ~transform_tolerance as amcl and fake_localization do, and
 * `amcl_pose` (PoseWithCovarianceStamped) and `particlecloud` (PoseArray, one pose) for every
 * odometry message. Parameters: ~robot (default: the namespace), ~global_frame_id (map),
 * ~odom_frame_id (<robot>/odom), ~base_frame_id (<robot>/base_footprint),
 * ~transform_tolerance (0.1 s), ~tf_publish_rate (10 Hz). Sim time only: the ground truth
 * exists only in simulation.
 *
 * Why a limit: /tf goes to every tf listener of the fleet, and at the odometry rate (50 Hz per
 * robot) the localizations' transforms were most of its messages. A transform post-dated by
 * 0.1 s every 0.1 s covers every lookup up to the next one, as amcl's at its laser's rate; the
 * simulator's lockstep waits on the time of the data (the stamp less the post-dating), so a
 * slow localization holds sim time instead of leaving the followers with old poses.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <limits>
#include <memory>
#include <stdexcept>
#include <string>

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <tf2_ros/transform_broadcaster.h>

#include "mbot_localization/localization_core.h"
#include "mbot_localization/localization_ros.h"

namespace mbot_localization
{
class FakeLocalizationNode
{
public:
  FakeLocalizationNode(ros::NodeHandle& nh, ros::NodeHandle& pnh)
  {
    StrictParams params(pnh);
    const std::string robot = robotName(params, nh);
    global_frame_ = params.getString("global_frame_id", "map");
    odom_frame_ = params.getString("odom_frame_id", prefixedFrame(robot, "odom"));
    base_frame_ = params.getString("base_frame_id", prefixedFrame(robot, "base_footprint"));
    transform_tolerance_ = ros::Duration(params.getDouble("transform_tolerance", 0.1));
    const double rate = params.getDouble("tf_publish_rate", 10.0);
    if (!(rate >= 0.0) || !std::isfinite(rate))
      throw std::runtime_error(pnh.resolveName("tf_publish_rate") + ": expected a number >= 0 [Hz], got " +
                               std::to_string(rate));
    // 1 ms short of the period: stamps on a 50 Hz grid then give exactly every 5th at 10 Hz
    tf_period_ns_ = rate > 0.0 ? static_cast<int64_t>(1e9 / rate) - 1000000 : 0;
    params.checkNoUnknown();
    if (!ros::Time::isSimTime())
      throw std::runtime_error(
          "fake_localization needs /use_sim_time true: it reads the "
          "simulator's ground truth, which only exists in simulation");

    pose_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("amcl_pose", 2, true);
    cloud_pub_ = nh.advertise<geometry_msgs::PoseArray>("particlecloud", 2, true);
    // TCP_NODELAY: without it a message that spans TCP segments waits for the receiver's delayed
    // ACK (Nagle), up to 40 ms between hosts: the fleet's map -> odom came late across machines.
    const ros::TransportHints no_delay = ros::TransportHints().tcpNoDelay();
    odom_sub_ = nh.subscribe("odom", 20, &FakeLocalizationNode::onOdometry, this, no_delay);
    truth_sub_ = nh.subscribe("base_pose_ground_truth", 20, &FakeLocalizationNode::onGroundTruth, this, no_delay);
    ROS_INFO("fake_localization: %s -> %s from %s and %s", global_frame_.c_str(), odom_frame_.c_str(),
             truth_sub_.getTopic().c_str(), odom_sub_.getTopic().c_str());
  }

private:
  void onOdometry(const nav_msgs::Odometry& msg)
  {
    if (!msg.header.frame_id.empty() && msg.header.frame_id != odom_frame_)
      ROS_WARN_ONCE("fake_localization: odometry is in frame '%s', expected '%s' (~odom_frame_id)",
                    msg.header.frame_id.c_str(), odom_frame_.c_str());
    if (!msg.child_frame_id.empty() && msg.child_frame_id != base_frame_)
      ROS_WARN_ONCE("fake_localization: odometry is of frame '%s', expected '%s' (~base_frame_id)",
                    msg.child_frame_id.c_str(), base_frame_.c_str());
    matcher_.addOdometry({static_cast<int64_t>(msg.header.stamp.toNSec()), toPose2D(msg.pose.pose)});
    publishMatches();
  }

  void onGroundTruth(const nav_msgs::Odometry& msg)
  {
    matcher_.addGroundTruth({static_cast<int64_t>(msg.header.stamp.toNSec()), toPose2D(msg.pose.pose)});
    publishMatches();
  }

  void publishMatches()
  {
    for (const GroundTruthMatcher::Match& m : matcher_.takeMatches())
    {
      ros::Time stamp;
      stamp.fromNSec(static_cast<uint64_t>(m.stamp_ns));

      // (a stamp before the last one: sim time went back, a reset)
      if (m.stamp_ns - last_tf_ns_ >= tf_period_ns_ || m.stamp_ns < last_tf_ns_)
      {
        geometry_msgs::TransformStamped tf;
        tf.header.stamp = stamp + transform_tolerance_;
        tf.header.frame_id = global_frame_;
        tf.child_frame_id = odom_frame_;
        tf.transform = toTransformMsg(m.map_odom);
        broadcaster_.sendTransform(tf);
        last_tf_ns_ = m.stamp_ns;
      }

      geometry_msgs::PoseWithCovarianceStamped pose;  // exact: the covariance stays zero
      pose.header.stamp = stamp;
      pose.header.frame_id = global_frame_;
      pose.pose.pose = toPoseMsg(m.map_base);
      pose_pub_.publish(pose);

      geometry_msgs::PoseArray cloud;
      cloud.header = pose.header;
      cloud.poses.push_back(pose.pose.pose);
      cloud_pub_.publish(cloud);
    }
  }

  std::string global_frame_, odom_frame_, base_frame_;
  ros::Duration transform_tolerance_;
  int64_t tf_period_ns_ = 0;
  int64_t last_tf_ns_ = std::numeric_limits<int64_t>::min() / 2;  // the first match goes out
  GroundTruthMatcher matcher_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Publisher pose_pub_, cloud_pub_;
  ros::Subscriber odom_sub_, truth_sub_;
};

}  // namespace mbot_localization
