#include "mbot_navigation/ros/costmap_ros.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include <tf2/exceptions.h>
#include <tf2/utils.h>

#include <mbot_common/ros_edge.h>
#include "mbot_navigation/ros/move_base_params.h"

namespace mbot_navigation
{
using mbot_common::StrictParams;

namespace
{
std::string stripSlash(std::string frame)
{
  // costmap_2d (noetic) drops a leading '/' (tf1 style, as in older tutorials); tf2 rejects it.
  while (!frame.empty() && frame.front() == '/') frame.erase(0, 1);
  return frame;
}

// costmap_2d keys this node does not implement, by where they appear.
const std::vector<std::string> kIgnoredCostmapKeys = {"always_send_full_costmap"};
const std::vector<std::string> kIgnoredStaticKeys = {"first_map_only", "subscribe_to_updates", "use_maximum"};
// Obstacle (and voxel) layer keys: this layer is 2-D, fed by one laser, always combined by maximum.
const std::vector<std::string> kIgnoredObstacleKeys = {
    "max_obstacle_height", "min_obstacle_height", "combination_method", "origin_z", "z_resolution", "z_voxels",
    "unknown_threshold",   "mark_threshold",      "publish_voxel_map"};
const std::vector<std::string> kIgnoredSourceKeys = {
    "sensor_frame",        "observation_persistence", "expected_update_rate", "min_obstacle_height",
    "max_obstacle_height", "obstacle_min_range",      "raytrace_min_range"};
// Found with searchParam from an observation source upwards (its layer, the costmap, the node).
const std::vector<std::string> kSearchedRangeKeys = {"obstacle_range", "raytrace_range", "obstacle_max_range",
                                                     "raytrace_max_range"};
// Flat layer keys: with `plugins`, costmap_2d reads them from the layers' namespaces instead.
const std::vector<std::string> kFlatLayerKeys = {"static_map",
                                                 "map_type",
                                                 "map_topic",
                                                 "lethal_cost_threshold",
                                                 "unknown_cost_value",
                                                 "trinary_costmap",
                                                 "first_map_only",
                                                 "subscribe_to_updates",
                                                 "use_maximum",
                                                 "scan_topic",
                                                 "observation_sources",
                                                 "footprint_clearing_enabled",
                                                 "max_obstacle_height",
                                                 "min_obstacle_height",
                                                 "combination_method",
                                                 "origin_z",
                                                 "z_resolution",
                                                 "z_voxels",
                                                 "unknown_threshold",
                                                 "mark_threshold",
                                                 "publish_voxel_map",
                                                 "inflation_radius",
                                                 "cost_scaling_factor",
                                                 "inflate_unknown",
                                                 "robots_layer",
                                                 "robots_prediction_time",
                                                 "robots_prediction_step",
                                                 "robots_prediction_cost",
                                                 "robots_padding",
                                                 "robots_scan_margin",
                                                 "moving_obstacles_layer",
                                                 "moving_obstacles_prediction_time",
                                                 "moving_obstacles_prediction_step",
                                                 "moving_obstacles_prediction_cost",
                                                 "moving_obstacles_static_margin",
                                                 "moving_obstacles_cluster_distance",
                                                 "moving_obstacles_max_size",
                                                 "moving_obstacles_association_gate",
                                                 "moving_obstacles_velocity_window",
                                                 "moving_obstacles_min_track_age",
                                                 "moving_obstacles_track_timeout",
                                                 "moving_obstacles_min_speed",
                                                 "moving_obstacles_max_speed",
                                                 "moving_obstacles_blocked_time"};

/// The static layer's keys of `p` (the costmap's namespace, or the layer's).
void readStaticLayer(StrictParams& p, const ros::NodeHandle& nh, CostmapRosSettings& s, ParamReport& r)
{
  s.map_topic = p.getString("map_topic", s.map_topic);
  s.static_layer.lethal_cost_threshold = p.getInt("lethal_cost_threshold", s.static_layer.lethal_cost_threshold);
  s.static_layer.unknown_cost_value = p.getInt("unknown_cost_value", s.static_layer.unknown_cost_value);
  s.static_layer.trinary_costmap = p.getBool("trinary_costmap", s.static_layer.trinary_costmap);
  ignoreStandardKeys(p, nh, kIgnoredStaticKeys, "a costmap_2d static layer key", r);
}

/// A source's range, found as costmap_2d finds it: noetic's `<name>_max_range`, else the older
/// `<name>_range`, each with searchParam from the source's namespace upwards.
double searchRange(const ros::NodeHandle& source_nh, const std::string& name, double default_value)
{
  std::string found;
  const double value = searchDouble(source_nh, name + "_max_range", default_value, &found);
  return found.empty() ? searchDouble(source_nh, name + "_range", default_value) : value;
}

/// The obstacle layer's keys: ours (scan_topic) or costmap_2d's observation_sources, of which one
/// LaserScan source is used. The ranges are searched from the source upwards, as in costmap_2d.
void readObstacleLayer(StrictParams& p, const ros::NodeHandle& nh, CostmapRosSettings& s, ParamReport& r)
{
  ObstacleLayerConfig& o = s.obstacle_layer;
  for (const std::string& key : kSearchedRangeKeys) p.markKnown(key);
  o.obstacle_range = searchRange(nh, "obstacle", o.obstacle_range);
  o.raytrace_range = searchRange(nh, "raytrace", o.raytrace_range);
  o.footprint_clearing_enabled = p.getBool("footprint_clearing_enabled", o.footprint_clearing_enabled);
  ignoreStandardKeys(p, nh, kIgnoredObstacleKeys, "a costmap_2d obstacle layer key", r);
  const bool has_scan_topic = nh.hasParam("scan_topic");
  s.scan_topic = p.getString("scan_topic", s.scan_topic);
  if (!nh.hasParam("observation_sources")) return;
  if (has_scan_topic)
    throw std::runtime_error("parameters " + nh.resolveName("scan_topic") + " and " +
                             nh.resolveName("observation_sources") + ": set one of them");
  std::istringstream names(p.getString("observation_sources", ""));
  s.scan_topic.clear();  // no LaserScan source: no obstacle layer
  std::string name;
  while (names >> name)
  {
    const ros::NodeHandle source_nh(nh, name);
    StrictParams sp{source_nh, mbot_common::UnknownKeys::WARN};
    p.markKnown(name);
    // costmap_2d's defaults; a source without `topic` subscribes to its own name.
    const std::string data_type = sp.getString("data_type", "PointCloud");
    const std::string topic = sp.getString("topic", name);
    const bool marking = sp.getBool("marking", true), clearing = sp.getBool("clearing", false);
    const bool inf_is_valid = sp.getBool("inf_is_valid", false);
    for (const std::string& key : kSearchedRangeKeys) sp.markKnown(key);
    const double obstacle_range = searchRange(source_nh, "obstacle", o.obstacle_range);
    const double raytrace_range = searchRange(source_nh, "raytrace", o.raytrace_range);
    ignoreStandardKeys(sp, source_nh, kIgnoredSourceKeys, "a costmap_2d observation source key", r);
    reportUnknownKeys(sp, r);
    if (data_type != "LaserScan" && data_type != "PointCloud" && data_type != "PointCloud2")
      throw std::runtime_error("parameter " + source_nh.resolveName("data_type") +
                               ": expected LaserScan, PointCloud or PointCloud2, got '" + data_type + "'");
    if (data_type != "LaserScan")
      r.notes.push_back("observation source " + source_nh.getNamespace() + ": data_type " + data_type +
                        " is not implemented (LaserScan only); ignored");
    else if (!s.scan_topic.empty())
      r.notes.push_back("observation source " + source_nh.getNamespace() +
                        ": only one LaserScan source is implemented (" + s.scan_topic + " is used); ignored");
    else
    {
      s.scan_topic = topic;
      o.obstacle_range = obstacle_range;
      o.raytrace_range = raytrace_range;
      o.marking = marking;
      o.clearing = clearing;
      o.inf_is_valid = inf_is_valid;
    }
  }
}

void readInflationLayer(StrictParams& p, CostmapRosSettings& s)
{
  InflationLayerConfig& c = s.inflation_layer;
  c.inflation_radius = p.getDouble("inflation_radius", c.inflation_radius);
  c.cost_scaling_factor = p.getDouble("cost_scaling_factor", c.cost_scaling_factor);
  c.inflate_unknown = p.getBool("inflate_unknown", c.inflate_unknown);
}

/// The robots layer (ours): flat keys are robots_<key>, in a plugin's namespace plain <key>.
void readRobotsLayer(StrictParams& p, const std::string& prefix, CostmapRosSettings& s, int& prediction_cost)
{
  s.robots.prediction_time = p.getDouble(prefix + "prediction_time", s.robots.prediction_time);
  s.robots.prediction_step = p.getDouble(prefix + "prediction_step", s.robots.prediction_step);
  prediction_cost = p.getInt(prefix + "prediction_cost", prediction_cost);
  s.robots_padding = p.getDouble(prefix + "padding", s.robots_padding);
  s.robots_scan_margin = p.getDouble(prefix + "scan_margin", s.robots_scan_margin);
}

/// The moving obstacles layer (ours): flat keys are moving_obstacles_<key>, in a plugin's namespace
/// plain <key>. `where` names the namespace in errors (the core names the key).
void readMovingLayer(StrictParams& p, const std::string& prefix, const std::string& where, CostmapRosSettings& s)
{
  MovingObstaclesConfig& m = s.moving;
  m.prediction_time = p.getDouble(prefix + "prediction_time", m.prediction_time);
  m.prediction_step = p.getDouble(prefix + "prediction_step", m.prediction_step);
  const int prediction_cost = p.getInt(prefix + "prediction_cost", m.prediction_cost);
  if (prediction_cost < 0 || prediction_cost >= cost::INSCRIBED)
    throw std::runtime_error(where + prefix + "prediction_cost: expected 0..252 (below INSCRIBED), got " +
                             std::to_string(prediction_cost));
  m.prediction_cost = static_cast<uint8_t>(prediction_cost);
  m.static_margin = p.getDouble(prefix + "static_margin", m.static_margin);
  m.cluster_distance = p.getDouble(prefix + "cluster_distance", m.cluster_distance);
  m.max_size = p.getDouble(prefix + "max_size", m.max_size);
  m.association_gate = p.getDouble(prefix + "association_gate", m.association_gate);
  m.velocity_window = p.getDouble(prefix + "velocity_window", m.velocity_window);
  m.min_track_age = p.getDouble(prefix + "min_track_age", m.min_track_age);
  m.track_timeout = p.getDouble(prefix + "track_timeout", m.track_timeout);
  m.min_speed = p.getDouble(prefix + "min_speed", m.min_speed);
  m.max_speed = p.getDouble(prefix + "max_speed", m.max_speed);
  m.blocked_time = p.getDouble(prefix + "blocked_time", m.blocked_time);
  try
  {
    checkMovingObstaclesConfig(m);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::runtime_error("parameters " + where + prefix + "*: " + e.what());
  }
}

/// costmap_2d's `plugins` list: [{name, type}, ...] -> the layers, each read from its namespace.
void readPlugins(StrictParams& p, const ros::NodeHandle& nh, CostmapRosSettings& s, int& prediction_cost,
                 ParamReport& r)
{
  XmlRpc::XmlRpcValue list;
  nh.getParam("plugins", list);
  p.markKnown("plugins");
  const std::string param = nh.resolveName("plugins");
  if (list.getType() != XmlRpc::XmlRpcValue::TypeArray)
    throw std::runtime_error("parameter " + param + ": expected a list of {name: ..., type: ...}");
  static const std::vector<std::pair<std::string, LayerKind>> types = {
      {"costmap_2d::StaticLayer", LayerKind::STATIC},
      {"costmap_2d::ObstacleLayer", LayerKind::OBSTACLE},
      {"costmap_2d::VoxelLayer", LayerKind::OBSTACLE},
      {"costmap_2d::InflationLayer", LayerKind::INFLATION},
      {"mbot_navigation::RobotsLayer", LayerKind::ROBOTS},
      {"mbot_navigation::MovingObstaclesLayer", LayerKind::MOVING}};
  s.static_map = s.robots_layer = s.inflation = s.moving_obstacles = false;
  s.scan_topic.clear();
  std::vector<LayerKind> seen;
  for (int i = 0; i < list.size(); ++i)
  {
    XmlRpc::XmlRpcValue& entry = list[i];
    if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct || !entry.hasMember("name") || !entry.hasMember("type") ||
        entry["name"].getType() != XmlRpc::XmlRpcValue::TypeString ||
        entry["type"].getType() != XmlRpc::XmlRpcValue::TypeString)
      throw std::runtime_error("parameter " + param + ": entry " + std::to_string(i) +
                               " is not {name: <string>, type: <string>}");
    const std::string name = entry["name"], type = entry["type"];
    auto it = std::find_if(types.begin(), types.end(), [&](const auto& t) { return t.first == type; });
    if (it == types.end())
    {
      std::string known;
      for (const auto& t : types) known += (known.empty() ? "" : ", ") + t.first;
      throw std::runtime_error("parameter " + param + ": layer '" + name + "' has type '" + type +
                               "', which this node does not have (it has " + known + ")");
    }
    if (std::find(seen.begin(), seen.end(), it->second) != seen.end())
      throw std::runtime_error("parameter " + param + ": layer '" + name + "' (" + type +
                               "): this node has one layer of each kind");
    seen.push_back(it->second);
    const ros::NodeHandle layer_nh(nh, name);
    StrictParams lp(layer_nh, mbot_common::UnknownKeys::WARN);
    p.markKnown(name);
    const bool enabled = lp.getBool("enabled", true);
    switch (it->second)
    {
      case LayerKind::STATIC:
        s.static_map = enabled;
        s.static_layer.track_unknown_space = lp.getBool("track_unknown_space", s.costmap.track_unknown_space);
        readStaticLayer(lp, layer_nh, s, r);
        break;
      case LayerKind::OBSTACLE:
        if (type == "costmap_2d::VoxelLayer")
          r.notes.push_back("layer " + layer_nh.getNamespace() +
                            ": costmap_2d::VoxelLayer is read as a 2-D obstacle layer");
        s.obstacle_layer.track_unknown_space = lp.getBool("track_unknown_space", s.costmap.track_unknown_space);
        if (!layer_nh.hasParam("scan_topic") && !layer_nh.hasParam("observation_sources"))
          throw std::runtime_error("layer " + layer_nh.getNamespace() + " (" + type +
                                   "): expected observation_sources (or scan_topic)");
        readObstacleLayer(lp, layer_nh, s, r);
        // The layer's own tf tolerance (a costmap-level one is the costmap's, implemented).
        ignoreStandardKeys(lp, layer_nh, {"transform_tolerance"}, "a costmap_2d obstacle layer key", r);
        if (!enabled) s.scan_topic.clear();
        break;
      case LayerKind::INFLATION:
        s.inflation = enabled;
        s.inflation_layer_name = name;
        readInflationLayer(lp, s);
        break;
      case LayerKind::ROBOTS:
        s.robots_layer = enabled;
        readRobotsLayer(lp, "", s, prediction_cost);
        break;
      case LayerKind::MOVING:
        s.moving_obstacles = enabled;
        readMovingLayer(lp, "", layer_nh.getNamespace() + "/", s);
        break;
    }
    reportUnknownKeys(lp, r);
  }
  s.layer_order = seen;  // built in the listed order
  if (s.moving_obstacles && s.scan_topic.empty())
    throw std::runtime_error("parameter " + param +
                             ": mbot_navigation::MovingObstaclesLayer tracks what the obstacle layer's LaserScan "
                             "source sees; list an enabled costmap_2d::ObstacleLayer with one");
  if (!s.inflation)
    r.notes.push_back("parameter " + param + ": no inflation layer, so nothing keeps the robot's radius off obstacles");
  for (const std::string& key : kFlatLayerKeys)
    if (nh.hasParam(key))
    {
      p.markKnown(key);
      r.notes.push_back("parameter " + nh.resolveName(key) +
                        ": with `plugins`, layer settings go in the layer's namespace; ignored");
    }
}
}  // namespace

