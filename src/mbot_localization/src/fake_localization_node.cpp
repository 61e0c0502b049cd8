// fake_localization as a node of its own (the class: mbot_localization/fake_localization.h).
#include <exception>

#include <ros/ros.h>

#include "mbot_localization/fake_localization.h"

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fake_localization");
  ros::NodeHandle nh, pnh("~");
  try
  {
    mbot_localization::FakeLocalizationNode node(nh, pnh);
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("fake_localization: %s", e.what());
    return 1;
  }
  return 0;
}
