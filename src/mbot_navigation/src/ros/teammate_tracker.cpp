#include "mbot_navigation/ros/teammate_tracker.h"

#include <cmath>
#include <regex>

#include <tf2/exceptions.h>

#include "mbot_description/robot_model.h"
#include <mbot_common/ros_edge.h>

namespace mbot_navigation
{
TeammateTracker::TeammateTracker(const ros::NodeHandle& nh, tf2_ros::Buffer& tf, const std::string& self,
                                 const std::string& global_frame, Source source, const std::vector<std::string>& names,
                                 double timeout, std::function<double(const std::string&)> radius_of)
    : nh_(nh),
      tf_(tf),
      self_(self),
      global_frame_(global_frame),
      source_(source),
      timeout_(timeout),
      radius_of_(std::move(radius_of))
{
  for (const std::string& name : names)
    if (name != self_) track(name);
}

void TeammateTracker::track(const std::string& name)
{
  if (mates_.count(name)) return;
  Mate& mate = mates_[name];
  mate.radius = radius_of_(name);
  if (!stopped_) subscribe(name, mate);
  ROS_INFO("teammate %s: from /%s/%s (radius %.2f m)", name.c_str(), name.c_str(),
           source_ == Source::GROUND_TRUTH ? "base_pose_ground_truth" : "odom", mate.radius);
}

void TeammateTracker::subscribe(const std::string& name, Mate& mate)
{
  const std::string topic = "/" + name + (source_ == Source::GROUND_TRUTH ? "/base_pose_ground_truth" : "/odom");
  mate.sub = nh_.subscribe<nav_msgs::Odometry>(
      topic, 1, [this, name](const nav_msgs::Odometry::ConstPtr& msg) { mates_[name].last = msg; }, ros::VoidConstPtr(),
      ros::TransportHints().tcpNoDelay());
}

void TeammateTracker::stop()
{
  for (auto& kv : mates_)
  {
    kv.second.sub.shutdown();
    kv.second.last.reset();
  }
  stopped_ = true;
}

void TeammateTracker::start()
{
  if (!stopped_) return;
  stopped_ = false;
  for (auto& kv : mates_) subscribe(kv.first, kv.second);
}

void TeammateTracker::discover(const ros::WallTime& now)
{
  // The simulator's list of its robots: a cached parameter, which the master pushes to this
  // process when it changes, so reading it asks the master nothing.
  XmlRpc::XmlRpcValue list;
  if (ros::param::getCached("/stage/robots", list) && list.getType() == XmlRpc::XmlRpcValue::TypeArray)
  {
    for (int i = 0; i < list.size(); ++i)
      if (list[i].getType() == XmlRpc::XmlRpcValue::TypeStruct && list[i].hasMember("name") &&
          list[i]["name"].getType() == XmlRpc::XmlRpcValue::TypeString)
      {
        const std::string name = static_cast<std::string>(list[i]["name"]);
        if (name != self_) track(name);
      }
    return;
  }
  // No simulator (a real fleet whose launch set no ~robots): the master's topic list, rarely.
  if (now < next_topic_poll_) return;
  next_topic_poll_ = now + ros::WallDuration(kTopicPollPeriod);
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return;
  static const std::regex odom_topic("^/([^/]+)/odom$");
  for (const ros::master::TopicInfo& t : topics)
  {
    std::smatch m;
    if (t.datatype != "nav_msgs/Odometry" || !std::regex_match(t.name, m, odom_topic)) continue;
    if (m[1] != self_) track(m[1]);
  }
}

std::vector<std::string> TeammateTracker::names() const
{
  std::vector<std::string> out;
  for (const auto& kv : mates_) out.push_back(kv.first);
  return out;
}

std::vector<TeammateState> TeammateTracker::states(const ros::Time& now) const
{
  std::vector<TeammateState> out;
  for (const auto& kv : mates_)
  {
    const nav_msgs::Odometry::ConstPtr& msg = kv.second.last;
    if (!msg || std::fabs((now - msg->header.stamp).toSec()) > timeout_) continue;
    TeammateState s;
    s.name = kv.first;
    s.radius = kv.second.radius;
    s.vx = msg->twist.twist.linear.x;
    s.vy = msg->twist.twist.linear.y;
    s.wz = msg->twist.twist.angular.z;
    if (source_ == Source::GROUND_TRUTH)
    {
      s.pose = mbot_common::toPose2D(msg->pose.pose);
    }
    else
    {
      try
      {
        s.pose = mbot_common::toPose2D(
            tf_.lookupTransform(global_frame_, kv.first + "/base_footprint", ros::Time(0)).transform);
      }
      catch (const tf2::TransformException&)
      {
        continue;  // no pose for it yet
      }
    }
    out.push_back(s);
  }
  return out;
}

TeammateRadii::TeammateRadii(const std::string& description_dir, const std::string& own_model, double own_radius)
    : description_dir_(description_dir), own_model_(own_model), own_radius_(own_radius)
{
  model_radius_[own_model_] = own_radius_;
}

double TeammateRadii::operator()(const std::string& name)
{
  // The simulator lists its robots' models in /stage/robots ([{name, model}]); else assume ours.
  std::string model = own_model_;
  XmlRpc::XmlRpcValue list;
  if (ros::param::getCached("/stage/robots", list) && list.getType() == XmlRpc::XmlRpcValue::TypeArray)
    for (int i = 0; i < list.size(); ++i)
      if (list[i].getType() == XmlRpc::XmlRpcValue::TypeStruct && list[i].hasMember("name") &&
          list[i].hasMember("model") && static_cast<std::string>(list[i]["name"]) == name)
        model = static_cast<std::string>(list[i]["model"]);
  auto it = model_radius_.find(model);
  if (it != model_radius_.end()) return it->second;
  double radius = own_radius_;
  try
  {
    radius = mbot_description::loadRobotModel(description_dir_, model).footprint_radius;
  }
  catch (const std::exception& e)
  {
    ROS_WARN("teammate %s: cannot load model '%s' (%s); assuming radius %.2f m", name.c_str(), model.c_str(), e.what(),
             radius);
  }
  model_radius_[model] = radius;
  return radius;
}

}  // namespace mbot_navigation
