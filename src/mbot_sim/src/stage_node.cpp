/**
 * @file stage_node.cpp
 * @brief stage_node: the headless multi-robot simulator. Builds StageRos and runs it; a bad
 *        world file or parameter ends the node with one ROS_FATAL line and exit code 1.
 *
 *   rosrun mbot_sim stage_node _world:=office _real_time_factor:=5
 */
#include "mbot_sim/stage_ros.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "stage_node");
  ros::NodeHandle nh;
  ros::NodeHandle private_nh("~");
  try
  {
    mbot_sim::StageRos node(nh, mbot_sim::readStageParams(private_nh));
    node.run();
  }
  catch (const mbot_sim::StartupError& e)
  {
    ROS_FATAL("%s", e.what());
    return 1;
  }
  catch (const std::exception& e)  // a bug, not bad input; still one line and no core dump
  {
    ROS_FATAL("stage_node: unexpected error: %s", e.what());
    return 1;
  }
  return 0;
}
