// The nav node's parameter reader (move_base_params.h) on a parameter server (rostest
// move_base_params.test): a tutorial-style move_base set loads with notes only, each naming its
// key; a key nobody knows is a warning naming it and the nearest known key; the plugins form
// picks the layers; keys costmap_2d searches for upwards are found there; the shipped costmaps
// (layered) resolve exactly as their pre-layer (flat) form.
#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

#include <gtest/gtest.h>
#include <ros/package.h>
#include <ros/ros.h>
#include <tf2_ros/buffer.h>

#include "mbot_navigation/ros/move_base_params.h"

using namespace mbot_navigation;

namespace
{
std::string descriptionDir() { return ros::package::getPath("mbot_description"); }

NavParams read(const std::string& ns, ParamReport& report)
{
  return readNavParams(ros::NodeHandle("/" + ns), ros::NodeHandle("/" + ns + "/move_base"), descriptionDir(), report);
}

/// The error text of reading `ns` ("" when it loads).
std::string readError(const std::string& ns)
{
  ParamReport report;
  try
  {
    read(ns, report);
  }
  catch (const std::runtime_error& e)
  {
    return e.what();
  }
  return "";
}

/// True when one of `lines` is about the parameter `key` (its full name).
bool mentions(const std::vector<std::string>& lines, const std::string& key)
{
  return std::any_of(lines.begin(), lines.end(), [&](const std::string& line) {
    return line.find(key + ":") != std::string::npos || line.find(key + " (") != std::string::npos;
  });
}

/// Copy the tutorial set of /robot_0/move_base into /<ns>/move_base.
void copyTutorialSet(const std::string& ns)
{
  XmlRpc::XmlRpcValue all;
  ASSERT_TRUE(ros::param::get("/robot_0/move_base", all));
  ros::param::set("/" + ns + "/move_base", all);
}
}  // namespace

TEST(MoveBaseParams, TutorialSetLoadsWithNotesOnly)
{
  ParamReport report;
  NavParams p;
  ASSERT_NO_THROW(p = read("robot_0", report));
  // move_base's meanings and units
  EXPECT_EQ(p.global_planner, "astar");  // navfn/NavfnROS
  EXPECT_DOUBLE_EQ(p.controller_frequency, 10.0);
  EXPECT_DOUBLE_EQ(p.nav.planner_frequency, 1.0);
  EXPECT_DOUBLE_EQ(p.nav.oscillation_distance, 0.2);
  EXPECT_EQ(p.global_costmap.global_frame, "map");  // "/map", tf1 style
  EXPECT_EQ(p.local_costmap.global_frame, "map");   // odom: runs in the global costmap's frame
  EXPECT_TRUE(p.global_costmap.static_map);
  EXPECT_FALSE(p.local_costmap.static_map);
  EXPECT_TRUE(p.local_costmap.costmap.rolling_window);
  EXPECT_NEAR(p.global_costmap.costmap.robot_radius, std::hypot(0.12, 0.12) + 0.01, 1e-9);  // footprint + padding
  EXPECT_EQ(p.global_costmap.scan_topic, "scan");                                           // from observation_sources
  EXPECT_DOUBLE_EQ(p.global_costmap.obstacle_layer.obstacle_range, 2.5);
  EXPECT_TRUE(p.global_costmap.obstacle_layer.marking);
  EXPECT_TRUE(p.global_costmap.obstacle_layer.clearing);
  EXPECT_FALSE(p.global_costmap.obstacle_layer.inf_is_valid);  // costmap_2d's default
  EXPECT_DOUBLE_EQ(p.global_costmap.inflation_layer.inflation_radius, 0.55);
  EXPECT_DOUBLE_EQ(p.local_costmap.inflation_layer.cost_scaling_factor, 5.0);
  EXPECT_DOUBLE_EQ(p.dwa.max_vel_x, 0.45);
  EXPECT_DOUBLE_EQ(p.dwa.max_vel_theta, 1.5);
  EXPECT_DOUBLE_EQ(p.dwa.xy_goal_tolerance, 0.15);
  EXPECT_EQ(p.dwa.vx_samples, 6);
  EXPECT_DOUBLE_EQ(p.dwa.controller_frequency, 10.0);
  EXPECT_EQ(p.odom_topic, "odom");
  EXPECT_FALSE(p.shutdown_costmaps);  // the fixture sets it, to false

  EXPECT_EQ(report.warnings, std::vector<std::string>{});  // every key is a standard one
  for (const std::string& key :
       {"/robot_0/move_base/conservative_reset_dist", "/robot_0/move_base/NavfnROS/default_tolerance",
        "/robot_0/move_base/NavfnROS/visualize_potential", "/robot_0/move_base/DWAPlannerROS/publish_traj_pc",
        "/robot_0/move_base/DWAPlannerROS/stop_time_buffer",
        "/robot_0/move_base/global_costmap/always_send_full_costmap",
        "/robot_0/move_base/global_costmap/laser_scan_sensor/sensor_frame",
        "/robot_0/move_base/local_costmap/laser_scan_sensor/expected_update_rate",
        "/robot_0/move_base/local_costmap/global_frame", "/robot_0/move_base/global_costmap/footprint"})
    EXPECT_TRUE(mentions(report.notes, key)) << key;
  // Exactly one note per ignored key (nothing is reported twice).
  for (const std::string& n : report.notes) EXPECT_EQ(std::count(report.notes.begin(), report.notes.end(), n), 1) << n;
  // Implemented keys give no note.
  for (const std::string& key :
       {"/robot_0/move_base/DWAPlannerROS/max_vel_x", "/robot_0/move_base/controller_frequency",
        "/robot_0/move_base/shutdown_costmaps", "/robot_0/move_base/global_costmap/inflation_radius",
        "/robot_0/move_base/DWAPlannerROS/controller_frequency"})
    EXPECT_FALSE(mentions(report.notes, key)) << key;
}

