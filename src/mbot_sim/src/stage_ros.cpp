/**
 * @file stage_ros.cpp
 * @brief The ROS wrapper of World: parameters, construction, the robot list, markers, and the
 *        loop that owns sim time. See stage_ros.h; the rest of StageRos is in
 *        stage_ros_lockstep.cpp (lockstep), stage_ros_robot_io.cpp (per-robot topics) and
 *        stage_ros_services.cpp (services, live tuning).
 */
#include "mbot_sim/stage_ros.h"

#include "stage_ros_internal.h"

#include <mbot_common/paths.h>
#include <mbot_msgs/Contact.h>
#include <ros/callback_queue.h>
#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>
#include <visualization_msgs/MarkerArray.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <boost/make_shared.hpp>

#include <cmath>
#include <cstdio>
#include <fstream>

namespace mbot_sim
{
// =============================================================================================
// parameters

StageParams readStageParams(const ros::NodeHandle& pnh)
{
  StageParams p;
  if (!pnh.getParam("world", p.world) || p.world.empty())
    throw StartupError(pnh.resolveName("world") +
                       ": missing parameter: expected a world name (maps/NAME.world.yaml) or a world file path");
  pnh.param<std::string>("maps_dir", p.maps_dir, "");
  if (pnh.hasParam("real_time_factor"))
  {
    if (!pnh.getParam("real_time_factor", p.real_time_factor) || !(p.real_time_factor >= 0.0))
      throw StartupError(pnh.resolveName("real_time_factor") + ": expected a number >= 0 (0 = as fast as possible)");
    p.has_real_time_factor = true;
  }
  if (pnh.hasParam("seed"))
  {
    if (!pnh.getParam("seed", p.seed) || p.seed < 0)
      throw StartupError(pnh.resolveName("seed") + ": expected an integer >= 0");
    p.has_seed = true;
  }
  pnh.param("base_watchdog_timeout", p.watchdog_timeout, 0.2);
  if (!(p.watchdog_timeout > 0.0))
    throw StartupError(pnh.resolveName("base_watchdog_timeout") + ": expected a number > 0 [s]");
  pnh.param("marker_rate", p.marker_rate, 10.0);
  if (!(p.marker_rate > 0.0)) throw StartupError(pnh.resolveName("marker_rate") + ": expected a number > 0 [Hz]");
  pnh.param("clock_rate", p.clock_rate, 0.0);
  if (!(p.clock_rate >= 0.0))
    throw StartupError(pnh.resolveName("clock_rate") + ": expected a number >= 0 [Hz] (0: /clock after every step)");
  pnh.param("lockstep_report", p.lockstep_report, std::string());
  pnh.param("wheel_tf_rate", p.wheel_tf_rate, 10.0);
  if (!(p.wheel_tf_rate >= 0.0))
    throw StartupError(pnh.resolveName("wheel_tf_rate") + ": expected a number >= 0 [Hz] (0: no wheel transforms)");
  pnh.param("lockstep", p.lockstep, false);
  pnh.param("lockstep_period", p.lockstep_period, 0.05);
  if (!(p.lockstep_period > 0.0))
    throw StartupError(pnh.resolveName("lockstep_period") + ": expected a number > 0 [s]");
  pnh.param("lockstep_active_timeout", p.lockstep_active_timeout, 0.5);
  if (!(p.lockstep_active_timeout > 0.0))
    throw StartupError(pnh.resolveName("lockstep_active_timeout") + ": expected a number > 0 [s]");
  pnh.param("lockstep_wall_timeout", p.lockstep_wall_timeout, 2.0);
  if (!(p.lockstep_wall_timeout > 0.0))
    throw StartupError(pnh.resolveName("lockstep_wall_timeout") + ": expected a number > 0 [s]");
  pnh.param("lockstep_pacer_lag", p.lockstep_pacer_lag, 0.3);
  if (!(p.lockstep_pacer_lag > 0.0))
    throw StartupError(pnh.resolveName("lockstep_pacer_lag") + ": expected a number > 0 [s]");
  pnh.param("lockstep_localization_postdate", p.lockstep_localization_postdate, 0.1);
  if (!(p.lockstep_localization_postdate >= 0.0))
    throw StartupError(pnh.resolveName("lockstep_localization_postdate") + ": expected a number >= 0 [s]");
  pnh.param("lockstep_localization_lag", p.lockstep_localization_lag, 0.1);
  if (!(p.lockstep_localization_lag >= 0.0))
    throw StartupError(pnh.resolveName("lockstep_localization_lag") + ": expected a number >= 0 [s]");
  return p;
}

// =============================================================================================
// construction

StageRos::StageRos(const ros::NodeHandle& nh, const StageParams& params) : nh_(nh), params_(params)
{
  std::string path;
  try
  {
    // a name: maps_dir, then the workspace's maps/ (mbot_common::resolveWorldPath)
    path = mbot_common::resolveWorldPath(params.world, params.maps_dir);
  }
  catch (const mbot_common::ConfigError& e)
  {
    throw StartupError(e.what());
  }
  description_dir_ = ros::package::getPath("mbot_description");
  if (description_dir_.empty()) throw StartupError("cannot find the package mbot_description (for the robot models)");

  WorldConfig config;
  try
  {
    config = loadWorldConfig(path);
    if (params.has_seed) config.seed = static_cast<unsigned>(params.seed);
    world_ = buildWorld(
        config, [this](const std::string& name) { return model(name); }, params.watchdog_timeout);
  }
  catch (const WorldConfigError& e)
  {
    throw StartupError(e.what());
  }
  real_time_factor_ = params.has_real_time_factor ? params.real_time_factor : config.real_time_factor;

  clock_pub_ = nh_.advertise<rosgraph_msgs::Clock>("/clock", 10);
  contact_pub_ = nh_.advertise<mbot_msgs::Contact>("contacts", 100);
  marker_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("stage/markers", 1, true);
  applied_pub_ = nh_.advertise<mbot_msgs::AppliedCommands>("stage/applied_commands", 10);
  fleet_truth_pub_ = nh_.advertise<mbot_msgs::RobotStates>("stage/ground_truth", 100);
  fleet_truth_.header.frame_id = "map";
  tf_pub_ = nh_.advertise<tf2_msgs::TFMessage>("/tf", 100);  // as tf2_ros::TransformBroadcaster
  for (int id : world_->robotIds()) addRobotIo(id);
  publishRobotList();
  publishMarkers();

  services_.push_back(nh_.advertiseService("reset", &StageRos::onReset, this));
  services_.push_back(nh_.advertiseService("reset_positions", &StageRos::onReset, this));
  services_.push_back(nh_.advertiseService("pause_physics", &StageRos::onPause, this));
  services_.push_back(nh_.advertiseService("unpause_physics", &StageRos::onUnpause, this));
  services_.push_back(nh_.advertiseService("spawn_robot", &StageRos::onSpawn, this));
  services_.push_back(nh_.advertiseService("remove_robot", &StageRos::onRemove, this));
  services_.push_back(nh_.advertiseService("spawn_obstacle", &StageRos::onSpawnObstacle, this));
  services_.push_back(nh_.advertiseService("remove_obstacle", &StageRos::onRemoveObstacle, this));
  services_.push_back(nh_.advertiseService("teleport_robot", &StageRos::onTeleport, this));
  services_.push_back(nh_.advertiseService("set_fault", &StageRos::onSetFault, this));
  world_->setListener(this);
  if (params_.lockstep)  // only then: every /tf message costs this node a callback
  {
    tf_sub_ = nh_.subscribe("/tf", 1000, &StageRos::onTf, this, ros::TransportHints().tcpNoDelay());
    heartbeat_sub_ =
        nh_.subscribe("/lockstep/heartbeat", 100, &StageRos::onHeartbeat, this, ros::TransportHints().tcpNoDelay());
  }

  ROS_INFO(
      "stage_node: world %s: %zu robots, %zu obstacles, map walls as %zu boxes, physics step %.3f s, "
      "real-time factor %g%s, seed %u",
      path.c_str(), world_->robotCount(), world_->obstacles().size(), world_->wallBoxCount(), world_->physicsStep(),
      real_time_factor_, real_time_factor_ == 0.0 ? " (as fast as possible)" : "", config.seed);
  startReconfigureServer();
  if (params_.lockstep)
    ROS_INFO(
        "stage_node: lockstep: sim time waits for the driven robots' cmd_vel and localization every %g s "
        "sim time (driven: a cmd_vel within %g s sim time; localization lag up to %g s sim time; at most %g s "
        "wall per wait)",
        params_.lockstep_period, params_.lockstep_active_timeout, params_.lockstep_localization_lag,
        params_.lockstep_wall_timeout);
}

const mbot_description::RobotModel& StageRos::model(const std::string& name)
{
  auto it = models_.find(name);
  if (it == models_.end()) it = models_.emplace(name, mbot_description::loadRobotModel(description_dir_, name)).first;
  return it->second;
}

// =============================================================================================
// what stage_node tells about the world: the robot list, the markers

/// `/stage/robots`: [{name, model}, ...]. The robot_state_publishers helper starts one
/// robot_state_publisher per entry; tools can list the robots from it.
void StageRos::publishRobotList()
{
  XmlRpc::XmlRpcValue list;
  list.setSize(0);
  int i = 0;
  for (int id : world_->robotIds())
  {
    XmlRpc::XmlRpcValue entry;
    entry["name"] = world_->robotName(id);
    entry["model"] = world_->robotModel(id).name;
    list[i++] = entry;
  }
  nh_.setParam("stage/robots", list);
}

/// /stage/markers: obstacles (ns "obstacles", "moving_obstacles") and every robot as a disc of its
/// footprint radius with its name above it (ns "robots", "robot_names"), so that a fleet view
/// shows who is where even without each robot's RobotModel. The array starts with DELETEALL:
/// removed robots disappear, and rviz draws the array as one consistent picture.
void StageRos::publishMarkers()
{
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);
  int index = 0;
  for (const ObstacleState& o : world_->obstacles())
  {
    visualization_msgs::Marker m;
    m.header.frame_id = "map";
    m.header.stamp.fromSec(world_->time());
    m.ns = o.moving ? "moving_obstacles" : "obstacles";
    m.id = index++;
    m.action = visualization_msgs::Marker::ADD;
    const bool box = o.shape.type == ShapeConfig::Type::BOX;
    m.type = box ? visualization_msgs::Marker::CUBE : visualization_msgs::Marker::CYLINDER;
    m.pose.position.x = o.pose.x;
    m.pose.position.y = o.pose.y;
    m.pose.position.z = 0.25;
    m.pose.orientation = yawToQuaternion(o.pose.theta);
    m.scale.x = box ? o.shape.length : 2.0 * o.shape.radius;
    m.scale.y = box ? o.shape.width : 2.0 * o.shape.radius;
    m.scale.z = 0.5;
    m.color.r = o.moving ? 0.9f : 0.55f;
    m.color.g = o.moving ? 0.45f : 0.4f;
    m.color.b = o.moving ? 0.1f : 0.3f;
    m.color.a = 1.0f;
    m.text = o.name;
    array.markers.push_back(m);
  }
  for (int id : world_->robotIds())
  {
    const Pose2D pose = world_->groundTruth(id);
    const float hue = static_cast<float>(id % 6) / 6.0f;  // a stable colour per robot
    visualization_msgs::Marker m;
    m.header.frame_id = "map";
    m.header.stamp.fromSec(world_->time());
    m.ns = "robots";
    m.id = id;
    m.action = visualization_msgs::Marker::ADD;
    m.type = visualization_msgs::Marker::CYLINDER;
    m.pose.position.x = pose.x;
    m.pose.position.y = pose.y;
    m.pose.position.z = 0.05;
    m.pose.orientation.w = 1.0;
    m.scale.x = m.scale.y = 2.0 * world_->robotModel(id).footprint_radius;
    m.scale.z = 0.1;
    m.color.r = 0.5f + 0.5f * std::cos(2.0f * static_cast<float>(M_PI) * hue);
    m.color.g = 0.5f + 0.5f * std::cos(2.0f * static_cast<float>(M_PI) * (hue - 1.0f / 3.0f));
    m.color.b = 0.5f + 0.5f * std::cos(2.0f * static_cast<float>(M_PI) * (hue - 2.0f / 3.0f));
    m.color.a = 0.9f;
    array.markers.push_back(m);

    m.ns = "robot_names";
    m.type = visualization_msgs::Marker::TEXT_VIEW_FACING;
    m.pose.position.y += world_->robotModel(id).footprint_radius + 0.2;
    m.pose.position.z = 0.5;
    m.scale.x = m.scale.y = 0.0;
    m.scale.z = 0.3;  // text height [m]: a robot 1 m away keeps its name apart
    m.color.r = m.color.g = m.color.b = 1.0f;
    m.color.a = 1.0f;
    m.text = world_->robotName(id);
    array.markers.push_back(m);
  }
  marker_pub_.publish(array);
}

