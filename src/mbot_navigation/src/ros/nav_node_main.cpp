// The move_base-compatible nav node of one robot (nav_node.h). Launch it as node `move_base` in
// the robot's namespace: roslaunch mbot_navigation navigation.launch robot:=robot_0
#include <exception>

#include <ros/ros.h>

#include "mbot_navigation/ros/nav_node.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "move_base");
  std::unique_ptr<mbot_navigation::NavNode> node;
  try
  {
    node = std::make_unique<mbot_navigation::NavNode>(ros::NodeHandle(), ros::NodeHandle("~"));
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    return 1;
  }
  ros::spin();
  return 0;
}
