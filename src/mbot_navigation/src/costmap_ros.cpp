#include "mbot_navigation/costmap_ros.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <tf2/exceptions.h>
#include <tf2/utils.h>

#include <mbot_common/ros_edge.h>

namespace mbot_navigation
{
using mbot_common::StrictParams;

CostmapRosSettings readCostmapSettings(const ros::NodeHandle& costmap_nh, const CostmapRosSettings& d)
{
  StrictParams p(costmap_nh);
  CostmapRosSettings s = d;
  s.global_frame = p.getString("global_frame", d.global_frame);
  s.robot_base_frame = p.getString("robot_base_frame", d.robot_base_frame);
  s.update_frequency = p.getDouble("update_frequency", d.update_frequency);
  s.publish_frequency = p.getDouble("publish_frequency", d.publish_frequency);
  s.transform_tolerance = p.getDouble("transform_tolerance", d.transform_tolerance);

  LayeredCostmapConfig& c = s.costmap;
  c.rolling_window = p.getBool("rolling_window", d.costmap.rolling_window);
  c.width = p.getDouble("width", d.costmap.width);
  c.height = p.getDouble("height", d.costmap.height);
  c.resolution = p.getDouble("resolution", d.costmap.resolution);
  c.origin_x = p.getDouble("origin_x", d.costmap.origin_x);
  c.origin_y = p.getDouble("origin_y", d.costmap.origin_y);
  c.robot_radius = p.getDouble("robot_radius", d.costmap.robot_radius);
  c.track_unknown_space = p.getBool("track_unknown_space", d.costmap.track_unknown_space);

  s.static_map = p.getBool("static_map", d.static_map);
  s.map_topic = p.getString("map_topic", d.map_topic);
  s.static_layer.track_unknown_space = c.track_unknown_space;
  s.static_layer.lethal_cost_threshold = p.getInt("lethal_cost_threshold", d.static_layer.lethal_cost_threshold);
  s.static_layer.unknown_cost_value = p.getInt("unknown_cost_value", d.static_layer.unknown_cost_value);
  s.static_layer.trinary_costmap = p.getBool("trinary_costmap", d.static_layer.trinary_costmap);

  s.scan_topic = p.getString("scan_topic", d.scan_topic);
  s.obstacle_layer.track_unknown_space = c.track_unknown_space;
  s.obstacle_layer.obstacle_range = p.getDouble("obstacle_range", d.obstacle_layer.obstacle_range);
  s.obstacle_layer.raytrace_range = p.getDouble("raytrace_range", d.obstacle_layer.raytrace_range);
  s.obstacle_layer.footprint_clearing_enabled =
      p.getBool("footprint_clearing_enabled", d.obstacle_layer.footprint_clearing_enabled);

  s.inflation_layer.inflation_radius = p.getDouble("inflation_radius", d.inflation_layer.inflation_radius);
  s.inflation_layer.cost_scaling_factor = p.getDouble("cost_scaling_factor", d.inflation_layer.cost_scaling_factor);
  s.inflation_layer.inflate_unknown = p.getBool("inflate_unknown", d.inflation_layer.inflate_unknown);

  s.robots_layer = p.getBool("robots_layer", d.robots_layer);
  s.robots.prediction_time = p.getDouble("robots_prediction_time", d.robots.prediction_time);
  s.robots.prediction_step = p.getDouble("robots_prediction_step", d.robots.prediction_step);
  const int prediction_cost = p.getInt("robots_prediction_cost", d.robots.prediction_cost);
  s.robots_padding = p.getDouble("robots_padding", d.robots_padding);
  s.robots_scan_margin = p.getDouble("robots_scan_margin", d.robots_scan_margin);
  p.checkNoUnknown();

  const std::string ns = costmap_nh.getNamespace() + "/";
  if (prediction_cost < 0 || prediction_cost >= cost::INSCRIBED)
    throw std::runtime_error("parameter " + ns + "robots_prediction_cost: expected 0..252 (below INSCRIBED), got " +
                             std::to_string(prediction_cost));
  s.robots.prediction_cost = static_cast<uint8_t>(prediction_cost);
  if (!(s.robots_padding >= 0.0))
    throw std::runtime_error("parameter " + ns + "robots_padding: expected a number >= 0 [m]");
  if (!(s.update_frequency > 0.0))
    throw std::runtime_error("parameter " + ns + "update_frequency: expected a number > 0 [Hz]");
  if (!(s.publish_frequency >= 0.0))
    throw std::runtime_error("parameter " + ns + "publish_frequency: expected a number >= 0 [Hz]");
  if (!(c.resolution > 0.0)) throw std::runtime_error("parameter " + ns + "resolution: expected a number > 0 [m/cell]");
  if (c.rolling_window && !(c.width > 0.0 && c.height > 0.0))
    throw std::runtime_error("parameter " + ns + "width/height: expected numbers > 0 [m] for a rolling window");
  if (!c.rolling_window && !s.static_map)
    throw std::runtime_error("parameter " + ns + "static_map: a costmap that is not a rolling window takes its size "
                             "from the map, so static_map must be true");
  return s;
}

int8_t occupancyFromCost(uint8_t c)
{
  if (c == cost::FREE) return 0;
  if (c == cost::INSCRIBED) return 99;
  if (c == cost::LETHAL) return 100;
  if (c == cost::NO_INFORMATION) return -1;
  return static_cast<int8_t>(1 + (97 * (c - 1)) / 251);
}

void toOccupancyGrid(const Costmap2D& costmap, nav_msgs::OccupancyGrid& grid)
{
  grid.info.resolution = static_cast<float>(costmap.resolution());
  grid.info.width = costmap.sizeX();
  grid.info.height = costmap.sizeY();
  grid.info.origin.position.x = costmap.originX();
  grid.info.origin.position.y = costmap.originY();
  grid.info.origin.position.z = 0.0;
  grid.info.origin.orientation.x = grid.info.origin.orientation.y = grid.info.origin.orientation.z = 0.0;
  grid.info.origin.orientation.w = 1.0;
  const size_t n = static_cast<size_t>(costmap.sizeX()) * costmap.sizeY();
  grid.data.resize(n);
  const uint8_t* costs = costmap.data();
  for (size_t i = 0; i < n; ++i) grid.data[i] = occupancyFromCost(costs[i]);
}

CostmapRos::CostmapRos(const std::string& name, const CostmapRosSettings& settings, ros::NodeHandle& nh,
                       ros::NodeHandle& private_nh, tf2_ros::Buffer& tf)
  : name_(name), settings_(settings), tf_(tf)
{
  layered_ = std::make_unique<LayeredCostmap>(settings.costmap);
  if (settings.static_map)
    static_layer_ =
        static_cast<StaticLayer*>(&layered_->addLayer(std::make_unique<StaticLayer>(settings.static_layer)));
  if (!settings.scan_topic.empty())
    obstacle_layer_ =
        static_cast<ObstacleLayer*>(&layered_->addLayer(std::make_unique<ObstacleLayer>(settings.obstacle_layer)));
  if (settings.robots_layer)
    robots_layer_ = static_cast<RobotsLayer*>(&layered_->addLayer(std::make_unique<RobotsLayer>(settings.robots)));
  // Last: inflate everything below, teammates included.
  layered_->addLayer(std::make_unique<InflationLayer>(settings.inflation_layer));

  ros::NodeHandle root;
  if (static_layer_) map_sub_ = root.subscribe(settings.map_topic, 1, &CostmapRos::mapCallback, this);
  if (obstacle_layer_) scan_sub_ = nh.subscribe(settings.scan_topic, 10, &CostmapRos::scanCallback, this);
  if (settings.publish_frequency > 0.0)
    costmap_pub_ = private_nh.advertise<nav_msgs::OccupancyGrid>(name + "/costmap", 1, true);
  grid_msg_.header.frame_id = settings.global_frame;
}

void CostmapRos::mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& map)
{
  if (map->header.frame_id != settings_.global_frame && !map->header.frame_id.empty())
    ROS_WARN("%s: the map is in frame '%s', not in the costmap's global_frame '%s'; using it as if it were",
             name_.c_str(), map->header.frame_id.c_str(), settings_.global_frame.c_str());
  if (map->data.size() != static_cast<size_t>(map->info.width) * map->info.height || map->info.width == 0)
  {
    ROS_ERROR("%s: ignoring a map of %ux%u cells with %zu values", name_.c_str(), map->info.width,
              map->info.height, map->data.size());
    return;
  }
  static_layer_->setMap(map->info.width, map->info.height, map->info.resolution, map->info.origin.position.x,
                        map->info.origin.position.y, map->data.data());
  last_map_ = map;
  ++map_count_;
  next_update_ = ros::Time(0);  // show the map at the next cycle
}