TEST(MoveBaseParams, UnknownKeyIsAWarningNamingItAndTheNearestKnownKey)
{
  const std::vector<std::pair<std::string, std::string>> typos = {
      {"typo/move_base/DWAPlannerROS/max_vel_xx", "max_vel_x"},
      {"typo/move_base/local_costmap/inflation_raduis", "inflation_radius"},
      {"typo/move_base/global_costmap/laser_scan_sensor/markign", "marking"},
      {"typo/move_base/GlobalPlanner/publish_scal", "publish_scale"},
      {"typo/move_base/TrajectoryPlannerROS/vtheta_sample", "vtheta_samples"},
      {"typo/move_base/planner_frequncy", "planner_frequency"}};
  copyTutorialSet("typo");
  for (const auto& typo : typos) ros::param::set("/" + typo.first, 0.3);
  ParamReport report;
  NavParams p;
  ASSERT_NO_THROW(p = read("typo", report));  // as move_base: an unknown key stops nothing
  for (const auto& typo : typos)
  {
    const std::string line = "unknown parameter /" + typo.first + " (ignored; did you mean " + typo.second + "?)";
    EXPECT_EQ(std::count(report.warnings.begin(), report.warnings.end(), line), 1) << line;
  }
  EXPECT_EQ(report.warnings.size(), typos.size());
  EXPECT_DOUBLE_EQ(p.dwa.max_vel_x, 0.45);  // the rest is read as before

  // A wrong value still stops the node, naming the key.
  copyTutorialSet("bad_type");
  ros::param::set("/bad_type/move_base/DWAPlannerROS/max_vel_x", std::string("fast"));
  std::string error = readError("bad_type");
  EXPECT_NE(error.find("/bad_type/move_base/DWAPlannerROS/max_vel_x"), std::string::npos) << error;
  copyTutorialSet("bad_range");
  ros::param::set("/bad_range/move_base/controller_frequency", -1.0);
  error = readError("bad_range");
  EXPECT_NE(error.find("/bad_range/move_base/controller_frequency"), std::string::npos) << error;
}

