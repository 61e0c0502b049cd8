#include "mbot_navigation/local_planner/dwa_model_limits.h"
#include "mbot_navigation/ros/move_base_params.h"

#include <algorithm>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "mbot_description/robot_model.h"

namespace mbot_navigation
{
using mbot_common::StrictParams;

namespace
{
// Standard keys this node does not implement (docs/move_base_keys.md), by namespace.
const std::vector<std::string> kIgnoredMoveBaseKeys = {
    "recovery_behaviors", "conservative_reset_dist", "max_planning_retries", "make_plan_clear_costmap",
    "make_plan_add_unreachable_goal", "restore_defaults",
    // the namespaces of move_base's default recoveries, and of a planner this node does not have
    "conservative_reset", "rotate_recovery", "aggressive_reset", "CarrotPlanner"};
const std::vector<std::string> kIgnoredNavfnKeys = {"default_tolerance", "visualize_potential", "planner_window_x",
                                                    "planner_window_y", "planner_costmap_publish_frequency"};
const std::vector<std::string> kIgnoredGlobalPlannerKeys = {
    "default_tolerance",       "visualize_potential", "use_dijkstra",      "use_quadratic",    "use_grid_path",
    "old_navfn_behavior",      "lethal_cost",         "publish_potential", "publish_scale",    "orientation_mode",
    "orientation_window_size", "outline_map",         "planner_window_x",  "planner_window_y", "restore_defaults"};
const std::vector<std::string> kIgnoredDwaKeys = {"acc_lim_trans",   "acc_limit_trans",      "stop_time_buffer",
                                                  "scaling_speed",   "max_scaling_factor",   "use_dwa",
                                                  "sum_scores",      "cheat_factor",         "sim_period",
                                                  "publish_traj_pc", "publish_cost_grid_pc", "publish_cost_grid",
                                                  "global_frame_id", "meter_scoring",        "restore_defaults"};
// base_local_planner's TrajectoryPlannerROS: accepted so that a set with both local planners loads;
// this node runs DWA (base_local_planner/TrajectoryPlannerROS as base_local_planner is an error).
const std::vector<std::string> kTrajectoryPlannerKeys = {"acc_lim_x",
                                                         "acc_lim_y",
                                                         "acc_lim_theta",
                                                         "acc_lim_th",
                                                         "max_vel_x",
                                                         "min_vel_x",
                                                         "max_vel_theta",
                                                         "min_vel_theta",
                                                         "max_rotational_vel",
                                                         "min_in_place_vel_theta",
                                                         "min_in_place_rotational_vel",
                                                         "escape_vel",
                                                         "backup_vel",
                                                         "holonomic_robot",
                                                         "y_vels",
                                                         "yaw_goal_tolerance",
                                                         "xy_goal_tolerance",
                                                         "latch_xy_goal_tolerance",
                                                         "sim_time",
                                                         "sim_granularity",
                                                         "angular_sim_granularity",
                                                         "vx_samples",
                                                         "vtheta_samples",
                                                         "controller_frequency",
                                                         "meter_scoring",
                                                         "path_distance_bias",
                                                         "goal_distance_bias",
                                                         "pdist_scale",
                                                         "gdist_scale",
                                                         "occdist_scale",
                                                         "heading_lookahead",
                                                         "heading_scoring",
                                                         "heading_scoring_timestep",
                                                         "dwa",
                                                         "simple_attractor",
                                                         "publish_cost_grid_pc",
                                                         "global_frame_id",
                                                         "oscillation_reset_dist",
                                                         "escape_reset_dist",
                                                         "escape_reset_theta",
                                                         "prune_plan",
                                                         "stop_time_buffer",
                                                         "world_model",
                                                         "point_grid",
                                                         "restore_defaults"};
// costmap_2d finds these with searchParam, so they may stand at the node's level (for both costmaps).
const std::vector<std::string> kSearchedCostmapKeys = {"footprint",      "robot_radius",       "obstacle_range",
                                                       "raytrace_range", "obstacle_max_range", "raytrace_max_range"};

/// DWA keys may be given flat (~max_vel_x) or under ~DWAPlannerROS/ (dwa_local_planner's place).
/// Where both are set they must agree (dynamic_reconfigure writes ~DWAPlannerROS/ at start-up,
/// so a restarted node finds both). Older dwa_local_planner names are read as the new ones.
class DwaParams
{
public:
  DwaParams(const ros::NodeHandle& private_nh, StrictParams& flat, StrictParams& scoped)
      : nh_(private_nh), flat_(flat), scoped_(scoped)
  {}
  double getDouble(const std::string& key, double d, const std::string& old_name = "")
  {
    if (!old_name.empty()) d = get(old_name, d, &StrictParams::getDouble);
    return get(key, d, &StrictParams::getDouble);
  }
  int getInt(const std::string& key, int d, const std::string& old_name = "")
  {
    if (!old_name.empty()) d = get(old_name, d, &StrictParams::getInt);
    return get(key, d, &StrictParams::getInt);
  }
  bool getBool(const std::string& key, bool d) { return get(key, d, &StrictParams::getBool); }
  std::string getString(const std::string& key, const std::string& d)
  {
    const std::string flat = flat_.getString(key, d);
    const std::string scoped = scoped_.getString(key, flat);
    if (nh_.hasParam(key) && nh_.hasParam("DWAPlannerROS/" + key) && flat != scoped) throw conflict(key);
    return scoped;
  }
  /// True when `key` is set flat or under DWAPlannerROS/.
  bool has(const std::string& key) const { return nh_.hasParam(key) || nh_.hasParam("DWAPlannerROS/" + key); }
  std::string name(const std::string& key) const
  {
    return nh_.resolveName(nh_.hasParam("DWAPlannerROS/" + key) ? "DWAPlannerROS/" + key : key);
  }

private:
  template <typename T>
  T get(const std::string& key, T d, T (StrictParams::*read)(const std::string&, T))
  {
    const T flat = (flat_.*read)(key, d);
    const T scoped = (scoped_.*read)(key, flat);
    if (nh_.hasParam(key) && nh_.hasParam("DWAPlannerROS/" + key) && flat != scoped) throw conflict(key);
    return scoped;
  }
  std::runtime_error conflict(const std::string& key) const
  {
    return std::runtime_error("parameter " + nh_.resolveName(key) + " is also set, to another value, as " +
                              nh_.resolveName("DWAPlannerROS/" + key) + ": set it in one place");
  }
  ros::NodeHandle nh_;
  StrictParams& flat_;
  StrictParams& scoped_;
};

/// The DWA settings: dwa_local_planner's defaults, the robot model's limits, then the parameters.
DwaConfig readDwaConfig(DwaParams& p, const mbot_description::RobotModel& model, double footprint_radius,
                        double controller_frequency, ParamReport& report)
{
  // Names that dwa_local_planner itself does not read, but its wiki page (acc_lim_th) and
  // base_local_planner (vtheta_samples) use: read as the current names.
  for (const auto& alias :
       {std::make_pair("acc_lim_th", "acc_lim_theta"), std::make_pair("vtheta_samples", "vth_samples")})
    if (p.has(alias.first))
      report.notes.push_back("parameter " + p.name(alias.first) + ": read as " + alias.second +
                             " (dwa_local_planner reads only " + alias.second + ")");
  DwaConfig c;
  applyModelLimits(model.limits, c);

  c.max_vel_trans = p.getDouble("max_vel_trans", c.max_vel_trans, "max_trans_vel");
  c.min_vel_trans = p.getDouble("min_vel_trans", c.min_vel_trans, "min_trans_vel");
  c.max_vel_x = p.getDouble("max_vel_x", c.max_vel_x);
  c.min_vel_x = p.getDouble("min_vel_x", c.min_vel_x);
  c.max_vel_y = p.getDouble("max_vel_y", c.max_vel_y);
  c.min_vel_y = p.getDouble("min_vel_y", c.min_vel_y);
  c.max_vel_theta = p.getDouble("max_vel_theta", c.max_vel_theta, "max_rot_vel");
  c.min_vel_theta = p.getDouble("min_vel_theta", c.min_vel_theta, "min_rot_vel");
  c.acc_lim_x = p.getDouble("acc_lim_x", c.acc_lim_x);
  c.acc_lim_y = p.getDouble("acc_lim_y", c.acc_lim_y);
  c.acc_lim_theta = p.getDouble("acc_lim_theta", c.acc_lim_theta, "acc_lim_th");
  c.trans_stopped_vel = p.getDouble("trans_stopped_vel", c.trans_stopped_vel);
  c.theta_stopped_vel = p.getDouble("theta_stopped_vel", c.theta_stopped_vel, "rot_stopped_vel");
  c.xy_goal_tolerance = p.getDouble("xy_goal_tolerance", c.xy_goal_tolerance);
  c.yaw_goal_tolerance = p.getDouble("yaw_goal_tolerance", c.yaw_goal_tolerance);
  c.latch_xy_goal_tolerance = p.getBool("latch_xy_goal_tolerance", c.latch_xy_goal_tolerance);
  c.sim_time = p.getDouble("sim_time", c.sim_time);
  c.sim_granularity = p.getDouble("sim_granularity", c.sim_granularity);
  c.angular_sim_granularity = p.getDouble("angular_sim_granularity", c.angular_sim_granularity);
  c.vx_samples = p.getInt("vx_samples", c.vx_samples);
  c.vy_samples = p.getInt("vy_samples", c.vy_samples);
  c.vth_samples = p.getInt("vth_samples", c.vth_samples, "vtheta_samples");
  // dwa_local_planner's dynamic_reconfigure server raises a count below 1 to 1 (vy_samples: 0 is common).
  auto atLeastOne = [&](int& samples, const std::string& key) {
    if (samples >= 1) return;
    report.notes.push_back("parameter " + p.name(key) + ": " + std::to_string(samples) +
                           " is raised to 1, as dwa_local_planner does");
    samples = 1;
  };
  atLeastOne(c.vx_samples, "vx_samples");
  atLeastOne(c.vy_samples, "vy_samples");
  atLeastOne(c.vth_samples, "vth_samples");
  c.path_distance_bias = p.getDouble("path_distance_bias", c.path_distance_bias);
  c.goal_distance_bias = p.getDouble("goal_distance_bias", c.goal_distance_bias);
  c.occdist_scale = p.getDouble("occdist_scale", c.occdist_scale);
  c.twirling_scale = p.getDouble("twirling_scale", c.twirling_scale);
  c.forward_point_distance = p.getDouble("forward_point_distance", c.forward_point_distance);
  c.oscillation_reset_dist = p.getDouble("oscillation_reset_dist", c.oscillation_reset_dist);
  c.oscillation_reset_angle = p.getDouble("oscillation_reset_angle", c.oscillation_reset_angle);
  c.prune_plan = p.getBool("prune_plan", c.prune_plan);
  c.controller_frequency = controller_frequency;
  c.footprint_radius = footprint_radius;
  c.validate();  // std::invalid_argument naming the key
  return c;
}

AStarConfig readAStarConfig(StrictParams& p)
{
  AStarConfig c;
  c.neutral_cost = p.getDouble("neutral_cost", c.neutral_cost);
  c.cost_factor = p.getDouble("cost_factor", c.cost_factor);
  c.allow_unknown = p.getBool("allow_unknown", c.allow_unknown);
  c.heuristic_weight = p.getDouble("heuristic_weight", c.heuristic_weight);
  c.smooth_path = p.getBool("smooth_path", c.smooth_path);
  c.smoothing_tolerance = p.getDouble("smoothing_tolerance", c.smoothing_tolerance);
  c.smoothing_passes = p.getInt("smoothing_passes", c.smoothing_passes);
  return c;
}

OmplConfig readOmplConfig(StrictParams& p)
{
  OmplConfig c;
  c.planner = p.getString("planner", c.planner);
  c.time_limit = p.getDouble("time_limit", c.time_limit);
  const int seed = p.getInt("seed", static_cast<int>(c.seed));
  if (seed <= 0) throw std::runtime_error("parameter OmplPlanner/seed: expected an integer > 0");
  c.seed = static_cast<unsigned>(seed);
  c.path_resolution = p.getDouble("path_resolution", c.path_resolution);
  c.simplify = p.getBool("simplify", c.simplify);
  c.simplify_time_limit = p.getDouble("simplify_time_limit", c.simplify_time_limit);
  c.cost_weight = p.getDouble("cost_weight", c.cost_weight);
  return c;
}

std::vector<std::string> readNameList(const ros::NodeHandle& nh, const std::string& key)
{
  std::vector<std::string> names;
  XmlRpc::XmlRpcValue v;
  if (!nh.getParam(key, v)) return names;
  const std::string expected = "parameter " + nh.resolveName(key) + ": expected a list of robot names";
  if (v.getType() != XmlRpc::XmlRpcValue::TypeArray) throw std::runtime_error(expected);
  for (int i = 0; i < v.size(); ++i)
  {
    if (v[i].getType() != XmlRpc::XmlRpcValue::TypeString) throw std::runtime_error(expected);
    names.push_back(static_cast<std::string>(v[i]));
  }
  return names;
}

void require(bool ok, const ros::NodeHandle& nh, const std::string& key, const std::string& expected)
{
  if (!ok) throw std::runtime_error("parameter " + nh.resolveName(key) + ": expected " + expected);
}

double toNumber(const XmlRpc::XmlRpcValue& v, bool& ok)
{
  if (v.getType() == XmlRpc::XmlRpcValue::TypeDouble) return static_cast<double>(const_cast<XmlRpc::XmlRpcValue&>(v));
  if (v.getType() == XmlRpc::XmlRpcValue::TypeInt) return static_cast<int>(const_cast<XmlRpc::XmlRpcValue&>(v));
  ok = false;
  return 0.0;
}
/// move_base's recovery_behaviors name the namespaces of their settings: accept those (the
/// recoveries here are fixed: clear costmaps, rotate, back up).
void ignoreRecoveryNamespaces(StrictParams& p, const ros::NodeHandle& nh, ParamReport& report)
{
  XmlRpc::XmlRpcValue list;
  if (!nh.getParam("recovery_behaviors", list) || list.getType() != XmlRpc::XmlRpcValue::TypeArray) return;
  for (int i = 0; i < list.size(); ++i)
  {
    XmlRpc::XmlRpcValue& entry = list[i];
    if (entry.getType() != XmlRpc::XmlRpcValue::TypeStruct || !entry.hasMember("name") ||
        entry["name"].getType() != XmlRpc::XmlRpcValue::TypeString)
      continue;
    const std::string name = entry["name"];
    p.markKnown(name);
    if (nh.hasParam(name))
      report.notes.push_back("parameter " + nh.resolveName(name) + ": the settings of recovery behaviour '" + name +
                             "', which this node does not run; ignored");
  }
}
}  // namespace

void ignoreStandardKeys(StrictParams& p, const ros::NodeHandle& nh, const std::vector<std::string>& keys,
                        const std::string& what, ParamReport& report)
{
  for (const std::string& key : keys)
  {
    p.markKnown(key);
    if (!nh.hasParam(key)) continue;
    const std::string note = "parameter " + nh.resolveName(key) + ": ";
    const bool noted = std::any_of(report.notes.begin(), report.notes.end(),
                                   [&](const std::string& n) { return n.compare(0, note.size(), note) == 0; });
    if (!noted) report.notes.push_back(note + what + " that this node does not implement; ignored");
  }
}

void reportUnknownKeys(const StrictParams& p, ParamReport& report)
{
  for (const std::string& w : p.checkNoUnknown()) report.warnings.push_back(w);
}

double searchDouble(const ros::NodeHandle& from, const std::string& key, double default_value, std::string* found)
{
  std::string name;
  if (found) found->clear();
  if (!from.searchParam(key, name)) return default_value;
  XmlRpc::XmlRpcValue v;
  if (!from.getParam(name, v)) return default_value;
  bool ok = true;
  const double value = toNumber(v, ok);
  if (!ok) throw std::runtime_error("parameter " + name + ": expected a number");
  if (found) *found = name;
  return value;
}

std::string globalPlannerFor(const std::string& name, const std::string& param)
{
  if (name == "astar" || name == "global_planner/GlobalPlanner" || name == "navfn/NavfnROS") return "astar";
  if (name == "ompl") return "ompl";
  throw std::runtime_error("parameter " + param + ": expected astar, ompl, global_planner/GlobalPlanner or " +
                           "navfn/NavfnROS (both run our A*), got '" + name + "'");
}

std::string localPlannerFor(const std::string& name, const std::string& param)
{
  if (name == "dwa" || name == "dwa_local_planner/DWAPlannerROS") return "dwa";
  if (name == "base_local_planner/TrajectoryPlannerROS")
    throw std::runtime_error("parameter " + param + ": base_local_planner/TrajectoryPlannerROS is not supported; " +
                             "use dwa_local_planner/DWAPlannerROS (DWAPlannerROS/ keys)");
  throw std::runtime_error("parameter " + param + ": expected dwa or dwa_local_planner/DWAPlannerROS, got '" + name +
                           "'");
}

double footprintRadius(const XmlRpc::XmlRpcValue& footprint, const std::string& param)
{
  const std::string expected = "parameter " + param + ": expected a list of at least 3 [x, y] points";
  std::vector<std::pair<double, double>> points;
  if (footprint.getType() == XmlRpc::XmlRpcValue::TypeString)
  {
    // costmap_2d also takes "[[x, y], [x, y], ...]" as a string.
    std::string text = static_cast<std::string>(const_cast<XmlRpc::XmlRpcValue&>(footprint));
    std::replace_if(
        text.begin(), text.end(), [](char ch) { return ch == '[' || ch == ']' || ch == ','; }, ' ');
    std::istringstream in(text);
    double x, y;
    while (in >> x)
    {
      if (!(in >> y)) throw std::runtime_error(expected);
      points.emplace_back(x, y);
    }
    if (!in.eof()) throw std::runtime_error(expected);
  }
  else if (footprint.getType() == XmlRpc::XmlRpcValue::TypeArray)
  {
    XmlRpc::XmlRpcValue& list = const_cast<XmlRpc::XmlRpcValue&>(footprint);
    for (int i = 0; i < list.size(); ++i)
    {
      bool ok = list[i].getType() == XmlRpc::XmlRpcValue::TypeArray && list[i].size() == 2;
      const double x = ok ? toNumber(list[i][0], ok) : 0.0;
      const double y = ok ? toNumber(list[i][1], ok) : 0.0;
      if (!ok) throw std::runtime_error(expected);
      points.emplace_back(x, y);
    }
  }
  if (points.size() < 3) throw std::runtime_error(expected);
  double radius = 0.0;
  for (const auto& pt : points) radius = std::max(radius, std::hypot(pt.first, pt.second));
  return radius;
}

NavParams readNavParams(const ros::NodeHandle& nh, const ros::NodeHandle& private_nh,
                        const std::string& description_dir, ParamReport& report)
{
  NavParams out;
  StrictParams p(private_nh, mbot_common::UnknownKeys::WARN);
  out.robot = mbot_common::robotName(p, nh);
  out.model = p.getString("model", "mbot");
  mbot_description::RobotModel model;
  try
  {
    model = mbot_description::loadRobotModel(description_dir, out.model);
  }
  catch (const mbot_description::ModelError& e)
  {
    throw std::runtime_error("parameter " + private_nh.resolveName("model") + " = '" + out.model + "': " + e.what());
  }
  out.footprint_radius = model.footprint_radius;
  out.model_min_vel_x = model.limits.min_vel_x;

  // --- move_base's own parameters
  const std::string global_planner = p.getString("base_global_planner", "astar");
  out.global_planner = globalPlannerFor(global_planner, private_nh.resolveName("base_global_planner"));
  localPlannerFor(p.getString("base_local_planner", "dwa"), private_nh.resolveName("base_local_planner"));
  out.controller_frequency = p.getDouble("controller_frequency", 20.0);
  require(out.controller_frequency > 0.0, private_nh, "controller_frequency", "a number > 0 [Hz]");
  NavigatorConfig& nav = out.nav;
  nav.planner_frequency = p.getDouble("planner_frequency", nav.planner_frequency);
  nav.planner_patience = p.getDouble("planner_patience", nav.planner_patience);
  nav.controller_patience = p.getDouble("controller_patience", nav.controller_patience);
  nav.oscillation_timeout = p.getDouble("oscillation_timeout", nav.oscillation_timeout);
  nav.oscillation_distance = p.getDouble("oscillation_distance", nav.oscillation_distance);
  nav.recovery_behavior_enabled = p.getBool("recovery_behavior_enabled", nav.recovery_behavior_enabled);
  out.clearing_rotation_allowed = p.getBool("clearing_rotation_allowed", true);
  out.shutdown_costmaps = p.getBool("shutdown_costmaps", false);
  out.back_up.distance = p.getDouble("back_up_distance", out.back_up.distance);
  out.back_up.speed = p.getDouble("back_up_speed", out.back_up.speed);
  require(out.back_up.distance >= 0.0, private_nh, "back_up_distance", "a number >= 0 [m] (0: no backing up)");
  require(out.back_up.speed > 0.0, private_nh, "back_up_speed", "a number > 0 [m/s]");
  ignoreStandardKeys(p, private_nh, kIgnoredMoveBaseKeys, "a move_base key", report);
  ignoreRecoveryNamespaces(p, private_nh, report);
  for (const std::string& key : kSearchedCostmapKeys) p.markKnown(key);  // read by the costmaps (searchParam)

  // --- teammates
  out.robots = readNameList(private_nh, "robots");
  p.markKnown("robots");
  out.robots_source = p.getString("robots_source", "ground_truth");
  require(out.robots_source == "ground_truth" || out.robots_source == "odom", private_nh, "robots_source",
          "'ground_truth' or 'odom', got '" + out.robots_source + "'");
  out.robots_timeout = p.getDouble("robots_timeout", 1.0);

  // --- costmaps
  CostmapRosSettings global_defaults;
  global_defaults.robot_base_frame = mbot_common::prefixedFrame(out.robot, "base_footprint");
  global_defaults.costmap.robot_radius = out.footprint_radius;
  global_defaults.costmap.rolling_window = false;
  global_defaults.update_frequency = 5.0;
  global_defaults.publish_frequency = 1.0;
  CostmapRosSettings local_defaults = global_defaults;
  local_defaults.costmap.rolling_window = true;
  local_defaults.costmap.width = local_defaults.costmap.height = 4.0;
  local_defaults.update_frequency = 10.0;
  local_defaults.publish_frequency = 2.0;
  p.markKnown("global_costmap");
  p.markKnown("local_costmap");
  out.global_costmap = readCostmapSettings(ros::NodeHandle(private_nh, "global_costmap"), global_defaults, &report);
  out.local_costmap = readCostmapSettings(ros::NodeHandle(private_nh, "local_costmap"), local_defaults, &report);
  if (out.global_costmap.robot_base_frame != out.local_costmap.robot_base_frame)
    throw std::runtime_error("parameters " + private_nh.resolveName("global_costmap/robot_base_frame") + " and " +
                             private_nh.resolveName("local_costmap/robot_base_frame") +
                             ": must be the same (one robot)");
  if (out.global_costmap.global_frame != out.local_costmap.global_frame)
  {
    // move_base's tutorials run the local costmap in odom. Here the plan is shared between the
    // two costmaps, so the local window lives in the global costmap's frame.
    report.notes.push_back("parameter " + private_nh.resolveName("local_costmap/global_frame") + ": '" +
                           out.local_costmap.global_frame + "' is not the global costmap's frame; the local costmap " +
                           "runs in '" + out.global_costmap.global_frame + "' here (the plan is shared)");
    out.local_costmap.global_frame = out.global_costmap.global_frame;
  }

  // --- planners: our A* reads global_planner's keys (and navfn's allow_unknown when it stands in for navfn)
  {
    const ros::NodeHandle gp_nh(private_nh, "GlobalPlanner");
    StrictParams gp(gp_nh, mbot_common::UnknownKeys::WARN);
    p.markKnown("GlobalPlanner");
    out.planners.astar = readAStarConfig(gp);
    ignoreStandardKeys(gp, gp_nh, kIgnoredGlobalPlannerKeys, "a global_planner key", report);
    reportUnknownKeys(gp, report);
    const ros::NodeHandle nf_nh(private_nh, "NavfnROS");
    StrictParams nf(nf_nh, mbot_common::UnknownKeys::WARN);
    p.markKnown("NavfnROS");
    const bool navfn_allow_unknown = nf.getBool("allow_unknown", out.planners.astar.allow_unknown);
    if (global_planner == "navfn/NavfnROS") out.planners.astar.allow_unknown = navfn_allow_unknown;
    ignoreStandardKeys(nf, nf_nh, kIgnoredNavfnKeys, "a navfn key", report);
    reportUnknownKeys(nf, report);
    StrictParams op(ros::NodeHandle(private_nh, "OmplPlanner"), mbot_common::UnknownKeys::WARN);
    p.markKnown("OmplPlanner");
    out.planners.ompl = readOmplConfig(op);
    reportUnknownKeys(op, report);
  }
  nav.allow_unknown = out.planners.astar.allow_unknown;
  {
    const ros::NodeHandle dwa_nh(private_nh, "DWAPlannerROS");
    StrictParams dp(dwa_nh, mbot_common::UnknownKeys::WARN);
    p.markKnown("DWAPlannerROS");
    DwaParams dwa_params(private_nh, p, dp);
    // As dwa_local_planner: its own controller_frequency (searchParam), else move_base's.
    const double dwa_frequency = dp.getDouble("controller_frequency", out.controller_frequency);
    try
    {
      out.dwa = readDwaConfig(dwa_params, model, out.local_costmap.costmap.robot_radius, dwa_frequency, report);
    }
    catch (const std::invalid_argument& e)
    {
      throw std::runtime_error(std::string("parameters ") + dwa_nh.getNamespace() + "/: " + e.what());
    }
    out.odom_topic = dwa_params.getString("odom_topic", out.odom_topic);
    ignoreStandardKeys(dp, dwa_nh, kIgnoredDwaKeys, "a dwa_local_planner key", report);
    ignoreStandardKeys(p, private_nh, kIgnoredDwaKeys, "a dwa_local_planner key", report);
    reportUnknownKeys(dp, report);
  }
  {
    const ros::NodeHandle tp_nh(private_nh, "TrajectoryPlannerROS");
    StrictParams tp(tp_nh, mbot_common::UnknownKeys::WARN);
    p.markKnown("TrajectoryPlannerROS");
    ignoreStandardKeys(tp, tp_nh, kTrajectoryPlannerKeys, "a base_local_planner key (this node runs DWA)", report);
    reportUnknownKeys(tp, report);
  }
  reportUnknownKeys(p, report);
  // Both costmaps may find the same key at the node's level (footprint): say it once.
  for (std::vector<std::string>* lines : {&report.notes, &report.warnings})
  {
    std::vector<std::string> unique;
    for (const std::string& line : *lines)
      if (std::find(unique.begin(), unique.end(), line) == unique.end()) unique.push_back(line);
    lines->swap(unique);
  }
  return out;
}

DWAPlannerConfig toReconfigure(const DwaConfig& d)
{
  DWAPlannerConfig c;
  c.max_vel_trans = d.max_vel_trans;
  c.min_vel_trans = d.min_vel_trans;
  c.max_vel_x = d.max_vel_x;
  c.min_vel_x = d.min_vel_x;
  c.max_vel_y = d.max_vel_y;
  c.min_vel_y = d.min_vel_y;
  c.max_vel_theta = d.max_vel_theta;
  c.min_vel_theta = d.min_vel_theta;
  c.acc_lim_x = d.acc_lim_x;
  c.acc_lim_y = d.acc_lim_y;
  c.acc_lim_theta = d.acc_lim_theta;
  c.trans_stopped_vel = d.trans_stopped_vel;
  c.theta_stopped_vel = d.theta_stopped_vel;
  c.xy_goal_tolerance = d.xy_goal_tolerance;
  c.yaw_goal_tolerance = d.yaw_goal_tolerance;
  c.latch_xy_goal_tolerance = d.latch_xy_goal_tolerance;
  c.sim_time = d.sim_time;
  c.sim_granularity = d.sim_granularity;
  c.angular_sim_granularity = d.angular_sim_granularity;
  c.vx_samples = d.vx_samples;
  c.vy_samples = d.vy_samples;
  c.vth_samples = d.vth_samples;
  c.path_distance_bias = d.path_distance_bias;
  c.goal_distance_bias = d.goal_distance_bias;
  c.occdist_scale = d.occdist_scale;
  c.twirling_scale = d.twirling_scale;
  c.forward_point_distance = d.forward_point_distance;
  c.oscillation_reset_dist = d.oscillation_reset_dist;
  c.oscillation_reset_angle = d.oscillation_reset_angle;
  c.prune_plan = d.prune_plan;
  return c;
}

DwaConfig fromReconfigure(const DWAPlannerConfig& c, const DwaConfig& base)
{
  DwaConfig d = base;
  d.max_vel_trans = c.max_vel_trans;
  d.min_vel_trans = c.min_vel_trans;
  d.max_vel_x = c.max_vel_x;
  d.min_vel_x = c.min_vel_x;
  d.max_vel_y = c.max_vel_y;
  d.min_vel_y = c.min_vel_y;
  d.max_vel_theta = c.max_vel_theta;
  d.min_vel_theta = c.min_vel_theta;
  d.acc_lim_x = c.acc_lim_x;
  d.acc_lim_y = c.acc_lim_y;
  d.acc_lim_theta = c.acc_lim_theta;
  d.trans_stopped_vel = c.trans_stopped_vel;
  d.theta_stopped_vel = c.theta_stopped_vel;
  d.xy_goal_tolerance = c.xy_goal_tolerance;
  d.yaw_goal_tolerance = c.yaw_goal_tolerance;
  d.latch_xy_goal_tolerance = c.latch_xy_goal_tolerance;
  d.sim_time = c.sim_time;
  d.sim_granularity = c.sim_granularity;
  d.angular_sim_granularity = c.angular_sim_granularity;
  d.vx_samples = c.vx_samples;
  d.vy_samples = c.vy_samples;
  d.vth_samples = c.vth_samples;
  d.path_distance_bias = c.path_distance_bias;
  d.goal_distance_bias = c.goal_distance_bias;
  d.occdist_scale = c.occdist_scale;
  d.twirling_scale = c.twirling_scale;
  d.forward_point_distance = c.forward_point_distance;
  d.oscillation_reset_dist = c.oscillation_reset_dist;
  d.oscillation_reset_angle = c.oscillation_reset_angle;
  d.prune_plan = c.prune_plan;
  return d;
}

InflationConfig toReconfigure(const InflationLayerConfig& i)
{
  InflationConfig c;
  c.inflation_radius = i.inflation_radius;
  c.cost_scaling_factor = i.cost_scaling_factor;
  c.inflate_unknown = i.inflate_unknown;
  return c;
}

InflationLayerConfig fromReconfigure(const InflationConfig& c)
{
  InflationLayerConfig i;
  i.inflation_radius = c.inflation_radius;
  i.cost_scaling_factor = c.cost_scaling_factor;
  i.inflate_unknown = c.inflate_unknown;
  return i;
}

}  // namespace mbot_navigation
