// Start-up of a process whose first lines matter (nav_node_main.cpp, fleet_host_main.cpp).
#pragma once

#include <ros/ros.h>
#include <rosgraph_msgs/Log.h>

namespace mbot_navigation
{
/// Wait (wall time, at most `timeout` s) until /rosout has a subscriber. Messages logged before
/// roscpp has connected to rosout never reach it, and the start-up lines (unknown keys, a bad
/// value, a nodelet that does not load) matter most.
inline void waitForRosout(ros::NodeHandle& nh, double timeout)
{
  // The same publication as rosconsole's: roscpp shares one per topic within a process.
  ros::Publisher rosout = nh.advertise<rosgraph_msgs::Log>("/rosout", 1);
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(timeout);
  while (rosout.getNumSubscribers() == 0 && ros::WallTime::now() < deadline && ros::ok())
    ros::WallDuration(0.01).sleep();
}

}  // namespace mbot_navigation