void CostmapRos::scanCallback(const sensor_msgs::LaserScan::ConstPtr& scan)
{
  pending_scans_.push_back(scan);
  while (pending_scans_.size() > 50) pending_scans_.pop_front();  // tf is far behind: keep the newest
}

void CostmapRos::setTeammates(const std::vector<TeammateState>& teammates)
{
  teammates_ = teammates;
}

std::vector<TeammateState> drawableTeammates(const std::vector<TeammateState>& teammates, const Pose2D& robot,
                                             double robot_radius, double resolution, double padding)
{
  std::vector<TeammateState> out = teammates;
  for (TeammateState& m : out)
  {
    // This robot's centre must stay more than its own radius (plus two cells for the grid's
    // rounding) away from the teammate's drawn disc, or its cell would be INSCRIBED.
    const double room = std::hypot(m.pose.x - robot.x, m.pose.y - robot.y) - robot_radius - 2.0 * resolution;
    m.radius += std::max(0.0, std::min(padding, room - m.radius));
  }
  return out;
}

void CostmapRos::applyScans(const ros::Time& now)
{
  std::deque<sensor_msgs::LaserScan::ConstPtr> keep;
  for (const sensor_msgs::LaserScan::ConstPtr& scan : pending_scans_)
  {
    geometry_msgs::TransformStamped t;
    try
    {
      t = tf_.lookupTransform(settings_.global_frame, scan->header.frame_id, scan->header.stamp);
    }
    catch (const tf2::ExtrapolationException& e)
    {
      // Usually the localization's transform for this stamp has not arrived yet: try again later.
      if ((now - scan->header.stamp).toSec() < settings_.transform_tolerance)
        keep.push_back(scan);
      else
        ROS_WARN_THROTTLE(5.0, "%s: dropping a scan of %.3f s that tf cannot place: %s", name_.c_str(),
                          scan->header.stamp.toSec(), e.what());
      continue;
    }
    catch (const tf2::TransformException& e)
    {
      ROS_WARN_THROTTLE(5.0, "%s: dropping a scan: %s", name_.c_str(), e.what());
      continue;
    }
    ScanObservation obs;
    obs.origin_x = t.transform.translation.x;
    obs.origin_y = t.transform.translation.y;
    obs.range_min = scan->range_min;
    obs.range_max = scan->range_max;
    const double yaw = tf2::getYaw(t.transform.rotation);
    obs.beams.reserve(scan->ranges.size());
    for (size_t i = 0; i < scan->ranges.size(); ++i)
    {
      const double angle = yaw + scan->angle_min + i * scan->angle_increment;
      const double r = scan->ranges[i];
      if (std::isfinite(r) && !teammates_.empty())
      {
        // A hit on a teammate is the robots layer's business (it moves; the obstacle layer would
        // leave a trail of marks behind it): skip the beam.
        const double hx = obs.origin_x + r * std::cos(angle), hy = obs.origin_y + r * std::sin(angle);
        bool on_mate = false;
        for (const TeammateState& m : teammates_)
          on_mate = on_mate || std::hypot(hx - m.pose.x, hy - m.pose.y) <= m.radius + settings_.robots_scan_margin;
        if (on_mate) continue;
      }
      obs.beams.push_back({angle, r});
    }
    obstacle_layer_->addObservation(obs);
  }
  pending_scans_.swap(keep);
}