// =============================================================================================
// the loop

void StageRos::publishClock()
{
  rosgraph_msgs::Clock clock;
  clock.clock.fromSec(world_->time());
  clock_pub_.publish(clock);
}

/// Before a step: the cmd_vels that arrived since the step before are used from now on (the newest
/// of each robot; one replaced before any step was never applied and is not reported).
void StageRos::noteAppliedCommands()
{
  const ros::Time now = ros::Time().fromSec(world_->time());
  for (auto& io : io_)
  {
    if (!io || !io->cmd_pending) continue;
    io->cmd_pending = false;
    if (!report_applied_) continue;  // nobody listens: only the flag is kept current
    mbot_msgs::AppliedCommand c;
    c.robot = io->name;
    c.received.fromSec(io->cmd_received);
    c.applied = now;
    c.cmd = io->cmd_msg;
    applied_batch_.commands.push_back(c);
  }
}

/// After a step: every kAppliedCommandsPeriod of sim time, the commands applied since the last
/// message, stamped with the sim time now, also when there were none, so that a listener knows
/// how far the report goes (`since` to the stamp). Nothing is collected while nobody subscribes
/// (checked here, once per period); the report then starts again with a new `since`.
void StageRos::publishAppliedCommands()
{
  const double t = world_->time();
  const bool went_back = t + kAppliedCommandsPeriod < next_applied_time_ - 1e-9;
  if (t + 1e-9 < next_applied_time_ && !went_back) return;
  next_applied_time_ = (std::floor((t + 1e-9) / kAppliedCommandsPeriod) + 1.0) * kAppliedCommandsPeriod;
  if (report_applied_)
  {
    applied_batch_.header.stamp.fromSec(t);
    applied_pub_.publish(applied_batch_);
    applied_batch_.commands.clear();
    applied_batch_.since = applied_batch_.header.stamp;
  }
  const bool listening = applied_pub_.getNumSubscribers() > 0;
  if (listening && !report_applied_) applied_batch_.since.fromSec(t);  // complete from the next step on
  report_applied_ = listening;
}

