#include "mbot_navigation/ros/nav_node.h"

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
#include "mbot_navigation/ros/move_base_params.h"
#include "mbot_navigation/global_planner/planner_factory.h"

namespace mbot_navigation
{
using mbot_common::StrictParams;

namespace
{
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
    : tf_(tf),
      self_(self),
      global_frame_(global_frame),
      source_(source),
      timeout_(timeout),
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
  mate.sub = root.subscribe<nav_msgs::Odometry>(
      topic, 1, [this, name](const nav_msgs::Odometry::ConstPtr& msg) { mates_[name].last = msg; });
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

NavNode::NavNode(ros::NodeHandle nh, ros::NodeHandle private_nh) : nh_(nh), private_nh_(private_nh)
{
  description_dir_ = ros::package::getPath("mbot_description");
  if (description_dir_.empty()) throw std::runtime_error("cannot find the package mbot_description (robot models)");
  ParamWarnings warnings;
  const NavParams params = readNavParams(nh_, private_nh_, description_dir_, warnings);
  for (const std::string& w : warnings) ROS_WARN("%s", w.c_str());
  robot_ = params.robot;
  own_model_ = params.model;
  own_radius_ = params.footprint_radius;
  model_radius_[own_model_] = own_radius_;
  controller_patience_ = params.nav.controller_patience;
  const CostmapRosSettings& global_settings = params.global_costmap;
  const CostmapRosSettings& local_settings = params.local_costmap;
  global_frame_ = global_settings.global_frame;
  robot_base_frame_ = global_settings.robot_base_frame;
  transform_tolerance_ = global_settings.transform_tolerance;
  goal_checker_ = StaticGoalChecker(params.nav.allow_unknown);  // "unreachable" as the planner sees it
  const DwaConfig& dwa = params.dwa;
  const double controller_frequency = params.controller_frequency;
  const std::string& global_planner_name = params.global_planner;

  std::unique_ptr<GlobalPlanner> global_planner;
  try
  {
    global_planner = makeGlobalPlanner(global_planner_name, params.planners);
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
  if (params.clearing_rotation_allowed)
  {
    RotateRecoveryConfig rotate;
    rotate.max_vel_theta = std::min(1.0, dwa.max_vel_theta);
    rotate.min_vel_theta = std::min(dwa.min_vel_theta, rotate.max_vel_theta);
    rotate.acc_lim_theta = dwa.acc_lim_theta;
    rotate.control_period = 1.0 / controller_frequency;
    recoveries.push_back(std::make_unique<RotateRecovery>(rotate));
  }
  BackUpRecoveryConfig back_up = params.back_up;
  back_up.footprint_radius = local_settings.costmap.robot_radius;
  back_up.speed = std::min(back_up.speed, -params.model_min_vel_x);  // a robot that cannot reverse does not
  if (back_up.distance > 0.0 && back_up.speed > 0.0) recoveries.push_back(std::make_unique<BackUpRecovery>(back_up));
  navigator_ = std::make_unique<Navigator>(params.nav, dwa, std::move(global_planner), std::move(recoveries));

  teammates_ = std::make_unique<TeammateTracker>(
      *tf_, robot_, global_frame_,
      params.robots_source == "odom" ? TeammateTracker::Source::ODOM : TeammateTracker::Source::GROUND_TRUTH,
      params.robots, params.robots_timeout, [this](const std::string& name) { return teammateRadius(name); });
  if (params.robots.empty())
  {
    teammates_->discover();
    discovery_timer_ =
        nh_.createWallTimer(ros::WallDuration(2.0), [this](const ros::WallTimerEvent&) { teammates_->discover(); });
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
  // No goal callback: the control cycle accepts new goals (see nav_node.h).
  server_->registerPreemptCallback([this]() { onPreempt(); });
  control_period_ = 1.0 / controller_frequency;
  cycle_timer_ = nh_.createTimer(ros::Duration(control_period_), &NavNode::cycle, this);
  startReconfigureServers();

  ROS_INFO(
      "%s: robot '%s' (model %s, radius %.2f m), global planner %s, DWA at %.0f Hz, frames %s -> %s; "
      "waiting for the map and the robot's pose",
      private_nh_.getNamespace().c_str(), robot_.c_str(), own_model_.c_str(), own_radius_, global_planner_name.c_str(),
      controller_frequency, global_frame_.c_str(), robot_base_frame_.c_str());
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
    ROS_WARN("teammate %s: cannot load model '%s' (%s); assuming radius %.2f m", name.c_str(), model.c_str(), e.what(),
             radius);
  }
  model_radius_[model] = radius;
  return radius;
}

// =============================================================================================
// NavNode: the control cycle

bool NavNode::robotPose(Pose2D& pose, std::string& error, ros::Time* stamp) const
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
  if (stamp) *stamp = t.header.stamp;
  return true;
}

void NavNode::cycle(const ros::TimerEvent&)
{
  const ros::Time now = ros::Time::now();
  if (now.isZero()) return;  // no /clock yet

  Pose2D pose;
  std::string pose_error;
  ros::Time pose_stamp;
  const bool has_pose = robotPose(pose, pose_error, &pose_stamp);
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

  if (server_->isNewGoalAvailable()) acceptGoal();

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
      feedback.base_position = toPoseStamped(pose, global_frame_, pose_stamp);  // as move_base: tf's stamp
      server_->publishFeedback(feedback);
      break;
    }
    case NavOutcome::NONE: break;
  }
}

