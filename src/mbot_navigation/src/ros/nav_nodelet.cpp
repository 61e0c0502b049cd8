// The nav node (nav_node.h) as a nodelet, mbot_navigation/NavNodelet: several robots' navigation
// in one manager process share its /tf subscription and tf2 buffer (shared_tf.h), its /clock and
// its timer thread. Load it as node `move_base` in the robot's namespace (navigation.launch
// manager:=NAME); topics, actions, services and parameters are the node's.
#include <memory>
#include <stdexcept>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "mbot_navigation/ros/nav_node.h"

namespace mbot_navigation
{
class NavNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    // Each nodelet's callbacks run one at a time (its own queue), as in the node's single thread.
    try
    {
      node_ = std::make_unique<NavNode>(getNodeHandle(), getPrivateNodeHandle());
    }
    catch (const std::exception& e)
    {
      NODELET_FATAL("%s: %s", getName().c_str(), e.what());
      throw std::runtime_error(e.what());  // the manager refuses the load; its loader exits
    }
  }

  std::unique_ptr<NavNode> node_;
};

}  // namespace mbot_navigation

PLUGINLIB_EXPORT_CLASS(mbot_navigation::NavNodelet, nodelet::Nodelet)
