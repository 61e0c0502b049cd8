// fake_localization (fake_localization.h) as a nodelet, mbot_localization/FakeLocalization: the
// robots of one host in one process (mbot_navigation's fleet_host) instead of a process each.
// Load it as `fake_localization` in the robot's namespace; topics and parameters are the node's.
#include <memory>
#include <stdexcept>

#include <nodelet/nodelet.h>
#include <pluginlib/class_list_macros.hpp>

#include "mbot_localization/fake_localization.h"

namespace mbot_localization
{
class FakeLocalizationNodelet : public nodelet::Nodelet
{
private:
  void onInit() override
  {
    try
    {
      node_ = std::make_unique<FakeLocalizationNode>(getNodeHandle(), getPrivateNodeHandle());
    }
    catch (const std::exception& e)
    {
      NODELET_FATAL("%s: %s", getName().c_str(), e.what());
      throw std::runtime_error(e.what());  // the manager refuses the load
    }
  }

  std::unique_ptr<FakeLocalizationNode> node_;
};

}  // namespace mbot_localization

PLUGINLIB_EXPORT_CLASS(mbot_localization::FakeLocalizationNodelet, nodelet::Nodelet)
