// fleet_host: one process for the per-robot C++ nodes of a host (the robots' nav nodes and
// localizations), loaded as nodelets from the parameter ~nodelets, e.g.
//
//   nodelets: [{name: /robot_0/move_base, type: mbot_navigation/NavNodelet},
//              {name: /robot_0/fake_localization, type: mbot_localization/FakeLocalization}, ...]
//
// Each keeps its name, topics and parameters (/robot_0/move_base/...), as if it ran alone. A nodelet
// manager loads nodelets on request of a `nodelet load` process per nodelet, and each of those is a
// ROS node that idles on /clock: with sleeping nav nodes the loaders cost what sharing saves. This
// host loads them itself (nodelet::Loader), and still offers the manager's services
// (~load_nodelet, ~unload_nodelet, ~list) for robots added later. ~num_worker_threads: as a
// nodelet manager's. A nodelet that does not load stops the host with an error naming it.
#include <map>
#include <set>
#include <string>
#include <vector>

#include <XmlRpcValue.h>
#include <nodelet/loader.h>
#include <ros/ros.h>

#include "mbot_navigation/ros/wait_for_rosout.h"

namespace
{
struct NodeletSpec
{
  std::string name, type;
};

/// ~nodelets read strictly: a list of {name: /ns/node, type: pkg/Class}, names unique.
std::vector<NodeletSpec> readNodelets(const ros::NodeHandle& pnh)
{
  const std::string param = pnh.resolveName("nodelets");
  XmlRpc::XmlRpcValue list;
  if (!pnh.getParam("nodelets", list) || list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    throw std::runtime_error(param + ": expected a list of {name: /<robot>/<node>, type: <package>/<Class>}");
  std::vector<NodeletSpec> out;
  std::set<std::string> names;
  for (int i = 0; i < list.size(); ++i)
  {
    XmlRpc::XmlRpcValue& entry = list[i];
    const std::string where = param + "[" + std::to_string(i) + "]";
    if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct)
      throw std::runtime_error(where + ": expected {name: ..., type: ...}");
    for (auto it = entry.begin(); it != entry.end(); ++it)
      if (it->first != "name" && it->first != "type")
        throw std::runtime_error(where + ": unknown key '" + it->first + "' (known: name, type)");
    NodeletSpec spec;
    for (const char* key : {"name", "type"})
    {
      if (!entry.hasMember(key) || entry[key].getType() != XmlRpc::XmlRpcValue::TypeString)
        throw std::runtime_error(where + ": '" + key + "' must be a string");
      (std::string(key) == "name" ? spec.name : spec.type) = static_cast<std::string>(entry[key]);
    }
    if (spec.name.empty() || spec.name[0] != '/')
      throw std::runtime_error(where + ": name '" + spec.name + "' must be a full name such as /robot_0/move_base");
    if (!names.insert(spec.name).second) throw std::runtime_error(where + ": '" + spec.name + "' is loaded twice");
    out.push_back(spec);
  }
  return out;
}
}  // namespace

int main(int argc, char** argv)
{
  ros::init(argc, argv, "fleet_host");
  ros::NodeHandle nh, pnh("~");
  mbot_navigation::waitForRosout(nh, 3.0);
  try
  {
    const std::vector<NodeletSpec> nodelets = readNodelets(pnh);
    nodelet::Loader loader(true);  // the manager's services, worker threads from ~num_worker_threads
    for (const NodeletSpec& spec : nodelets)
      if (!loader.load(spec.name, spec.type, std::map<std::string, std::string>(), std::vector<std::string>()))
        throw std::runtime_error("could not load " + spec.name + " (" + spec.type + "): see the error above");
    ROS_INFO("%s: %zu nodelets loaded", ros::this_node::getName().c_str(), nodelets.size());
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("%s: %s", ros::this_node::getName().c_str(), e.what());
    ros::WallDuration(0.5).sleep();  // rosconsole publishes to /rosout from its own thread
    return 1;
  }
  return 0;
}
