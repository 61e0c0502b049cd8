/**
 * @file fleet_tf_relay_node.cpp
 * @brief fleet_tf_relay: /tf split per robot, so that a node that needs the poses of two robots
 *        does not receive (and a Python node does not deserialize) the whole fleet's /tf.
 *
 * Subscribes `/tf`. Every transform whose child frame is `<robot>/F` with F in `~frames`
 * (default: odom and base_footprint, the transforms that place a robot: map -> <robot>/odom from
 * its localization, <robot>/odom -> <robot>/base_footprint from its odometry) is published again
 * on `/<robot>/tf_pose` (tf2_msgs/TFMessage), the transforms of one /tf message and one robot in
 * one message. The rest (a robot's fixed joints are on /tf_static) stay on /tf. One relay serves
 * the whole fleet: each robot's topic costs the relay O(1) per transform, and each subscriber
 * gets only the robots it asked for (mbot_follower's follower controller: itself, the robot it
 * follows and the leader).
 */
#include <map>
#include <string>
#include <vector>

#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>

#include "mbot_localization/tf_relay.h"

namespace mbot_localization
{
class FleetTfRelay
{
public:
  FleetTfRelay(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh)
  {
    frames_ = pnh.param("frames", std::vector<std::string>{"odom", "base_footprint"});
    if (frames_.empty())
      throw std::runtime_error(pnh.resolveName("frames") + ": expected a list of frame names (without prefix)");
    topic_ = pnh.param("topic", std::string("tf_pose"));
    tf_sub_ = nh_.subscribe("/tf", 1000, &FleetTfRelay::onTf, this, ros::TransportHints().tcpNoDelay());
    std::string names;
    for (const std::string& f : frames_) names += (names.empty() ? "" : ", ") + f;
    ROS_INFO("fleet_tf_relay: /tf -> /<robot>/%s for the frames <robot>/{%s}", topic_.c_str(), names.c_str());
  }

private:
  void onTf(const tf2_msgs::TFMessage::ConstPtr& msg)
  {
    std::map<std::string, tf2_msgs::TFMessage> split;
    for (const geometry_msgs::TransformStamped& t : msg->transforms)
    {
      const std::string robot = robotOfTransform(t.child_frame_id, frames_);
      if (!robot.empty()) split[robot].transforms.push_back(t);
    }
    for (const auto& entry : split)
    {
      auto pub = pubs_.find(entry.first);
      if (pub == pubs_.end())
        pub =
            pubs_.emplace(entry.first, nh_.advertise<tf2_msgs::TFMessage>("/" + entry.first + "/" + topic_, 100)).first;
      pub->second.publish(entry.second);
    }
  }

  ros::NodeHandle nh_;
  std::vector<std::string> frames_;
  std::string topic_;
  ros::Subscriber tf_sub_;
  std::map<std::string, ros::Publisher> pubs_;
};

}  // namespace mbot_localization

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fleet_tf_relay");
  ros::NodeHandle nh, pnh("~");
  try
  {
    mbot_localization::FleetTfRelay relay(nh, pnh);
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("fleet_tf_relay: %s", e.what());
    std::fprintf(stderr, "fleet_tf_relay: %s\n", e.what());
    return 1;
  }
  return 0;
}
