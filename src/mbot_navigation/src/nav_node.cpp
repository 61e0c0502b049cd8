#include "mbot_navigation/nav_node.h"

#include <algorithm>
#include <cmath>
#include <regex>
#include <stdexcept>

#include <ros/package.h>
#include <tf2/exceptions.h>
#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include "mbot_description/robot_model.h"
#include <mbot_common/ros_edge.h>
#include "mbot_navigation/planner_factory.h"

namespace mbot_navigation
{
using mbot_common::StrictParams;

namespace
{
// =============================================================================================
// parameters

/// DWA keys may be given flat (~max_vel_x) or under ~DWAPlannerROS/ (dwa_local_planner's place),
/// not both.
class DwaParams
{
public:
  DwaParams(const ros::NodeHandle& private_nh, StrictParams& flat, StrictParams& scoped)
    : nh_(private_nh), flat_(flat), scoped_(scoped)
  {
  }
  // The flat value (or the default) is the default of the scoped one; both readers mark the key
  // as known, so that neither reports it as unknown.
  double getDouble(const std::string& key, double d)
  {
    check(key);
    return scoped_.getDouble(key, flat_.getDouble(key, d));
  }
  int getInt(const std::string& key, int d)
  {
    check(key);
    return scoped_.getInt(key, flat_.getInt(key, d));
  }
  bool getBool(const std::string& key, bool d)
  {
    check(key);
    return scoped_.getBool(key, flat_.getBool(key, d));
  }

private:
  void check(const std::string& key) const
  {
    if (nh_.hasParam(key) && nh_.hasParam("DWAPlannerROS/" + key))
      throw std::runtime_error("parameter " + nh_.resolveName(key) + " is also set as " +
                               nh_.resolveName("DWAPlannerROS/" + key) + ": set it in one place");
  }
  ros::NodeHandle nh_;
  StrictParams& flat_;
  StrictParams& scoped_;
};

/// The DWA settings: dwa_local_planner's defaults, the robot model's limits, then the parameters.
DwaConfig readDwaConfig(DwaParams& p, const mbot_description::RobotModel& model, double footprint_radius,
                        double controller_frequency)
{
  DwaConfig c;
  const mbot_description::Limits& lim = model.limits;
  c.max_vel_x = lim.max_vel_x;
  c.min_vel_x = lim.min_vel_x;
  c.max_vel_y = lim.max_vel_y;
  c.min_vel_y = -lim.max_vel_y;
  c.max_vel_trans = std::max(lim.max_vel_x, lim.max_vel_y);
  c.max_vel_theta = lim.max_vel_theta;
  c.min_vel_theta = std::min(c.min_vel_theta, lim.max_vel_theta);
  c.acc_lim_x = lim.acc_lim_x;
  c.acc_lim_y = lim.acc_lim_y;
  c.acc_lim_theta = lim.acc_lim_theta;

  c.max_vel_trans = p.getDouble("max_vel_trans", c.max_vel_trans);
  c.min_vel_trans = p.getDouble("min_vel_trans", c.min_vel_trans);
  c.max_vel_x = p.getDouble("max_vel_x", c.max_vel_x);
  c.min_vel_x = p.getDouble("min_vel_x", c.min_vel_x);
  c.max_vel_y = p.getDouble("max_vel_y", c.max_vel_y);
  c.min_vel_y = p.getDouble("min_vel_y", c.min_vel_y);
  c.max_vel_theta = p.getDouble("max_vel_theta", c.max_vel_theta);
  c.min_vel_theta = p.getDouble("min_vel_theta", c.min_vel_theta);
  c.acc_lim_x = p.getDouble("acc_lim_x", c.acc_lim_x);
  c.acc_lim_y = p.getDouble("acc_lim_y", c.acc_lim_y);
  c.acc_lim_theta = p.getDouble("acc_lim_theta", c.acc_lim_theta);
  c.trans_stopped_vel = p.getDouble("trans_stopped_vel", c.trans_stopped_vel);
  c.theta_stopped_vel = p.getDouble("theta_stopped_vel", c.theta_stopped_vel);
  c.xy_goal_tolerance = p.getDouble("xy_goal_tolerance", c.xy_goal_tolerance);
  c.yaw_goal_tolerance = p.getDouble("yaw_goal_tolerance", c.yaw_goal_tolerance);
  c.latch_xy_goal_tolerance = p.getBool("latch_xy_goal_tolerance", c.latch_xy_goal_tolerance);
  c.sim_time = p.getDouble("sim_time", c.sim_time);
  c.sim_granularity = p.getDouble("sim_granularity", c.sim_granularity);
  c.angular_sim_granularity = p.getDouble("angular_sim_granularity", c.angular_sim_granularity);
  c.vx_samples = p.getInt("vx_samples", c.vx_samples);
  c.vy_samples = p.getInt("vy_samples", c.vy_samples);
  c.vth_samples = p.getInt("vth_samples", c.vth_samples);
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

geometry_msgs::PoseStamped toPoseStamped(const Pose2D& p, const std::string& frame, const ros::Time& stamp)
{
  geometry_msgs::PoseStamped out;
  out.header.frame_id = frame;
  out.header.stamp = stamp;
  out.pose = mbot_common::toPoseMsg(p);
  return out;
}
}  // namespace

// =============================================================================================
// TeammateTracker

TeammateTracker::TeammateTracker(tf2_ros::Buffer& tf, const std::string& self, const std::string& global_frame,
                                 Source source, const std::vector<std::string>& names, double timeout,
                                 std::function<double(const std::string&)> radius_of)
  : tf_(tf), self_(self), global_frame_(global_frame), source_(source), timeout_(timeout),
    radius_of_(std::move(radius_of))
{
  for (const std::string& name : names)
    if (name != self_) track(name);
}

void TeammateTracker::track(const std::string& name)
{
  if (mates_.count(name)) return;
  Mate& mate = mates_[name];
  mate.radius = radius_of_(name);
  ros::NodeHandle root;
  const std::string topic = "/" + name + (source_ == Source::GROUND_TRUTH ? "/base_pose_ground_truth" : "/odom");
  mate.sub = root.subscribe<nav_msgs::Odometry>(topic, 1, [this, name](const nav_msgs::Odometry::ConstPtr& msg) {
    mates_[name].last = msg;
  });
  ROS_INFO("teammate %s: from %s (radius %.2f m)", name.c_str(), topic.c_str(), mate.radius);
}

void TeammateTracker::discover()
{
  ros::master::V_TopicInfo topics;
  if (!ros::master::getTopics(topics)) return;
  static const std::regex odom_topic("^/([^/]+)/odom$");
  for (const ros::master::TopicInfo& t : topics)
  {
    std::smatch m;
    if (t.datatype != "nav_msgs/Odometry" || !std::regex_match(t.name, m, odom_topic)) continue;
    if (m[1] != self_) track(m[1]);
  }
}

std::vector<std::string> TeammateTracker::names() const
{
  std::vector<std::string> out;
  for (const auto& kv : mates_) out.push_back(kv.first);
  return out;
}

std::vector<TeammateState> TeammateTracker::states(const ros::Time& now) const
{
  std::vector<TeammateState> out;
  for (const auto& kv : mates_)
  {
    const nav_msgs::Odometry::ConstPtr& msg = kv.second.last;
    if (!msg || std::fabs((now - msg->header.stamp).toSec()) > timeout_) continue;
    TeammateState s;
    s.name = kv.first;
    s.radius = kv.second.radius;
    s.vx = msg->twist.twist.linear.x;
    s.vy = msg->twist.twist.linear.y;
    s.wz = msg->twist.twist.angular.z;
    if (source_ == Source::GROUND_TRUTH)
    {
      s.pose = mbot_common::toPose2D(msg->pose.pose);
    }
    else
    {
      try
      {
        s.pose = mbot_common::toPose2D(
            tf_.lookupTransform(global_frame_, kv.first + "/base_footprint", ros::Time(0)).transform);
      }
      catch (const tf2::TransformException&)
      {
        continue;  // no pose for it yet
      }
    }
    out.push_back(s);
  }
  return out;
}

// =============================================================================================
// NavNode: set-up

NavNode::NavNode(ros::NodeHandle nh, ros::NodeHandle private_nh)
  : nh_(nh), private_nh_(private_nh)
{
  StrictParams p(private_nh_);
  robot_ = mbot_common::robotName(p, nh_);
  own_model_ = p.getString("model", "mbot");
  description_dir_ = ros::package::getPath("mbot_description");
  if (description_dir_.empty()) throw std::runtime_error("cannot find the package mbot_description (robot models)");
  mbot_description::RobotModel model;
  try
  {
    model = mbot_description::loadRobotModel(description_dir_, own_model_);
  }
  catch (const mbot_description::ModelError& e)
  {
    throw std::runtime_error("parameter " + private_nh_.resolveName("model") + " = '" + own_model_ + "': " + e.what());
  }
  own_radius_ = model.footprint_radius;
  model_radius_[own_model_] = own_radius_;

  // --- move_base's own parameters
  const std::string global_planner_name = p.getString("base_global_planner", "astar");
  const std::string local_planner_name = p.getString("base_local_planner", "dwa");
  require(local_planner_name == "dwa" || local_planner_name == "dwa_local_planner/DWAPlannerROS", private_nh_,
          "base_local_planner", "'dwa' (the only local planner), got '" + local_planner_name + "'");
  const double controller_frequency = p.getDouble("controller_frequency", 20.0);
  require(controller_frequency > 0.0, private_nh_, "controller_frequency", "a number > 0 [Hz]");
  NavigatorConfig nav;
  nav.planner_frequency = p.getDouble("planner_frequency", nav.planner_frequency);
  nav.planner_patience = p.getDouble("planner_patience", nav.planner_patience);
  nav.controller_patience = p.getDouble("controller_patience", nav.controller_patience);
  nav.oscillation_timeout = p.getDouble("oscillation_timeout", nav.oscillation_timeout);
  nav.oscillation_distance = p.getDouble("oscillation_distance", nav.oscillation_distance);
  nav.recovery_behavior_enabled = p.getBool("recovery_behavior_enabled", nav.recovery_behavior_enabled);
  controller_patience_ = nav.controller_patience;
  const bool clearing_rotation_allowed = p.getBool("clearing_rotation_allowed", true);
  BackUpRecoveryConfig back_up;
  back_up.distance = p.getDouble("back_up_distance", back_up.distance);
  back_up.speed = p.getDouble("back_up_speed", back_up.speed);
  require(back_up.distance >= 0.0, private_nh_, "back_up_distance", "a number >= 0 [m] (0: no backing up)");
  require(back_up.speed > 0.0, private_nh_, "back_up_speed", "a number > 0 [m/s]");

  // --- teammates
  const std::vector<std::string> robots = readNameList(private_nh_, "robots");
  p.markKnown("robots");
  const std::string robots_source = p.getString("robots_source", "ground_truth");
  require(robots_source == "ground_truth" || robots_source == "odom", private_nh_, "robots_source",
          "'ground_truth' or 'odom', got '" + robots_source + "'");
  const double robots_timeout = p.getDouble("robots_timeout", 1.0);

  // --- costmaps
  CostmapRosSettings global_defaults;
  global_defaults.robot_base_frame = mbot_common::prefixedFrame(robot_, "base_footprint");
  global_defaults.costmap.robot_radius = own_radius_;
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
  const CostmapRosSettings global_settings =
      readCostmapSettings(ros::NodeHandle(private_nh_, "global_costmap"), global_defaults);
  const CostmapRosSettings local_settings =
      readCostmapSettings(ros::NodeHandle(private_nh_, "local_costmap"), local_defaults);
  if (global_settings.global_frame != local_settings.global_frame ||
      global_settings.robot_base_frame != local_settings.robot_base_frame)
    throw std::runtime_error("parameters " + private_nh_.resolveName("global_costmap") + " and " +
                             private_nh_.resolveName("local_costmap") +
                             ": global_frame and robot_base_frame must be the same in both (the plan is shared)");
  global_frame_ = global_settings.global_frame;
  robot_base_frame_ = global_settings.robot_base_frame;
  transform_tolerance_ = global_settings.transform_tolerance;

  // --- planners
  GlobalPlannerParams planner_params;
  {
    StrictParams gp(ros::NodeHandle(private_nh_, "GlobalPlanner"));
    p.markKnown("GlobalPlanner");
    planner_params.astar = readAStarConfig(gp);
    gp.checkNoUnknown();
    StrictParams op(ros::NodeHandle(private_nh_, "OmplPlanner"));
    p.markKnown("OmplPlanner");
    planner_params.ompl = readOmplConfig(op);
    op.checkNoUnknown();
  }
  nav.allow_unknown = planner_params.astar.allow_unknown;
  goal_checker_ = StaticGoalChecker(nav.allow_unknown);  // "unreachable" as the planner sees it
  DwaConfig dwa;
  {
    StrictParams dp(ros::NodeHandle(private_nh_, "DWAPlannerROS"));
    p.markKnown("DWAPlannerROS");
    DwaParams dwa_params(private_nh_, p, dp);
    dwa = readDwaConfig(dwa_params, model, local_settings.costmap.robot_radius, controller_frequency);
    dp.checkNoUnknown();
  }
  p.checkNoUnknown();

  std::unique_ptr<GlobalPlanner> global_planner;
  try
  {
    global_planner = makeGlobalPlanner(global_planner_name, planner_params);
  }
  catch (const std::invalid_argument& e)
  {
    throw std::runtime_error("parameter " + private_nh_.resolveName("base_global_planner") + ": " + e.what());
  }

  // --- the parts
  tf_ = std::make_unique<tf2_ros::Buffer>(ros::Duration(10.0));
  tf_listener_ = std::make_unique<tf2_ros::TransformListener>(*tf_);
  global_costmap_ = std::make_unique<CostmapRos>("global_costmap", global_settings, nh_, private_nh_, *tf_);
  local_costmap_ = std::make_unique<CostmapRos>("local_costmap", local_settings, nh_, private_nh_, *tf_);

  std::vector<std::unique_ptr<RecoveryBehavior>> recoveries;
  recoveries.push_back(std::make_unique<ClearCostmapsRecovery>([this]() {
    global_costmap_->clear();
    local_costmap_->clear();
  }));
  if (clearing_rotation_allowed)
  {
    RotateRecoveryConfig rotate;
    rotate.max_vel_theta = std::min(1.0, dwa.max_vel_theta);
    rotate.min_vel_theta = std::min(dwa.min_vel_theta, rotate.max_vel_theta);
    rotate.acc_lim_theta = dwa.acc_lim_theta;
    rotate.control_period = 1.0 / controller_frequency;
    recoveries.push_back(std::make_unique<RotateRecovery>(rotate));
  }
  back_up.footprint_radius = local_settings.costmap.robot_radius;
  back_up.speed = std::min(back_up.speed, -model.limits.min_vel_x);  // a robot that cannot reverse does not
  if (back_up.distance > 0.0 && back_up.speed > 0.0) recoveries.push_back(std::make_unique<BackUpRecovery>(back_up));
  navigator_ = std::make_unique<Navigator>(nav, dwa, std::move(global_planner), std::move(recoveries));

  teammates_ = std::make_unique<TeammateTracker>(
      *tf_, robot_, global_frame_,
      robots_source == "odom" ? TeammateTracker::Source::ODOM : TeammateTracker::Source::GROUND_TRUTH, robots,
      robots_timeout, [this](const std::string& name) { return teammateRadius(name); });
  if (robots.empty())
  {
    teammates_->discover();
    discovery_timer_ = nh_.createWallTimer(ros::WallDuration(2.0), [this](const ros::WallTimerEvent&) {
      teammates_->discover();
    });
  }

  // --- the move_base interface
  cmd_vel_pub_ = nh_.advertise<geometry_msgs::Twist>("cmd_vel", 1);
  global_plan_pub_ = private_nh_.advertise<nav_msgs::Path>("global_plan", 1, true);
  local_plan_pub_ = private_nh_.advertise<nav_msgs::Path>("local_plan", 1);
  action_goal_pub_ = nh_.advertise<move_base_msgs::MoveBaseActionGoal>("move_base/goal", 1);
  simple_goal_sub_ = nh_.subscribe("move_base_simple/goal", 1, &NavNode::onSimpleGoal, this);
  odom_sub_ = nh_.subscribe("odom", 1, &NavNode::onOdom, this);
  make_plan_srv_ = private_nh_.advertiseService("make_plan", &NavNode::onMakePlan, this);
  clear_costmaps_srv_ = private_nh_.advertiseService("clear_costmaps", &NavNode::onClearCostmaps, this);
  server_ = std::make_unique<ActionServer>(nh_, "move_base", false);
  server_->registerGoalCallback([this]() { onGoal(); });
  server_->registerPreemptCallback([this]() { onPreempt(); });
  control_period_ = 1.0 / controller_frequency;
  cycle_timer_ = nh_.createTimer(ros::Duration(control_period_), &NavNode::cycle, this);

  ROS_INFO("%s: robot '%s' (model %s, radius %.2f m), global planner %s, DWA at %.0f Hz, frames %s -> %s; "
           "waiting for the map and the robot's pose",
           private_nh_.getNamespace().c_str(), robot_.c_str(), own_model_.c_str(), own_radius_,
           global_planner_name.c_str(), controller_frequency, global_frame_.c_str(), robot_base_frame_.c_str());
}

double NavNode::teammateRadius(const std::string& name)
{
  // The simulator lists its robots' models in /stage/robots ([{name, model}]); else assume ours.
  std::string model = own_model_;
  XmlRpc::XmlRpcValue list;
  if (ros::param::getCached("/stage/robots", list) && list.getType() == XmlRpc::XmlRpcValue::TypeArray)
    for (int i = 0; i < list.size(); ++i)
      if (list[i].getType() == XmlRpc::XmlRpcValue::TypeStruct && list[i].hasMember("name") &&
          list[i].hasMember("model") && static_cast<std::string>(list[i]["name"]) == name)
        model = static_cast<std::string>(list[i]["model"]);
  auto it = model_radius_.find(model);
  if (it != model_radius_.end()) return it->second;
  double radius = own_radius_;
  try
  {
    radius = mbot_description::loadRobotModel(description_dir_, model).footprint_radius;
  }
  catch (const std::exception& e)
  {
    ROS_WARN("teammate %s: cannot load model '%s' (%s); assuming radius %.2f m", name.c_str(), model.c_str(),
             e.what(), radius);
  }
  model_radius_[model] = radius;
  return radius;
}

// =============================================================================================
// NavNode: the control cycle

bool NavNode::robotPose(Pose2D& pose, std::string& error) const
{
  // Under load this node's tf listener can fall behind /clock. Wait a little for the pose of one
  // control period ago rather than steer on an older one: at most one period of sim time, and at
  // most 0.1 s wall, because with stage_node's lockstep sim time stands still until this node sends
  // cmd_vel. (tf2's canTransform(timeout) would sleep in sim time, i.e. until the lockstep gives up.)
  const ros::Time start = ros::Time::now();
  const ros::Time wanted = start - ros::Duration(control_period_);
  const ros::WallTime wall_deadline = ros::WallTime::now() + ros::WallDuration(0.1);
  while (wanted.toSec() > 0.0 && !tf_->canTransform(global_frame_, robot_base_frame_, wanted) &&
         (ros::Time::now() - start).toSec() < control_period_ && ros::WallTime::now() < wall_deadline && ros::ok())
    ros::WallDuration(0.0005).sleep();
  geometry_msgs::TransformStamped t;
  try
  {
    t = tf_->lookupTransform(global_frame_, robot_base_frame_, ros::Time(0));
  }
  catch (const tf2::TransformException& e)
  {
    error = e.what();
    return false;
  }
  // The latest transform may be old when the localization or the simulator stopped.
  const double age = (ros::Time::now() - t.header.stamp).toSec();
  if (age > transform_tolerance_)
  {
    error = "the latest " + global_frame_ + " -> " + robot_base_frame_ + " transform is " + std::to_string(age) +
            " s old (transform_tolerance " + std::to_string(transform_tolerance_) + " s)";
    return false;
  }
  pose = mbot_common::toPose2D(t.transform);
  return true;
}

void NavNode::cycle(const ros::TimerEvent&)
{
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;  // no /clock yet

  Pose2D pose;
  std::string pose_error;
  const bool has_pose = robotPose(pose, pose_error);
  if (has_pose)
  {
    last_pose_time_ = now;
    const std::vector<TeammateState> mates = teammates_->states(now);
    for (CostmapRos* costmap : {global_costmap_.get(), local_costmap_.get()})
    {
      costmap->setTeammates(mates);
      if (costmap->updateDue(now) && costmap->ready()) costmap->update(pose, now);
      costmap->publishIfDue(now);
    }
  }
  if (global_costmap_->mapCount() != goal_checker_map_count_)
  {
    goal_checker_.setCostmap(global_costmap_->staticCostmap());
    goal_checker_map_count_ = global_costmap_->mapCount();
  }

  if (!server_started_)
  {
    if (!global_costmap_->ready() || !local_costmap_->ready() || !has_pose)
    {
      const std::string what = !global_costmap_->ready() ? "the map" : "the robot's pose (" + pose_error + ")";
      ROS_INFO_THROTTLE(10.0, "%s: waiting for %s", private_nh_.getNamespace().c_str(), what.c_str());
      return;
    }
    server_->start();
    server_started_ = true;
    ROS_INFO("%s: ready: action server %s started", private_nh_.getNamespace().c_str(),
             nh_.resolveName("move_base").c_str());
  }

  if (navigator_->state() == NavState::IDLE)
  {
    if (was_active_) publishZero();
    was_active_ = false;
    return;
  }
  was_active_ = true;
  if (!has_pose)
  {
    // Without a pose there is nothing safe to command; give tf controller_patience to come back.
    publishZero();
    ROS_WARN_THROTTLE(2.0, "%s: no robot pose: %s", private_nh_.getNamespace().c_str(), pose_error.c_str());
    if ((now - last_pose_time_).toSec() > controller_patience_)
    {
      navigator_->cancel();
      server_->setAborted(move_base_msgs::MoveBaseResult(),
                          "no robot pose from tf (" + global_frame_ + " -> " + robot_base_frame_ + ") for " +
                              std::to_string(static_cast<int>(controller_patience_)) + " s: " + pose_error);
    }
    return;
  }

  const NavState before = navigator_->state();
  const NavCycleResult result =
      navigator_->cycle(now.toSec(), pose, velocity_, global_costmap_->costmap(), local_costmap_->costmap());
  if (navigator_->state() != before)
    ROS_DEBUG("%s: %s -> %s%s%s", private_nh_.getNamespace().c_str(), toString(before), toString(navigator_->state()),
              navigator_->lastError().empty() ? "" : "; last error: ", navigator_->lastError().c_str());

  geometry_msgs::Twist cmd;
  cmd.linear.x = result.cmd.vx;
  cmd.linear.y = result.cmd.vy;
  cmd.angular.z = result.cmd.wz;
  cmd_vel_pub_.publish(cmd);
  if (result.plan_updated) publishPath(global_plan_pub_, navigator_->globalPlan(), now);
  publishPath(local_plan_pub_, navigator_->localPlan().poses, now);

  switch (result.outcome)
  {
    case NavOutcome::SUCCEEDED:
      ROS_INFO("%s: goal reached", private_nh_.getNamespace().c_str());
      server_->setSucceeded(move_base_msgs::MoveBaseResult(), "goal reached");
      break;
    case NavOutcome::ABORTED:
      ROS_WARN("%s: goal aborted: %s", private_nh_.getNamespace().c_str(), result.text.c_str());
      server_->setAborted(move_base_msgs::MoveBaseResult(), result.text);
      break;
    case NavOutcome::ACTIVE:
    {
      move_base_msgs::MoveBaseFeedback feedback;
      feedback.base_position = toPoseStamped(pose, global_frame_, now);
      server_->publishFeedback(feedback);
      break;
    }
    case NavOutcome::NONE: break;
  }
}

void NavNode::publishZero()
{
  cmd_vel_pub_.publish(geometry_msgs::Twist());
}

void NavNode::publishPath(const ros::Publisher& pub, const std::vector<Pose2D>& path, const ros::Time& stamp) const
{
  nav_msgs::Path msg;
  msg.header.frame_id = global_frame_;
  msg.header.stamp = stamp;
  msg.poses.reserve(path.size());
  for (const Pose2D& p : path) msg.poses.push_back(toPoseStamped(p, global_frame_, stamp));
  pub.publish(msg);
}

void NavNode::onOdom(const nav_msgs::Odometry::ConstPtr& odom)
{
  velocity_.vx = odom->twist.twist.linear.x;
  velocity_.vy = odom->twist.twist.linear.y;
  velocity_.wz = odom->twist.twist.angular.z;
}

// =============================================================================================
// NavNode: goals

std::string NavNode::goalToGlobalFrame(const geometry_msgs::PoseStamped& goal, Pose2D& out) const
{
  const std::string& frame = goal.header.frame_id;
  if (frame.empty()) return "goal frame is empty (expected a tf frame such as '" + global_frame_ + "')";
  if (frame == global_frame_)
  {
    out = mbot_common::toPose2D(goal.pose);
    return "";
  }
  if (!tf_->_frameExists(frame)) return "goal frame '" + frame + "' is unknown to tf";
  // As move_base: the goal is where the frame is now (latest transform), whatever its stamp.
  geometry_msgs::PoseStamped in = goal, transformed;
  in.header.stamp = ros::Time(0);
  try
  {
    tf_->transform(in, transformed, global_frame_, ros::Duration(0.5));
  }
  catch (const tf2::TransformException& e)
  {
    return "goal frame '" + frame + "' cannot be transformed to '" + global_frame_ + "': " + e.what();
  }
  out = mbot_common::toPose2D(transformed.pose);
  return "";
}

std::string NavNode::checkGoal(const geometry_msgs::PoseStamped& goal, Pose2D& out)
{
  GoalValues values;
  values.x = goal.pose.position.x;
  values.y = goal.pose.position.y;
  values.z = goal.pose.position.z;
  values.qx = goal.pose.orientation.x;
  values.qy = goal.pose.orientation.y;
  values.qz = goal.pose.orientation.z;
  values.qw = goal.pose.orientation.w;
  std::string error = checkGoalValues(values);
  if (error.empty()) error = goalToGlobalFrame(goal, out);
  if (!error.empty()) return error;
  Pose2D robot;
  std::string pose_error;
  const bool has_pose = robotPose(robot, pose_error);
  return goal_checker_.check(has_pose ? &robot : nullptr, out);
}

void NavNode::onGoal()
{
  const move_base_msgs::MoveBaseGoal::ConstPtr goal = server_->acceptNewGoal();
  if (!goal) return;
  Pose2D target;
  const std::string error = checkGoal(goal->target_pose, target);
  if (!error.empty())
  {
    navigator_->cancel();
    publishZero();
    ROS_WARN("%s: goal rejected: %s", private_nh_.getNamespace().c_str(), error.c_str());
    server_->setAborted(move_base_msgs::MoveBaseResult(), error);
    return;
  }
  ROS_INFO("%s: new goal (%.2f, %.2f, %.2f rad) in %s", private_nh_.getNamespace().c_str(), target.x, target.y,
           target.theta, global_frame_.c_str());
  const ros::Time now = ros::Time::now();
  navigator_->setGoal(target, now.toSec());
  last_pose_time_ = std::max(last_pose_time_, now);  // a missing pose counts from the goal's start
}

void NavNode::onPreempt()
{
  // Called for a cancel and before a new goal replaces the current one (then onGoal follows).
  if (!server_->isActive()) return;
  navigator_->cancel();
  publishZero();
  server_->setPreempted(move_base_msgs::MoveBaseResult(), "preempted");
  ROS_INFO("%s: goal preempted", private_nh_.getNamespace().c_str());
}

void NavNode::onSimpleGoal(const geometry_msgs::PoseStamped::ConstPtr& goal)
{
  // As move_base: send it on as an action goal, so that it preempts like any other.
  move_base_msgs::MoveBaseActionGoal action_goal;
  action_goal.header.stamp = ros::Time::now();
  action_goal.goal.target_pose = *goal;
  action_goal_pub_.publish(action_goal);
}

// =============================================================================================
// NavNode: services

bool NavNode::onMakePlan(nav_msgs::GetPlan::Request& req, nav_msgs::GetPlan::Response& res)
{
  res.plan.header.frame_id = global_frame_;
  res.plan.header.stamp = ros::Time::now();
  if (!global_costmap_->ready())
  {
    ROS_WARN("%s: make_plan: no map yet", private_nh_.getNamespace().c_str());
    return true;
  }
  Pose2D start, goal;
  std::string error;
  if (req.start.header.frame_id.empty())
  {
    if (!robotPose(start, error)) error = "no robot pose: " + error;
  }
  else
    error = goalToGlobalFrame(req.start, start);
  if (error.empty()) error = goalToGlobalFrame(req.goal, goal);
  if (!error.empty())
  {
    ROS_WARN("%s: make_plan: %s", private_nh_.getNamespace().c_str(), error.c_str());
    return true;  // as move_base: an empty plan
  }
  PlanResult plan = navigator_->makePlan(global_costmap_->costmap(), start, goal);
  if (!plan.ok && req.tolerance > 0.0)
  {
    // As move_base: try goals around the requested one, nearest first, within `tolerance`.
    const Costmap2D& cm = global_costmap_->costmap();
    const double res_m = cm.resolution();
    for (double r = res_m; r <= req.tolerance + 1e-9 && !plan.ok; r += res_m)
      for (int k = 0; k < 16 && !plan.ok; ++k)
      {
        Pose2D g = goal;
        g.x += r * std::cos(k * M_PI / 8.0);
        g.y += r * std::sin(k * M_PI / 8.0);
        unsigned mx, my;
        if (!cm.worldToMap(g.x, g.y, mx, my) || cm.cost(mx, my) >= cost::INSCRIBED) continue;
        plan = navigator_->makePlan(cm, start, g);
      }
  }
  if (!plan.ok)
  {
    ROS_WARN("%s: make_plan: %s", private_nh_.getNamespace().c_str(), plan.error.c_str());
    return true;
  }
  for (const Pose2D& p : plan.path) res.plan.poses.push_back(toPoseStamped(p, global_frame_, res.plan.header.stamp));
  return true;
}

bool NavNode::onClearCostmaps(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  global_costmap_->clear();
  local_costmap_->clear();
  ROS_INFO("%s: costmaps cleared", private_nh_.getNamespace().c_str());
  return true;
}

}  // namespace mbot_navigation
