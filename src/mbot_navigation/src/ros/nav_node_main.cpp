// The move_base-compatible nav node of one robot (nav_node.h). Launch it as node `move_base` in
// the robot's namespace: roslaunch mbot_navigation navigation.launch robot:=robot_0
#include <exception>

#include <ros/ros.h>

#include "mbot_navigation/ros/nav_node.h"
#include "mbot_navigation/ros/wait_for_rosout.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "move_base");
  // Held until main returns: when the last NodeHandle dies, roscpp shuts the node down and with
  // it the console, so the fatal line below would print nowhere.
  ros::NodeHandle nh;
  mbot_navigation::waitForRosout(nh, 3.0);
  std::unique_ptr<mbot_navigation::NavNode> node;
  try
  {
    node = std::make_unique<mbot_navigation::NavNode>(ros::NodeHandle(), ros::NodeHandle("~"));
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    // rosconsole publishes to /rosout from its own thread: give it time to send the line.
    ros::WallDuration(0.5).sleep();
    return 1;
  }
  ros::spin();
  return 0;
}