TEST(MoveBaseParams, KeysFoundAsCostmap2dFindsThem)
{
  // footprint / robot_radius at the node's level (costmap_2d's searchParam), for both costmaps.
  copyTutorialSet("search");
  ros::param::del("/search/move_base/global_costmap/footprint");
  ros::param::del("/search/move_base/local_costmap/footprint");
  ros::param::set("/search/move_base/robot_radius", 0.2);
  ParamReport report;
  NavParams p = read("search", report);
  EXPECT_DOUBLE_EQ(p.global_costmap.costmap.robot_radius, 0.2 + 0.01);  // + the costmap's footprint_padding
  EXPECT_DOUBLE_EQ(p.local_costmap.costmap.robot_radius, 0.2 + 0.01);
  ros::param::set("/search/move_base/footprint", std::string("[[0.3, 0.0], [-0.1, 0.1], [-0.1, -0.1]]"));
  report = ParamReport();
  p = read("search", report);
  EXPECT_DOUBLE_EQ(p.global_costmap.costmap.robot_radius, 0.3 + 0.01);  // a footprint wins
  EXPECT_EQ(report.warnings, std::vector<std::string>{});
  EXPECT_EQ(
      std::count_if(report.notes.begin(), report.notes.end(),
                    [](const std::string& n) { return n.find("/search/move_base/footprint:") != std::string::npos; }),
      1);

  // A source's ranges: its own, else its layer's, the costmap's, the node's; noetic's *_max_range first.
  copyTutorialSet("ranges");
  ros::param::del("/ranges/move_base/global_costmap/obstacle_range");
  ros::param::del("/ranges/move_base/local_costmap/obstacle_range");
  ros::param::set("/ranges/move_base/obstacle_range", 1.8);
  ros::param::set("/ranges/move_base/local_costmap/laser_scan_sensor/obstacle_max_range", 1.2);
  report = ParamReport();
  p = read("ranges", report);
  EXPECT_DOUBLE_EQ(p.global_costmap.obstacle_layer.obstacle_range, 1.8);
  EXPECT_DOUBLE_EQ(p.local_costmap.obstacle_layer.obstacle_range, 1.2);
  EXPECT_DOUBLE_EQ(p.local_costmap.obstacle_layer.raytrace_range, 3.0);
  EXPECT_EQ(report.warnings, std::vector<std::string>{});

  // A source without `topic` subscribes to its own name; inf_is_valid, marking and clearing are read.
  copyTutorialSet("source");
  ros::param::del("/source/move_base/global_costmap/laser_scan_sensor/topic");
  ros::param::set("/source/move_base/global_costmap/laser_scan_sensor/inf_is_valid", true);
  ros::param::set("/source/move_base/global_costmap/laser_scan_sensor/clearing", false);
  report = ParamReport();
  p = read("source", report);
  EXPECT_EQ(p.global_costmap.scan_topic, "laser_scan_sensor");
  EXPECT_TRUE(p.global_costmap.obstacle_layer.inf_is_valid);
  EXPECT_FALSE(p.global_costmap.obstacle_layer.clearing);
  EXPECT_TRUE(p.global_costmap.obstacle_layer.marking);
  EXPECT_EQ(p.local_costmap.scan_topic, "scan");
}

TEST(MoveBaseParams, OlderAndOtherPlannersKeysAreAccepted)
{
  copyTutorialSet("older");
  const std::string ns = "/older/move_base/";
  ros::param::del(ns + "DWAPlannerROS/acc_lim_theta");
  ros::param::del(ns + "DWAPlannerROS/vth_samples");
  ros::param::set(ns + "DWAPlannerROS/acc_lim_th", 2.0);     // the wiki's name
  ros::param::set(ns + "DWAPlannerROS/vtheta_samples", 12);  // base_local_planner's
  ros::param::set(ns + "DWAPlannerROS/vy_samples", 0);       // raised to 1, as dynamic_reconfigure does
  ros::param::set(ns + "DWAPlannerROS/sim_period", 0.1);
  ros::param::set(ns + "DWAPlannerROS/sum_scores", true);
  ros::param::set(ns + "DWAPlannerROS/odom_topic", std::string("odometry/filtered"));
  ros::param::set(ns + "GlobalPlanner/publish_scale", 100);
  ros::param::set(ns + "TrajectoryPlannerROS/pdist_scale", 0.6);
  ros::param::set(ns + "recovery_behaviors", [] {
    XmlRpc::XmlRpcValue list;
    list[0]["name"] = "super_reset";
    list[0]["type"] = "clear_costmap_recovery/ClearCostmapRecovery";
    return list;
  }());
  ros::param::set(ns + "super_reset/reset_distance", 5.0);
  ros::param::set(ns + "rotate_recovery/frequency", 20.0);
  ParamReport report;
  NavParams p;
  ASSERT_NO_THROW(p = read("older", report));
  EXPECT_EQ(report.warnings, std::vector<std::string>{});
  EXPECT_DOUBLE_EQ(p.dwa.acc_lim_theta, 2.0);
  EXPECT_EQ(p.dwa.vth_samples, 12);
  EXPECT_EQ(p.dwa.vy_samples, 1);
  EXPECT_EQ(p.odom_topic, "odometry/filtered");
  for (const std::string& key :
       {"DWAPlannerROS/acc_lim_th", "DWAPlannerROS/vtheta_samples", "DWAPlannerROS/vy_samples",
        "DWAPlannerROS/sim_period", "DWAPlannerROS/sum_scores", "GlobalPlanner/publish_scale",
        "TrajectoryPlannerROS/pdist_scale", "recovery_behaviors", "super_reset", "rotate_recovery"})
    EXPECT_TRUE(mentions(report.notes, ns + key)) << key;
}

