#include "mbot_navigation/ros/nav_node.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <ros/package.h>
#include <tf2/exceptions.h>
#include <tf2/utils.h>
#include <tf2_geometry_msgs/tf2_geometry_msgs.h>

#include <mbot_common/ros_edge.h>
#include "mbot_navigation/ros/move_base_params.h"
#include "mbot_navigation/ros/shared_tf.h"
#include "mbot_navigation/global_planner/goal_tolerance.h"
#include "mbot_navigation/global_planner/planner_factory.h"
#include "mbot_navigation/local_planner/dwa_planner.h"

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

GoalValues goalValues(const geometry_msgs::Pose& p)
{
  GoalValues v;
  v.x = p.position.x;
  v.y = p.position.y;
  v.z = p.position.z;
  v.qx = p.orientation.x;
  v.qy = p.orientation.y;
  v.qz = p.orientation.z;
  v.qw = p.orientation.w;
  return v;
}
}  // namespace

// =============================================================================================
// NavNode: set-up

NavNode::NavNode(ros::NodeHandle nh, ros::NodeHandle private_nh) : nh_(nh), private_nh_(private_nh)
{
  const std::string description_dir = ros::package::getPath("mbot_description");
  if (description_dir.empty()) throw std::runtime_error("cannot find the package mbot_description (robot models)");
  ParamReport report;
  const NavParams params = readNavParams(nh_, private_nh_, description_dir, report);
  for (const std::string& note : report.notes) ROS_INFO("%s", note.c_str());
  for (const std::string& w : report.warnings) ROS_WARN("%s", w.c_str());
  robot_ = params.robot;
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
  tf_ = SharedTf::buffer();
  tf_listener_ = SharedTf::listen();
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
  dwa_config_ = dwa;
  navigator_ = std::make_unique<Navigator>(params.nav, std::make_unique<DwaPlanner>(dwa), std::move(global_planner),
                                           std::move(recoveries));

  teammates_ = std::make_unique<TeammateTracker>(
      nh_, *tf_, robot_, global_frame_,
      params.robots_source == "odom" ? TeammateTracker::Source::ODOM : TeammateTracker::Source::GROUND_TRUTH,
      params.robots, params.robots_timeout, TeammateRadii(description_dir, params.model, params.footprint_radius));
  if (params.robots.empty())
  {
    // Cheap: a cached parameter (the master is asked only without the simulator; discover()).
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
  odom_topic_ = params.odom_topic;
  odom_sub_ = nh_.subscribe(odom_topic_, 1, &NavNode::onOdom, this, ros::TransportHints().tcpNoDelay());
  make_plan_srv_ = private_nh_.advertiseService("make_plan", &NavNode::onMakePlan, this);
  clear_costmaps_srv_ = private_nh_.advertiseService("clear_costmaps", &NavNode::onClearCostmaps, this);
  server_ = std::make_unique<ActionServer>(nh_, "move_base", false);
  // No goal callback: the control cycle accepts new goals (see nav_node.h).
  server_->registerPreemptCallback([this]() { onPreempt(); });
  control_period_ = 1.0 / controller_frequency;
  shutdown_costmaps_ = params.shutdown_costmaps;
  cycle_timer_ = nh_.createTimer(ros::Duration(control_period_), &NavNode::cycle, this);
  startReconfigureServers();

  ROS_INFO(
      "%s: robot '%s' (model %s, radius %.2f m), global planner %s, DWA at %.0f Hz, frames %s -> %s%s; "
      "waiting for the map and the robot's pose",
      private_nh_.getNamespace().c_str(), robot_.c_str(), params.model.c_str(), params.footprint_radius,
      global_planner_name.c_str(), controller_frequency, global_frame_.c_str(), robot_base_frame_.c_str(),
      shutdown_costmaps_ ? ", costmaps shut down while idle" : "");
}

// =============================================================================================
// NavNode: the control cycle

bool NavNode::robotPose(Pose2D& pose, std::string& error, ros::Time* stamp, bool wait) const
{
  // Under load this node's tf listener can fall behind /clock. Wait a little for a pose at most two
  // control periods old rather than steer on an older one: at most one period of sim time, and at
  // most 0.1 s wall, because with stage_node's lockstep sim time stands still until this node sends
  // cmd_vel. (tf2's canTransform(timeout) would sleep in sim time, i.e. until the lockstep gives up.)
  // Two periods, not one: on a loaded machine the listener's thread often takes 10-35 ms to get a
  // core, and waiting for the pose of one period ago made this node the last to answer the lockstep.
  const ros::Time start = ros::Time::now();
  const ros::Time wanted = start - ros::Duration(2.0 * control_period_);
  const ros::WallTime wall_deadline = ros::WallTime::now() + ros::WallDuration(0.1);
  while (wait && wanted.toSec() > 0.0 && !tf_->canTransform(global_frame_, robot_base_frame_, wanted) &&
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
  if (global_costmap_->mapCount() != goal_checker_map_count_)
  {
    goal_checker_.setCostmap(global_costmap_->staticCostmap());
    goal_checker_map_count_ = global_costmap_->mapCount();
  }
  if (asleep_)
  {
    if (!server_->isNewGoalAvailable()) return;
    acceptGoal(false);  // a goal that is bad without tf is rejected at once, and the node sleeps on
    if (!has_pending_goal_) return;
    publishZero();  // as move_base at a new goal; under lockstep, sim time now waits for this node
    wake();
  }

  // Only a robot about to steer waits for a fresh pose (a woken one: for tf to come back); an idle
  // one takes the latest.
  const bool steering =
      navigator_->state() != NavState::IDLE || has_pending_goal_ || (server_started_ && server_->isNewGoalAvailable());
  Pose2D pose;
  std::string pose_error;
  ros::Time pose_stamp;
  const bool has_pose = robotPose(pose, pose_error, &pose_stamp, steering);
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

  if (server_->isNewGoalAvailable())
    acceptGoal(readyForGoal(has_pose));
  else if (has_pending_goal_ && readyForGoal(has_pose))
  {
    ROS_INFO("%s: woken for a goal %.2f s ago (wall): %s", private_nh_.getNamespace().c_str(),
             (ros::WallTime::now() - woken_at_).toSec(), has_pose ? "robot pose known" : "no robot pose yet");
    startPendingGoal();
  }
  if (has_pending_goal_)
  {
    publishZero();  // woken for it, waiting for tf
    was_active_ = true;
    return;
  }

  if (navigator_->state() == NavState::IDLE)
  {
    if (was_active_) publishZero();
    was_active_ = false;
    if (shutdown_costmaps_ && !server_->isNewGoalAvailable()) sleep();
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
  if (result.plan_updated) publishPath(global_plan_pub_, navigator_->globalPlan(), now);  // latched: always
  if (local_plan_pub_.getNumSubscribers() > 0) publishPath(local_plan_pub_, navigator_->localPlan().poses, now);

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

// =============================================================================================
// NavNode: sleeping while idle (shutdown_costmaps)

void NavNode::sleep()
{
  global_costmap_->stop();
  local_costmap_->stop();
  teammates_->stop();
  discovery_timer_.stop();
  odom_sub_.shutdown();
  tf_listener_.reset();  // the last one in the process stops the listener (shared_tf.h)
  asleep_ = true;
  ROS_DEBUG("%s: no goal: costmaps shut down", private_nh_.getNamespace().c_str());
}

void NavNode::wake()
{
  if (!asleep_) return;
  tf_listener_ = SharedTf::listen();
  odom_sub_ = nh_.subscribe(odom_topic_, 1, &NavNode::onOdom, this, ros::TransportHints().tcpNoDelay());
  velocity_ = Twist2D();  // until the odometry comes
  teammates_->start();
  if (discovery_timer_.isValid())
  {
    teammates_->discover();
    discovery_timer_.start();
  }
  global_costmap_->start();
  local_costmap_->start();
  woken_at_ = ros::WallTime::now();
  asleep_ = false;
  ROS_DEBUG("%s: costmaps started", private_nh_.getNamespace().c_str());
}

bool NavNode::readyForGoal(bool has_pose) const
{
  // Never woken (always awake): long ago.
  return has_pose || (ros::WallTime::now() - woken_at_).toSec() >= kWakeTimeout;
}

// =============================================================================================
// NavNode: live tuning

void NavNode::startReconfigureServers()
{
  // Each server starts with the values in force (not the .cfg defaults): updateConfig() before
  // setCallback(), whose first call then applies the same values.
  dwa_server_ = std::make_unique<dynamic_reconfigure::Server<DWAPlannerConfig>>(
      reconfigure_mutex_, ros::NodeHandle(private_nh_, "DWAPlannerROS"));
  DWAPlannerConfig c = toReconfigure(dwa_config_);
  dwa_server_->updateConfig(c);
  dwa_server_->setCallback([this](DWAPlannerConfig& config, uint32_t) { onDwaReconfigure(config); });

  for (CostmapRos* costmap : {global_costmap_.get(), local_costmap_.get()})
  {
    if (!costmap->settings().inflation) continue;
    inflation_servers_.push_back(std::make_unique<dynamic_reconfigure::Server<InflationConfig>>(
        reconfigure_mutex_,
        ros::NodeHandle(private_nh_, costmap->name() + "/" + costmap->settings().inflation_layer_name)));
    InflationConfig ic = toReconfigure(costmap->settings().inflation_layer);
    inflation_servers_.back()->updateConfig(ic);
    inflation_servers_.back()->setCallback(
        [this, costmap](InflationConfig& config, uint32_t) { onInflationReconfigure(*costmap, config); });
  }
}

void NavNode::onDwaReconfigure(DWAPlannerConfig& c)
{
  const DwaConfig d = fromReconfigure(c, dwa_config_);  // keeps the footprint and the control rate
  try
  {
    navigator_->setLocalPlanner(std::make_unique<DwaPlanner>(d));  // DwaPlanner validates
    dwa_config_ = d;
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
  const InflationLayerConfig config = fromReconfigure(c);
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
  std::string error = checkGoalValues(goalValues(goal.pose));
  if (error.empty()) error = goalToGlobalFrame(goal, out);
  if (!error.empty()) return error;
  Pose2D robot;
  std::string pose_error;
  const bool has_pose = robotPose(robot, pose_error);
  return goal_checker_.check(has_pose ? &robot : nullptr, out);
}

void NavNode::acceptGoal(bool ready)
{
  const move_base_msgs::MoveBaseGoal::ConstPtr goal = server_->acceptNewGoal();
  if (!goal) return;
  has_pending_goal_ = false;
  if (server_->isPreemptRequested())
  {
    // Cancelled before this cycle accepted it: the preempt callback only fires for an accepted
    // goal, so without this check the robot drove to a goal its client had already cancelled.
    navigator_->cancel();
    publishZero();
    server_->setPreempted(move_base_msgs::MoveBaseResult(), "cancelled before it was accepted");
    ROS_INFO("%s: goal cancelled before it was accepted", private_nh_.getNamespace().c_str());
    return;
  }
  pending_goal_ = goal->target_pose;
  has_pending_goal_ = true;
  if (ready)
  {
    startPendingGoal();
    return;
  }
  // Just woken, tf is not back yet: reject now what needs no tf.
  std::string error = checkGoalValues(goalValues(pending_goal_.pose));
  if (error.empty() && pending_goal_.header.frame_id == global_frame_)
    error = goal_checker_.check(nullptr, mbot_common::toPose2D(pending_goal_.pose));
  if (!error.empty()) rejectGoal(error);
}

void NavNode::startPendingGoal()
{
  has_pending_goal_ = false;
  Pose2D target;
  const std::string error = checkGoal(pending_goal_, target);
  if (!error.empty())
  {
    rejectGoal(error);
    return;
  }
  ROS_INFO("%s: new goal (%.2f, %.2f, %.2f rad) in %s", private_nh_.getNamespace().c_str(), target.x, target.y,
           target.theta, global_frame_.c_str());
  const ros::Time now = ros::Time::now();
  navigator_->setGoal(target, now.toSec());
  last_pose_time_ = std::max(last_pose_time_, now);  // a missing pose counts from the goal's start
}

void NavNode::rejectGoal(const std::string& error)
{
  has_pending_goal_ = false;
  navigator_->cancel();
  publishZero();
  ROS_WARN("%s: goal rejected: %s", private_nh_.getNamespace().c_str(), error.c_str());
  server_->setAborted(move_base_msgs::MoveBaseResult(), error);
}

void NavNode::onPreempt()
{
  // Called for a cancel and when a new goal arrives (the next cycle accepts it).
  if (!server_->isActive()) return;
  has_pending_goal_ = false;
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
  if (asleep_)
  {
    // As move_base, which plans on its stopped costmaps: wake for the call, plan on the map as it
    // stands at the robot's pose (tf's own thread fills the buffer meanwhile).
    wake();
    Pose2D robot;
    bool has_pose = false;
    const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(kWakeTimeout);
    while (!(has_pose = robotPose(robot, error, nullptr, false)) && ros::WallTime::now() < deadline && ros::ok())
      ros::WallDuration(0.01).sleep();
    if (has_pose) global_costmap_->update(robot, ros::Time::now());
    error.clear();
  }
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
  // As move_base: when the goal cannot be planned to, try goals around it within `tolerance`.
  const Costmap2D& costmap = global_costmap_->costmap();
  const PlanResult plan = planWithTolerance(costmap, goal, req.tolerance,
                                            [&](const Pose2D& g) { return navigator_->makePlan(costmap, start, g); });
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
