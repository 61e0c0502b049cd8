/**
 * @file map_server_node.cpp
 * @brief map_server: serves an occupancy map as ROS's map_server does.
 *
 *   rosrun mbot_navigation map_server MAP.yaml     (or _map:=office, a map in the workspace maps/)
 *
 * Publishes `map` (nav_msgs/OccupancyGrid, latched) and `map_metadata` (latched), serves
 * `static_map` (nav_msgs/GetMap). Parameters: ~map (when no argument is given), ~frame_id (map).
 * A missing or broken map is one ROS_FATAL line naming the file and the problem, exit code 1.
 */
#include <stdexcept>
#include <string>

#include <nav_msgs/GetMap.h>
#include <nav_msgs/MapMetaData.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <tf2/LinearMath/Quaternion.h>

#include <mbot_common/map_io.h>
#include <mbot_common/paths.h>

#include <mbot_common/ros_edge.h>

namespace mbot_navigation
{
namespace map_server
{
nav_msgs::OccupancyGrid toOccupancyGrid(const mbot_common::OccupancyMap& map, const std::string& frame_id)
{
  nav_msgs::OccupancyGrid grid;
  grid.header.frame_id = frame_id;
  grid.header.stamp = ros::Time::now();
  grid.info.map_load_time = grid.header.stamp;
  grid.info.resolution = static_cast<float>(map.resolution);
  grid.info.width = map.width;
  grid.info.height = map.height;
  grid.info.origin.position.x = map.origin_x;
  grid.info.origin.position.y = map.origin_y;
  tf2::Quaternion q;
  q.setRPY(0.0, 0.0, map.origin_yaw);
  grid.info.origin.orientation.x = q.x();
  grid.info.origin.orientation.y = q.y();
  grid.info.origin.orientation.z = q.z();
  grid.info.origin.orientation.w = q.w();
  grid.data = map.data;  // both row-major with row 0 at the origin
  return grid;
}

class MapServerNode
{
public:
  MapServerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh, const std::string& argument)
  {
    mbot_common::StrictParams params(pnh);
    const std::string param_map = params.getString("map", "");
    const std::string frame_id = params.getString("frame_id", "map");
    params.checkNoUnknown();
    const std::string name = argument.empty() ? param_map : argument;
    if (name.empty())
      throw std::runtime_error(
          "no map given: rosrun mbot_navigation map_server MAP.yaml, or the "
          "parameter ~map (a path, or a name in the workspace maps/ folder)");
    // a bare name: maps/NAME.yaml next to this package's workspace, then mbot_common's workspace
    const std::string path =
        mbot_common::resolveMapPath(name, mbot_common::findMapsDirectory(ros::package::getPath("mbot_navigation")));

    grid_ = toOccupancyGrid(mbot_common::loadMap(path), frame_id);  // throws MapError naming the file
    map_pub_ = nh.advertise<nav_msgs::OccupancyGrid>("map", 1, true);
    metadata_pub_ = nh.advertise<nav_msgs::MapMetaData>("map_metadata", 1, true);
    service_ = nh.advertiseService("static_map", &MapServerNode::onGetMap, this);
    map_pub_.publish(grid_);
    metadata_pub_.publish(grid_.info);
    ROS_INFO("map_server: %s: %u x %u cells at %.3f m/cell, origin (%.3f, %.3f), frame %s", path.c_str(),
             grid_.info.width, grid_.info.height, grid_.info.resolution, grid_.info.origin.position.x,
             grid_.info.origin.position.y, frame_id.c_str());
  }

private:
  bool onGetMap(nav_msgs::GetMap::Request&, nav_msgs::GetMap::Response& response)
  {
    response.map = grid_;
    return true;
  }

  nav_msgs::OccupancyGrid grid_;
  ros::Publisher map_pub_, metadata_pub_;
  ros::ServiceServer service_;
};

}  // namespace map_server
}  // namespace mbot_navigation

int main(int argc, char** argv)
{
  ros::init(argc, argv, "map_server");  // removes remappings (name:=value) from argv
  ros::NodeHandle nh, pnh("~");
  if (argc > 2)
  {
    ROS_FATAL("map_server: expected at most one argument (the map), got %d", argc - 1);
    return 1;
  }
  try
  {
    mbot_navigation::map_server::MapServerNode node(nh, pnh, argc == 2 ? argv[1] : "");
    ros::spin();
  }
  catch (const std::exception& e)
  {
    std::string message = e.what();  // one line, so that a log grep finds all of it
    for (char& c : message)
      if (c == '\n') c = ' ';
    ROS_FATAL("map_server: %s", message.c_str());
    return 1;
  }
  return 0;
}