void StageRos::run()
{
  ros::CallbackQueue& queue = *ros::getGlobalCallbackQueue();
  const ros::WallTime run_started = ros::WallTime::now();
  ros::WallTime anchor_wall = run_started;
  double anchor_sim = world_->time();
  next_boundary_ = (std::floor(world_->time() / params_.lockstep_period) + 1.0) * params_.lockstep_period;

  while (ros::ok())
  {
    queue.callAvailable(ros::WallDuration(0));
    if (paused_)
    {
      queue.callAvailable(ros::WallDuration(0.01));  // wait for unpause, without spinning hot
      pacing_reset_ = true;
      continue;
    }
    if (pacing_reset_)
    {
      anchor_wall = ros::WallTime::now();
      anchor_sim = world_->time();
      pacing_reset_ = false;
    }
    if (boundary_wait_pending_ && !waitForControllers()) continue;  // paused or shut down meanwhile

    noteAppliedCommands();
    world_->step();  // calls the on*() listeners, which publish
    if (!tf_batch_.empty())
    {
      // One message for all robots, published as a shared pointer: this node's own /tf subscriber
      // (lockstep) then gets it as it is, not serialized and deserialized again.
      auto tf = boost::make_shared<tf2_msgs::TFMessage>();
      tf->transforms.swap(tf_batch_);
      tf_batch_.reserve(tf->transforms.size());
      tf_pub_.publish(tf);
    }
    // The fleet's ground truth in one message: a node watching every robot (metrics collector,
    // scenario runner) takes one message per step instead of one per robot.
    if (!fleet_truth_.robots.empty())
    {
      fleet_truth_.header.stamp = fleet_truth_.robots.front().stamp;
      fleet_truth_pub_.publish(fleet_truth_);
      fleet_truth_.robots.clear();
    }
    report_fleet_truth_ = fleet_truth_pub_.getNumSubscribers() > 0;
    // Every node wakes for each /clock message (rospy handles each in Python): ~clock_rate below the
    // physics rate spares the fleet's nodes that work. A lockstep boundary always gets its /clock:
    // the controllers' timers fire on it, and sim time waits there for their commands.
    const double t = world_->time();
    const bool at_boundary = params_.lockstep && t + 1e-9 >= next_boundary_;
    const bool went_back = params_.clock_rate > 0.0 && t + 1.0 / params_.clock_rate < next_clock_time_ - 1e-9;  // reset
    if (params_.clock_rate <= 0.0 || at_boundary || went_back || t + 1e-9 >= next_clock_time_)
    {
      publishClock();
      if (params_.clock_rate > 0.0)
        next_clock_time_ = (std::floor((t + 1e-9) * params_.clock_rate) + 1.0) / params_.clock_rate;
    }
    if (params_.lockstep) noteBoundary();
    publishAppliedCommands();
    // Markers are for eyes: at ~marker_rate in sim time, at most 30 Hz wall, only while someone listens.
    if (world_->time() + 1e-9 >= next_marker_time_ && ros::WallTime::now() >= next_marker_wall_ &&
        marker_pub_.getNumSubscribers() > 0)
    {
      publishMarkers();
      next_marker_time_ = world_->time() + 1.0 / params_.marker_rate;
      next_marker_wall_ = ros::WallTime::now() + ros::WallDuration(1.0 / 30.0);
    }

    if (real_time_factor_ > 0.0)
    {
      const ros::WallTime due = anchor_wall + ros::WallDuration((world_->time() - anchor_sim) / real_time_factor_);
      const ros::WallTime now = ros::WallTime::now();
      if (due > now)
        (due - now).sleep();
      else if ((now - due).toSec() > 0.1)
        pacing_reset_ = true;  // too slow for this factor: go on from here, no catch-up burst
    }
  }
  if (params_.lockstep)  // for benchmarks: what the waits cost over the whole run
  {
    char head[160];
    std::snprintf(head, sizeof head, "stage_node: lockstep: %ld boundaries, %ld wall timeouts (%g s wall each); ",
                  boundary_count_, lockstep_timeouts_total_, params_.lockstep_wall_timeout);
    const std::string summary = head + lockstepWaitSummary((ros::WallTime::now() - run_started).toSec());
    ROS_INFO("%s", summary.c_str());
    if (!params_.lockstep_report.empty())  // the screen may be gone at shutdown: a file stays
    {
      std::ofstream report(params_.lockstep_report);
      report << summary << "\n";
      if (!report) ROS_ERROR("stage_node: ~lockstep_report: cannot write %s", params_.lockstep_report.c_str());
    }
  }
}

}  // namespace mbot_sim