TEST(MoveBaseParams, PlannerNames)
{
  copyTutorialSet("gp");
  ros::param::set("/gp/move_base/base_global_planner", std::string("global_planner/GlobalPlanner"));
  ros::param::set("/gp/move_base/GlobalPlanner/use_dijkstra", false);
  ParamReport report;
  EXPECT_EQ(read("gp", report).global_planner, "astar");
  EXPECT_TRUE(mentions(report.notes, "/gp/move_base/GlobalPlanner/use_dijkstra"));

  copyTutorialSet("carrot");
  ros::param::set("/carrot/move_base/base_global_planner", std::string("carrot_planner/CarrotPlanner"));
  EXPECT_NE(readError("carrot").find("carrot_planner/CarrotPlanner"), std::string::npos);

  copyTutorialSet("tpr");
  ros::param::set("/tpr/move_base/base_local_planner", std::string("base_local_planner/TrajectoryPlannerROS"));
  const std::string error = readError("tpr");
  EXPECT_NE(error.find("/tpr/move_base/base_local_planner"), std::string::npos) << error;
  EXPECT_NE(error.find("not supported"), std::string::npos) << error;
}

TEST(MoveBaseParams, PluginsPickTheLayers)
{
  ParamReport report;
  CostmapRosSettings d;
  const CostmapRosSettings s = readCostmapSettings(ros::NodeHandle("/plugins/move_base/global_costmap"), d, &report);
  EXPECT_TRUE(s.static_map);
  EXPECT_EQ(s.scan_topic, "scan");
  EXPECT_DOUBLE_EQ(s.obstacle_layer.obstacle_range, 2.0);  // the source's own
  EXPECT_TRUE(s.robots_layer);
  EXPECT_DOUBLE_EQ(s.robots.prediction_time, 1.5);
  EXPECT_TRUE(s.inflation);
  EXPECT_EQ(s.inflation_layer_name, "inflater");
  EXPECT_DOUBLE_EQ(s.inflation_layer.inflation_radius, 0.4);  // the layer's, not the flat 0.9
  EXPECT_DOUBLE_EQ(s.inflation_layer.cost_scaling_factor, 8.0);
  EXPECT_DOUBLE_EQ(s.costmap.robot_radius, 0.17);
  EXPECT_TRUE(mentions(report.notes, "/plugins/move_base/global_costmap/inflation_radius"));
  EXPECT_TRUE(mentions(report.notes, "/plugins/move_base/global_costmap/static_layer/subscribe_to_updates"));
  EXPECT_TRUE(mentions(report.notes, "/plugins/move_base/global_costmap/obstacle_layer/z_voxels"));
  EXPECT_EQ(report.warnings, std::vector<std::string>{});

  // A layer left out is not there; `enabled: false` turns one off.
  ros::param::set("/plugins2/global_costmap/plugins", [] {
    XmlRpc::XmlRpcValue list;
    list[0]["name"] = "static_layer";
    list[0]["type"] = "costmap_2d::StaticLayer";
    list[1]["name"] = "inflation_layer";
    list[1]["type"] = "costmap_2d::InflationLayer";
    return list;
  }());
  ros::param::set("/plugins2/global_costmap/inflation_layer/enabled", false);
  report = ParamReport();
  const CostmapRosSettings s2 = readCostmapSettings(ros::NodeHandle("/plugins2/global_costmap"), d, &report);
  EXPECT_TRUE(s2.static_map);
  EXPECT_TRUE(s2.scan_topic.empty());
  EXPECT_FALSE(s2.robots_layer);
  EXPECT_FALSE(s2.inflation);

  // An unknown layer type is an error naming it.
  ros::param::set("/plugins3/global_costmap/plugins", [] {
    XmlRpc::XmlRpcValue list;
    list[0]["name"] = "social";
    list[0]["type"] = "social_navigation_layers::ProxemicLayer";
    return list;
  }());
  try
  {
    readCostmapSettings(ros::NodeHandle("/plugins3/global_costmap"), d, &report);
    FAIL() << "an unknown layer type was accepted";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_NE(std::string(e.what()).find("social_navigation_layers::ProxemicLayer"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("'social'"), std::string::npos) << e.what();
  }
}

namespace
{
/// A plugins list of a static layer, an obstacle layer (one LaserScan source, obstacle_range 2.0 m)
/// when `with_obstacle_layer`, and a moving obstacles layer named "people", in /<ns>/global_costmap.
void setMovingPlugins(const std::string& ns, bool with_obstacle_layer)
{
  XmlRpc::XmlRpcValue list;
  int i = 0;
  list[i]["name"] = "static_layer";
  list[i++]["type"] = "costmap_2d::StaticLayer";
  if (with_obstacle_layer)
  {
    list[i]["name"] = "obstacle_layer";
    list[i++]["type"] = "costmap_2d::ObstacleLayer";
    ros::param::set("/" + ns + "/global_costmap/obstacle_layer/observation_sources", std::string("scan"));
    ros::param::set("/" + ns + "/global_costmap/obstacle_layer/scan/data_type", std::string("LaserScan"));
    ros::param::set("/" + ns + "/global_costmap/obstacle_layer/scan/clearing", true);
    ros::param::set("/" + ns + "/global_costmap/obstacle_layer/scan/obstacle_range", 2.0);
  }
  list[i]["name"] = "people";
  list[i]["type"] = "mbot_navigation::MovingObstaclesLayer";
  ros::param::set("/" + ns + "/global_costmap/plugins", list);
}

std::string settingsError(const std::string& costmap_ns)
{
  try
  {
    readCostmapSettings(ros::NodeHandle(costmap_ns), CostmapRosSettings());
  }
  catch (const std::runtime_error& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(MoveBaseParams, MovingObstaclesLayerKeysAndErrors)
{
  // Listed after the obstacle layer, with its keys in its namespace.
  setMovingPlugins("moving", true);
  ros::param::set("/moving/global_costmap/people/min_speed", 0.3);
  ros::param::set("/moving/global_costmap/people/prediction_time", 1.5);
  const CostmapRosSettings s = readCostmapSettings(ros::NodeHandle("/moving/global_costmap"), CostmapRosSettings());
  EXPECT_TRUE(s.moving_obstacles);
  EXPECT_EQ(s.layer_order, (std::vector<LayerKind>{LayerKind::STATIC, LayerKind::OBSTACLE, LayerKind::MOVING}));
  EXPECT_DOUBLE_EQ(s.moving.min_speed, 0.3);
  EXPECT_DOUBLE_EQ(s.moving.prediction_time, 1.5);
  EXPECT_DOUBLE_EQ(s.moving.obstacle_range, 2.0);  // the scan source's: it tracks what is marked

  // Without an obstacle layer there is no scan to track people in.
  setMovingPlugins("moving_alone", false);
  std::string error = settingsError("/moving_alone/global_costmap");
  EXPECT_NE(error.find("MovingObstaclesLayer"), std::string::npos) << error;
  EXPECT_NE(error.find("ObstacleLayer"), std::string::npos) << error;

  // A bad value is an error naming the layer's namespace and the key; so is an unknown key.
  setMovingPlugins("moving_bad", true);
  ros::param::set("/moving_bad/global_costmap/people/max_speed", 0.1);  // below min_speed
  error = settingsError("/moving_bad/global_costmap");
  EXPECT_NE(error.find("/moving_bad/global_costmap/people/"), std::string::npos) << error;
  EXPECT_NE(error.find("'max_speed'"), std::string::npos) << error;
  setMovingPlugins("moving_typo", true);
  ros::param::set("/moving_typo/global_costmap/people/min_sped", 0.3);
  ParamReport typo_report;
  readCostmapSettings(ros::NodeHandle("/moving_typo/global_costmap"), CostmapRosSettings(), &typo_report);
  EXPECT_EQ(typo_report.warnings,
            std::vector<std::string>{"unknown parameter /moving_typo/global_costmap/people/min_sped (ignored; did you "
                                     "mean min_speed?)"});

  // The flat form: moving_obstacles_<key>.
  ros::param::set("/moving_flat/global_costmap/moving_obstacles_association_gate", -0.5);
  error = settingsError("/moving_flat/global_costmap");
  EXPECT_NE(error.find("/moving_flat/global_costmap/moving_obstacles_"), std::string::npos) << error;
  EXPECT_NE(error.find("'association_gate'"), std::string::npos) << error;
  ros::param::set("/moving_flat_off/global_costmap/moving_obstacles_layer", false);
  EXPECT_FALSE(
      readCostmapSettings(ros::NodeHandle("/moving_flat_off/global_costmap"), CostmapRosSettings()).moving_obstacles);
}

namespace
{
/// A plugins list of a robots layer and an inflation layer, in this order or the other.
XmlRpc::XmlRpcValue robotsAndInflation(bool inflation_last)
{
  XmlRpc::XmlRpcValue list;
  const int robots = inflation_last ? 0 : 1;
  list[robots]["name"] = "robots";
  list[robots]["type"] = "mbot_navigation::RobotsLayer";
  list[1 - robots]["name"] = "inflation_layer";
  list[1 - robots]["type"] = "costmap_2d::InflationLayer";
  return list;
}

/// The cost at (x, y) [m] after one update with a teammate standing at (1, 0).
uint8_t costNearATeammate(const CostmapRosSettings& settings, double x, double y)
{
  ros::NodeHandle nh("/order"), private_nh("/order/move_base");
  tf2_ros::Buffer tf;
  CostmapRos costmap("global_costmap", settings, nh, private_nh, tf);
  TeammateState mate;
  mate.name = "robot_1";
  mate.pose = Pose2D{1.0, 0.0, 0.0};
  mate.radius = 0.2;
  costmap.setTeammates({mate});
  costmap.update(Pose2D{0.0, 0.0, 0.0}, ros::Time(1.0));
  unsigned mx, my;
  EXPECT_TRUE(costmap.costmap().worldToMap(x, y, mx, my));
  return costmap.costmap().cost(mx, my);
}
}  // namespace

TEST(MoveBaseParams, LayersAreStackedInTheListedOrder)
{
  CostmapRosSettings d;
  // costmap_2d's pre-layer order, with ours (moving obstacles, teammates) before the inflation
  EXPECT_EQ(d.layer_order, (std::vector<LayerKind>{LayerKind::STATIC, LayerKind::OBSTACLE, LayerKind::MOVING,
                                                   LayerKind::ROBOTS, LayerKind::INFLATION}));
  d.costmap.rolling_window = true;  // no map needed
  d.costmap.width = d.costmap.height = 4.0;
  d.costmap.robot_radius = 0.15;
  ParamReport report;
  ros::param::set("/order_last/global_costmap/plugins", robotsAndInflation(true));
  ros::param::set("/order_first/global_costmap/plugins", robotsAndInflation(false));
  const CostmapRosSettings last = readCostmapSettings(ros::NodeHandle("/order_last/global_costmap"), d, &report);
  const CostmapRosSettings first = readCostmapSettings(ros::NodeHandle("/order_first/global_costmap"), d, &report);
  EXPECT_EQ(last.layer_order, (std::vector<LayerKind>{LayerKind::ROBOTS, LayerKind::INFLATION}));
  EXPECT_EQ(first.layer_order, (std::vector<LayerKind>{LayerKind::INFLATION, LayerKind::ROBOTS}));
  ASSERT_TRUE(last.inflation && last.robots_layer && first.inflation && first.robots_layer);

  // The teammate (radius 0.2 m, drawn 0.1 m bigger) is lethal either way; 0.5 m from its centre
  // there is inflation only when the inflation layer is above the robots layer.
  EXPECT_EQ(costNearATeammate(last, 1.0, 0.0), cost::LETHAL);
  EXPECT_EQ(costNearATeammate(first, 1.0, 0.0), cost::LETHAL);
  EXPECT_GT(costNearATeammate(last, 1.5, 0.0), cost::FREE);
  EXPECT_EQ(costNearATeammate(first, 1.5, 0.0), cost::FREE);
}

TEST(MoveBaseParams, FootprintRadius)
{
  XmlRpc::XmlRpcValue text("[[-0.1, -0.1], [-0.1, 0.1], [0.3, 0.0]]");
  EXPECT_DOUBLE_EQ(footprintRadius(text, "f"), 0.3);
  XmlRpc::XmlRpcValue two("[[0.1, 0.1], [0.2, 0.0]]");
  EXPECT_THROW(footprintRadius(two, "f"), std::runtime_error);
  XmlRpc::XmlRpcValue bad("[[0.1, x]]");
  EXPECT_THROW(footprintRadius(bad, "f"), std::runtime_error);
}

namespace
{
/// The fields in which `a` and `b` differ, each as "name: a vs b" (empty: the same settings).
std::vector<std::string> differences(const CostmapRosSettings& a, const CostmapRosSettings& b)
{
  std::vector<std::string> out;
  auto compare = [&](const std::string& name, const auto& x, const auto& y) {
    if (x == y) return;
    std::ostringstream text;
    text << name << ": " << x << " vs " << y;
    out.push_back(text.str());
  };
  auto order = [](const std::vector<LayerKind>& layers) {
    std::string text;
    for (LayerKind k : layers) text += std::to_string(static_cast<int>(k)) + " ";
    return text;
  };
  compare("global_frame", a.global_frame, b.global_frame);
  compare("robot_base_frame", a.robot_base_frame, b.robot_base_frame);
  compare("update_frequency", a.update_frequency, b.update_frequency);
  compare("publish_frequency", a.publish_frequency, b.publish_frequency);
  compare("transform_tolerance", a.transform_tolerance, b.transform_tolerance);
  compare("costmap.rolling_window", a.costmap.rolling_window, b.costmap.rolling_window);
  compare("costmap.width", a.costmap.width, b.costmap.width);
  compare("costmap.height", a.costmap.height, b.costmap.height);
  compare("costmap.resolution", a.costmap.resolution, b.costmap.resolution);
  compare("costmap.origin_x", a.costmap.origin_x, b.costmap.origin_x);
  compare("costmap.origin_y", a.costmap.origin_y, b.costmap.origin_y);
  compare("costmap.track_unknown_space", a.costmap.track_unknown_space, b.costmap.track_unknown_space);
  compare("costmap.robot_radius", a.costmap.robot_radius, b.costmap.robot_radius);
  compare("static_map", a.static_map, b.static_map);
  compare("map_topic", a.map_topic, b.map_topic);
  compare("static_layer.track_unknown_space", a.static_layer.track_unknown_space, b.static_layer.track_unknown_space);
  compare("static_layer.lethal_cost_threshold", a.static_layer.lethal_cost_threshold,
          b.static_layer.lethal_cost_threshold);
  compare("static_layer.unknown_cost_value", a.static_layer.unknown_cost_value, b.static_layer.unknown_cost_value);
  compare("static_layer.trinary_costmap", a.static_layer.trinary_costmap, b.static_layer.trinary_costmap);
  compare("scan_topic", a.scan_topic, b.scan_topic);
  compare("obstacle_layer.obstacle_range", a.obstacle_layer.obstacle_range, b.obstacle_layer.obstacle_range);
  compare("obstacle_layer.raytrace_range", a.obstacle_layer.raytrace_range, b.obstacle_layer.raytrace_range);
  compare("obstacle_layer.track_unknown_space", a.obstacle_layer.track_unknown_space,
          b.obstacle_layer.track_unknown_space);
  compare("obstacle_layer.footprint_clearing_enabled", a.obstacle_layer.footprint_clearing_enabled,
          b.obstacle_layer.footprint_clearing_enabled);
  compare("obstacle_layer.marking", a.obstacle_layer.marking, b.obstacle_layer.marking);
  compare("obstacle_layer.clearing", a.obstacle_layer.clearing, b.obstacle_layer.clearing);
  compare("obstacle_layer.inf_is_valid", a.obstacle_layer.inf_is_valid, b.obstacle_layer.inf_is_valid);
  compare("inflation", a.inflation, b.inflation);
  compare("inflation_layer.inflation_radius", a.inflation_layer.inflation_radius, b.inflation_layer.inflation_radius);
  compare("inflation_layer.cost_scaling_factor", a.inflation_layer.cost_scaling_factor,
          b.inflation_layer.cost_scaling_factor);
  compare("inflation_layer.inflate_unknown", a.inflation_layer.inflate_unknown, b.inflation_layer.inflate_unknown);
  compare("inflation_layer_name", a.inflation_layer_name, b.inflation_layer_name);
  compare("robots_layer", a.robots_layer, b.robots_layer);
  compare("robots.prediction_time", a.robots.prediction_time, b.robots.prediction_time);
  compare("robots.prediction_step", a.robots.prediction_step, b.robots.prediction_step);
  compare("robots.prediction_cost", int(a.robots.prediction_cost), int(b.robots.prediction_cost));
  compare("robots_padding", a.robots_padding, b.robots_padding);
  compare("robots_scan_margin", a.robots_scan_margin, b.robots_scan_margin);
  compare("moving_obstacles", a.moving_obstacles, b.moving_obstacles);
  compare("moving.prediction_time", a.moving.prediction_time, b.moving.prediction_time);
  compare("moving.prediction_step", a.moving.prediction_step, b.moving.prediction_step);
  compare("moving.prediction_cost", int(a.moving.prediction_cost), int(b.moving.prediction_cost));
  compare("moving.obstacle_range", a.moving.obstacle_range, b.moving.obstacle_range);
  compare("moving.static_margin", a.moving.static_margin, b.moving.static_margin);
  compare("moving.cluster_distance", a.moving.cluster_distance, b.moving.cluster_distance);
  compare("moving.max_size", a.moving.max_size, b.moving.max_size);
  compare("moving.association_gate", a.moving.association_gate, b.moving.association_gate);
  compare("moving.velocity_window", a.moving.velocity_window, b.moving.velocity_window);
  compare("moving.min_track_age", a.moving.min_track_age, b.moving.min_track_age);
  compare("moving.track_timeout", a.moving.track_timeout, b.moving.track_timeout);
  compare("moving.min_speed", a.moving.min_speed, b.moving.min_speed);
  compare("moving.max_speed", a.moving.max_speed, b.moving.max_speed);
  compare("moving.blocked_time", a.moving.blocked_time, b.moving.blocked_time);
  compare("layer_order", order(a.layer_order), order(b.layer_order));
  return out;
}
}  // namespace

TEST(MoveBaseParams, ShippedLayeredCostmapsResolveAsTheirFlatForm)
{
  // config/nav_costmaps.yaml lists its layers with `plugins`; its flat twin does not.
  ASSERT_TRUE(ros::param::has("/shipped/move_base/global_costmap/plugins"));
  ASSERT_TRUE(ros::param::has("/shipped/move_base/local_costmap/plugins"));
  ASSERT_FALSE(ros::param::has("/flat/move_base/global_costmap/plugins"));
  ASSERT_FALSE(ros::param::has("/flat/move_base/local_costmap/plugins"));

  ParamReport shipped_report, flat_report;
  NavParams shipped, flat;
  ASSERT_NO_THROW(shipped = read("shipped", shipped_report));
  ASSERT_NO_THROW(flat = read("flat", flat_report));
  // The node starts without a warning or a note.
  EXPECT_EQ(shipped_report.warnings, std::vector<std::string>{});
  EXPECT_EQ(shipped_report.notes, std::vector<std::string>{});
  EXPECT_EQ(flat_report.warnings, std::vector<std::string>{});
  EXPECT_EQ(flat_report.notes, std::vector<std::string>{});
  EXPECT_TRUE(shipped.local_costmap.obstacle_layer.inf_is_valid);  // the simulator's +Inf clears

  for (const std::string& d : differences(shipped.global_costmap, flat.global_costmap))
    ADD_FAILURE() << "global_costmap " << d << " (shipped vs flat)";
  for (const std::string& d : differences(shipped.local_costmap, flat.local_costmap))
    ADD_FAILURE() << "local_costmap " << d << " (shipped vs flat)";

  // The comparison sees a change in any one field (here: two that only the layers' namespaces set).
  CostmapRosSettings changed = shipped.local_costmap;
  changed.robots_padding += 0.05;
  changed.layer_order.pop_back();
  EXPECT_EQ(differences(shipped.local_costmap, changed).size(), 2u);
  // And the two costmaps do differ from each other (a rolling window around the robot).
  EXPECT_FALSE(differences(shipped.global_costmap, shipped.local_costmap).empty());
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_move_base_params");
  ros::NodeHandle nh;
  return RUN_ALL_TESTS();
}