void NavNode::startReconfigureServers()
{
  // Each server starts with the values in force (not the .cfg defaults): updateConfig() before
  // setCallback(), whose first call then applies the same values.
  dwa_server_ = std::make_unique<dynamic_reconfigure::Server<DWAPlannerConfig>>(
      reconfigure_mutex_, ros::NodeHandle(private_nh_, "DWAPlannerROS"));
  const DwaConfig& d = navigator_->localPlanner().config();
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
  dwa_server_->updateConfig(c);
  dwa_server_->setCallback([this](DWAPlannerConfig& config, uint32_t) { onDwaReconfigure(config); });

  for (CostmapRos* costmap : {global_costmap_.get(), local_costmap_.get()})
  {
    if (!costmap->settings().inflation) continue;
    const InflationLayerConfig& i = costmap->settings().inflation_layer;
    inflation_servers_.push_back(std::make_unique<dynamic_reconfigure::Server<InflationConfig>>(
        reconfigure_mutex_,
        ros::NodeHandle(private_nh_, costmap->name() + "/" + costmap->settings().inflation_layer_name)));
    InflationConfig ic;
    ic.inflation_radius = i.inflation_radius;
    ic.cost_scaling_factor = i.cost_scaling_factor;
    ic.inflate_unknown = i.inflate_unknown;
    inflation_servers_.back()->updateConfig(ic);
    inflation_servers_.back()->setCallback(
        [this, costmap](InflationConfig& config, uint32_t) { onInflationReconfigure(*costmap, config); });
  }
}

void NavNode::onDwaReconfigure(DWAPlannerConfig& c)
{
  DwaConfig d = navigator_->localPlanner().config();  // keeps the footprint and the control rate
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
  try
  {
    navigator_->setLocalPlannerConfig(d);
    ROS_INFO("%s/DWAPlannerROS: new settings (max_vel_x %.2f m/s, max_vel_theta %.2f rad/s, sim_time %.2f s)",
             private_nh_.getNamespace().c_str(), d.max_vel_x, d.max_vel_theta, d.sim_time);
  }
  catch (const std::invalid_argument& e)
  {
    ROS_ERROR("%s/DWAPlannerROS: settings refused, the previous ones stay: %s", private_nh_.getNamespace().c_str(),
              e.what());
  }
}

void NavNode::onInflationReconfigure(CostmapRos& costmap, InflationConfig& c)
{
  InflationLayerConfig config;
  config.inflation_radius = c.inflation_radius;
  config.cost_scaling_factor = c.cost_scaling_factor;
  config.inflate_unknown = c.inflate_unknown;
  try
  {
    costmap.setInflation(config);
    if (&costmap == global_costmap_.get()) goal_checker_map_count_ = 0;  // the goal checks inflate as it does
    ROS_INFO("%s/%s: inflation_radius %.2f m, cost_scaling_factor %.1f", private_nh_.getNamespace().c_str(),
             costmap.name().c_str(), config.inflation_radius, config.cost_scaling_factor);
  }
  catch (const std::invalid_argument& e)
  {
    ROS_ERROR("%s/%s: inflation settings refused: %s", private_nh_.getNamespace().c_str(), costmap.name().c_str(),
              e.what());
  }
}

void NavNode::publishZero() { cmd_vel_pub_.publish(geometry_msgs::Twist()); }

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

void NavNode::acceptGoal()
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
  // Called for a cancel and when a new goal arrives (the next cycle accepts it).
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