CostmapRosSettings readCostmapSettings(const ros::NodeHandle& costmap_nh, const CostmapRosSettings& d,
                                       ParamReport* report)
{
  ParamReport local_report;
  ParamReport& r = report ? *report : local_report;
  StrictParams p(costmap_nh, mbot_common::UnknownKeys::WARN);
  CostmapRosSettings s = d;
  s.global_frame = stripSlash(p.getString("global_frame", d.global_frame));
  s.robot_base_frame = stripSlash(p.getString("robot_base_frame", d.robot_base_frame));
  s.update_frequency = p.getDouble("update_frequency", d.update_frequency);
  s.publish_frequency = p.getDouble("publish_frequency", d.publish_frequency);
  s.transform_tolerance = p.getDouble("transform_tolerance", d.transform_tolerance);
  ignoreStandardKeys(p, costmap_nh, kIgnoredCostmapKeys, "a costmap_2d key", r);

  LayeredCostmapConfig& c = s.costmap;
  c.rolling_window = p.getBool("rolling_window", d.costmap.rolling_window);
  c.width = p.getDouble("width", d.costmap.width);
  c.height = p.getDouble("height", d.costmap.height);
  c.resolution = p.getDouble("resolution", d.costmap.resolution);
  c.origin_x = p.getDouble("origin_x", d.costmap.origin_x);
  c.origin_y = p.getDouble("origin_y", d.costmap.origin_y);
  // As costmap_2d: `footprint`, else `robot_radius`, searched from here upwards (so both may stand
  // at the node's level, for both costmaps). A footprint "[]" counts as none.
  p.markKnown("footprint");
  p.markKnown("robot_radius");
  for (const std::string& key : kSearchedRangeKeys) p.markKnown(key);  // the sources search them up to here
  std::string footprint_name, radius_name;
  XmlRpc::XmlRpcValue footprint;
  if (costmap_nh.searchParam("footprint", footprint_name) && costmap_nh.getParam(footprint_name, footprint) &&
      !(footprint.getType() == XmlRpc::XmlRpcValue::TypeString &&
        (static_cast<std::string>(footprint).empty() || static_cast<std::string>(footprint) == "[]")))
  {
    // The layers here are circular.
    c.robot_radius = footprintRadius(footprint, footprint_name);
    r.notes.push_back("parameter " + footprint_name + ": the footprint polygon is taken as its " +
                      "circumscribed circle, radius " + std::to_string(c.robot_radius) + " m");
  }
  else
    c.robot_radius = searchDouble(costmap_nh, "robot_radius", d.costmap.robot_radius);
  c.robot_radius += p.getDouble("footprint_padding", 0.0);
  c.track_unknown_space = p.getBool("track_unknown_space", d.costmap.track_unknown_space);
  s.static_layer.track_unknown_space = c.track_unknown_space;
  s.obstacle_layer.track_unknown_space = c.track_unknown_space;

  int prediction_cost = d.robots.prediction_cost;
  if (costmap_nh.hasParam("plugins"))
    readPlugins(p, costmap_nh, s, prediction_cost, r);
  else
  {
    // costmap_2d's pre-layer form: static_map picks the static layer, map_type the obstacle layer.
    s.static_map = p.getBool("static_map", d.static_map);
    const std::string map_type = p.getString("map_type", "costmap");
    if (map_type == "voxel")
      r.notes.push_back("parameter " + costmap_nh.resolveName("map_type") + ": voxel is read as a 2-D obstacle layer");
    else if (map_type != "costmap")
      throw std::runtime_error("parameter " + costmap_nh.resolveName("map_type") +
                               ": expected costmap or voxel, got '" + map_type + "'");
    readStaticLayer(p, costmap_nh, s, r);
    readObstacleLayer(p, costmap_nh, s, r);
    readInflationLayer(p, s);
    // Written by the inflation layer's dynamic_reconfigure server; the flat keys win.
    StrictParams ip{ros::NodeHandle(costmap_nh, s.inflation_layer_name), mbot_common::UnknownKeys::WARN};
    p.markKnown(s.inflation_layer_name);
    const InflationLayerConfig flat = s.inflation_layer;
    readInflationLayer(ip, s);
    for (const char* key : {"inflation_radius", "cost_scaling_factor", "inflate_unknown"})
      if (costmap_nh.hasParam(key))
      {
        if (std::string(key) == "inflation_radius") s.inflation_layer.inflation_radius = flat.inflation_radius;
        if (std::string(key) == "cost_scaling_factor") s.inflation_layer.cost_scaling_factor = flat.cost_scaling_factor;
        if (std::string(key) == "inflate_unknown") s.inflation_layer.inflate_unknown = flat.inflate_unknown;
      }
    reportUnknownKeys(ip, r);
    s.robots_layer = p.getBool("robots_layer", d.robots_layer);
    readRobotsLayer(p, "robots_", s, prediction_cost);
    s.moving_obstacles = p.getBool("moving_obstacles_layer", d.moving_obstacles);
    readMovingLayer(p, "moving_obstacles_", costmap_nh.getNamespace() + "/", s);
  }
  reportUnknownKeys(p, r);
  s.moving.obstacle_range = s.obstacle_layer.obstacle_range;  // it tracks what the obstacle layer marks

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
    throw std::runtime_error("parameter " + ns +
                             "static_map: a costmap that is not a rolling window takes its size "
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
    : name_(name), settings_(settings), nh_(nh), tf_(tf)
{
  layered_ = std::make_unique<LayeredCostmap>(settings.costmap);
  // Bottom to top as configured; the default puts inflation last, so that it inflates everything
  // below it, teammates included.
  for (const LayerKind kind : settings.layer_order) switch (kind)
    {
      case LayerKind::STATIC:
        if (settings.static_map && !static_layer_)
          static_layer_ =
              static_cast<StaticLayer*>(&layered_->addLayer(std::make_unique<StaticLayer>(settings.static_layer)));
        break;
      case LayerKind::OBSTACLE:
        if (!settings.scan_topic.empty() && !obstacle_layer_)
          obstacle_layer_ = static_cast<ObstacleLayer*>(
              &layered_->addLayer(std::make_unique<ObstacleLayer>(settings.obstacle_layer)));
        break;
      case LayerKind::MOVING:
        if (settings.moving_obstacles && !settings.scan_topic.empty() && !moving_layer_)
          moving_layer_ = static_cast<MovingObstaclesLayer*>(
              &layered_->addLayer(std::make_unique<MovingObstaclesLayer>(settings.moving)));
        break;
      case LayerKind::ROBOTS:
        if (settings.robots_layer && !robots_layer_)
          robots_layer_ =
              static_cast<RobotsLayer*>(&layered_->addLayer(std::make_unique<RobotsLayer>(settings.robots)));
        break;
      case LayerKind::INFLATION:
        if (settings.inflation && !inflation_layer_)
          inflation_layer_ = static_cast<InflationLayer*>(
              &layered_->addLayer(std::make_unique<InflationLayer>(settings.inflation_layer)));
        break;
    }

  // People are told from the walls by the map (the static layer's grid, as long as the layer lives).
  if (moving_layer_ && static_layer_) moving_layer_->setStaticMap(&static_layer_->grid());

  // As costmap_2d: a relative map_topic is in the robot's namespace (ours default to "/map").
  if (static_layer_) map_sub_ = nh.subscribe(settings.map_topic, 1, &CostmapRos::mapCallback, this);
  subscribeScans();
  // Not latched: a new subscriber gets the current grid from onSubscriber(), and nobody pays for
  // grids that nobody reads.
  if (settings.publish_frequency > 0.0)
    costmap_pub_ = private_nh.advertise<nav_msgs::OccupancyGrid>(
        name + "/costmap", 1, [this](const ros::SingleSubscriberPublisher& pub) { onSubscriber(pub); });
  grid_msg_.header.frame_id = settings.global_frame;
}

void CostmapRos::subscribeScans()
{
  if (obstacle_layer_ || moving_layer_)
    scan_sub_ = nh_.subscribe(settings_.scan_topic, 10, &CostmapRos::scanCallback, this,
                              ros::TransportHints().tcpNoDelay());  // no Nagle wait between hosts
}

void CostmapRos::stop()
{
  scan_sub_.shutdown();
  pending_scans_.clear();
  teammates_.clear();
  stopped_ = true;
}

void CostmapRos::start()
{
  if (!stopped_) return;
  subscribeScans();
  resetLayers();  // marks from before the stop are where things were then
  warming_ = obstacle_layer_ || moving_layer_;
  stopped_ = false;
}

void CostmapRos::resetLayers()
{
  layered_->reset();
  next_update_ = ros::Time(0);
  if (!stopped_ || !updated_) return;
  if (robots_layer_) robots_layer_->setTeammates({});
  layered_->updateMap(last_robot_);
}

void CostmapRos::mapCallback(const nav_msgs::OccupancyGrid::ConstPtr& map)
{
  if (map->header.frame_id != settings_.global_frame && !map->header.frame_id.empty())
    ROS_WARN("%s: the map is in frame '%s', not in the costmap's global_frame '%s'; using it as if it were",
             name_.c_str(), map->header.frame_id.c_str(), settings_.global_frame.c_str());
  if (map->data.size() != static_cast<size_t>(map->info.width) * map->info.height || map->info.width == 0)
  {
    ROS_ERROR("%s: ignoring a map of %ux%u cells with %zu values", name_.c_str(), map->info.width, map->info.height,
              map->data.size());
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

void CostmapRos::setTeammates(const std::vector<TeammateState>& teammates) { teammates_ = teammates; }

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
    obs.stamp = scan->header.stamp.toSec();
    const double yaw = tf2::getYaw(t.transform.rotation);
    obs.beams.reserve(scan->ranges.size());
    for (size_t i = 0; i < scan->ranges.size(); ++i)
    {
      const double angle = yaw + scan->angle_min + i * scan->angle_increment;
      obs.beams.push_back({angle, scan->ranges[i]});
    }
    // Hits on teammates are the robots layer's (see withoutTeammateHits()).
    obs = withoutTeammateHits(obs, teammates_, settings_.robots_scan_margin);
    if (obstacle_layer_) obstacle_layer_->addObservation(obs);
    if (moving_layer_) moving_layer_->addObservation(obs);
    warming_ = false;
  }
  pending_scans_.swap(keep);
}

void CostmapRos::update(const Pose2D& robot, const ros::Time& now)
{
  if (obstacle_layer_ || moving_layer_) applyScans(now);
  if (robots_layer_)
    robots_layer_->setTeammates(drawableTeammates(teammates_, robot, settings_.costmap.robot_radius,
                                                  settings_.costmap.resolution, settings_.robots_padding));
  layered_->updateMap(robot);
  next_update_ = now + ros::Duration(1.0 / settings_.update_frequency);
  last_robot_ = robot;
  updated_ = true;
}

void CostmapRos::publishIfDue(const ros::Time& now)
{
  if (settings_.publish_frequency <= 0.0 || now < next_publish_ || !ready()) return;
  next_publish_ = now + ros::Duration(1.0 / settings_.publish_frequency);
  if (costmap_pub_.getNumSubscribers() == 0) return;
  grid_msg_.header.stamp = now;
  toOccupancyGrid(costmap(), grid_msg_);
  grid_msg_.info.map_load_time = now;
  costmap_pub_.publish(grid_msg_);
}

void CostmapRos::onSubscriber(const ros::SingleSubscriberPublisher& pub)
{
  if (!ready()) return;  // publishIfDue() sends the first grid
  const ros::Time now = ros::Time::now();
  grid_msg_.header.stamp = now;
  toOccupancyGrid(costmap(), grid_msg_);
  grid_msg_.info.map_load_time = now;
  pub.publish(grid_msg_);
}

void CostmapRos::clear()
{
  // Every layer forgets what it sensed (the static layer keeps its map and rewrites it), and the
  // whole master grid is rewritten.
  resetLayers();
}

void CostmapRos::setInflation(const InflationLayerConfig& config)
{
  if (!inflation_layer_) throw std::invalid_argument(name_ + " has no inflation layer");
  inflation_layer_->setConfig(config);
  settings_.inflation_layer = config;
  layered_->requestFullUpdate();  // every inflated cell may change
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
  if (settings_.inflation) costmap.addLayer(std::make_unique<InflationLayer>(settings_.inflation_layer));
  static_layer.setMap(last_map_->info.width, last_map_->info.height, last_map_->info.resolution,
                      last_map_->info.origin.position.x, last_map_->info.origin.position.y, last_map_->data.data());
  costmap.updateMap(Pose2D{});
  return costmap.costmap();
}

}  // namespace mbot_navigation