void CostmapRos::update(const Pose2D& robot, const ros::Time& now)
{
  if (obstacle_layer_) applyScans(now);
  if (robots_layer_)
    robots_layer_->setTeammates(
        drawableTeammates(teammates_, robot, settings_.costmap.robot_radius, settings_.costmap.resolution,
                          settings_.robots_padding));
  layered_->updateMap(robot);
  next_update_ = now + ros::Duration(1.0 / settings_.update_frequency);
}

void CostmapRos::publishIfDue(const ros::Time& now)
{
  if (settings_.publish_frequency <= 0.0 || now < next_publish_ || !ready()) return;
  next_publish_ = now + ros::Duration(1.0 / settings_.publish_frequency);
  grid_msg_.header.stamp = now;
  toOccupancyGrid(costmap(), grid_msg_);
  grid_msg_.info.map_load_time = now;
  costmap_pub_.publish(grid_msg_);
}

void CostmapRos::clear()
{
  // Every layer forgets what it sensed (the static layer keeps its map and rewrites it), and the
  // whole master grid is rewritten at the next update.
  layered_->reset();
  next_update_ = ros::Time(0);
}

Costmap2D CostmapRos::staticCostmap() const
{
  if (!last_map_) return Costmap2D();
  LayeredCostmapConfig config = settings_.costmap;
  config.rolling_window = false;
  LayeredCostmap costmap(config);
  auto& static_layer =
      static_cast<StaticLayer&>(costmap.addLayer(std::make_unique<StaticLayer>(settings_.static_layer)));
  costmap.addLayer(std::make_unique<InflationLayer>(settings_.inflation_layer));
  static_layer.setMap(last_map_->info.width, last_map_->info.height, last_map_->info.resolution,
                      last_map_->info.origin.position.x, last_map_->info.origin.position.y,
                      last_map_->data.data());
  costmap.updateMap(Pose2D{});
  return costmap.costmap();
}

}  // namespace mbot_navigation
