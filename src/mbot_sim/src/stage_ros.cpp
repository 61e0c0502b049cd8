/**
 * @file stage_ros.cpp
 * @brief The ROS wrapper of World: parameters, messages, services, sim time. See stage_ros.h.
 */
#include "mbot_sim/stage_ros.h"

#include <mbot_common/paths.h>
#include <mbot_msgs/Contact.h>
#include <ros/callback_queue.h>
#include <ros/package.h>
#include <rosgraph_msgs/Clock.h>
#include <visualization_msgs/MarkerArray.h>
#include <xmlrpcpp/XmlRpcValue.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <sstream>

namespace mbot_sim
{
namespace
{
geometry_msgs::Quaternion yawToQuaternion(double yaw)
{
  const std::array<double, 4> xyzw = mbot_common::quaternionFromYaw(yaw);
  geometry_msgs::Quaternion q;
  q.x = xyzw[0];
  q.y = xyzw[1];
  q.z = xyzw[2];
  q.w = xyzw[3];
  return q;
}

/// Fill pose and twist of an Odometry message.
void fillOdometry(nav_msgs::Odometry& msg, double stamp, const Pose2D& pose, const Twist2D& twist)
{
  msg.header.stamp.fromSec(stamp);
  msg.pose.pose.position.x = pose.x;
  msg.pose.pose.position.y = pose.y;
  msg.pose.pose.position.z = 0.0;
  msg.pose.pose.orientation = yawToQuaternion(pose.theta);
  msg.twist.twist.linear.x = twist.vx;
  msg.twist.twist.linear.y = twist.vy;
  msg.twist.twist.angular.z = twist.wz;
}

}  // namespace

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

void StageRos::addRobotIo(int id)
{
  auto io = std::make_unique<RobotIo>();
  io->name = world_->robotName(id);
  io->prefix = io->name + "/";
  const std::string ns = io->name + "/";
  // Queues of 100 (2 s at 50 Hz in real time): a subscriber that stalls briefly, or a fast
  // real-time factor, does not lose messages.
  io->odom = nh_.advertise<nav_msgs::Odometry>(ns + "odom", 100);
  io->ground_truth = nh_.advertise<nav_msgs::Odometry>(ns + "base_pose_ground_truth", 100);
  io->scan = nh_.advertise<sensor_msgs::LaserScan>(ns + "scan", 100);
  io->joint_states = nh_.advertise<sensor_msgs::JointState>(ns + "joint_states", 100);
  io->cmd_vel = nh_.subscribe<geometry_msgs::Twist>(
      ns + "cmd_vel", 1, [this, id](const geometry_msgs::Twist::ConstPtr& msg) { onCmdVel(id, msg); },
      ros::VoidConstPtr(), ros::TransportHints().tcpNoDelay());
  io->cmd_pose = nh_.subscribe<geometry_msgs::Pose>(
      ns + "cmd_pose", 1, [this, id](const geometry_msgs::Pose::ConstPtr& msg) { onCmdPose(id, msg); });

  // Message parts that never change, filled once.
  const mbot_description::RobotModel& m = world_->robotModel(id);
  io->odom_msg.header.frame_id = io->prefix + "odom";
  io->odom_msg.child_frame_id = io->prefix + "base_footprint";
  io->ground_truth_msg.header.frame_id = "map";
  io->ground_truth_msg.child_frame_id = io->prefix + "base_footprint";
  io->odom_tf.header.frame_id = io->odom_msg.header.frame_id;
  io->odom_tf.child_frame_id = io->odom_msg.child_frame_id;
  io->scan_msg.header.frame_id = io->prefix + "base_laser";
  io->scan_msg.angle_min = m.laser.min_angle;
  io->scan_msg.angle_increment = m.laser.angleIncrement();
  io->scan_msg.angle_max = m.laser.min_angle + m.laser.angleIncrement() * (m.laser.beams - 1);
  io->scan_msg.time_increment = 0.0;
  io->scan_msg.scan_time = 1.0 / m.laser.rate;
  io->scan_msg.range_min = m.laser.range_min;
  io->scan_msg.range_max = m.laser.range_max;
  for (const auto& joint : m.wheel_joints) io->joint_msg.name.push_back(io->prefix + joint);
  if (id >= static_cast<int>(io_.size())) io_.resize(id + 1);
  io_[id] = std::move(io);
}

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
// live tuning

void StageRos::startReconfigureServer()
{
  reconfigure_server_ =
      std::make_unique<dynamic_reconfigure::Server<SimulatorConfig>>(reconfigure_mutex_, ros::NodeHandle("~"));
  SimulatorConfig c;
  c.real_time_factor = real_time_factor_;
  c.laser_range = world_->noise().laser_range;
  c.odom_linear = world_->noise().odom_linear;
  c.odom_angular = world_->noise().odom_angular;
  // A value in force above the .cfg's maximum (the world file allows any) widens the maximum:
  // the server then shows it as it is and never clamps it when another setting changes.
  SimulatorConfig max = SimulatorConfig::__getMax__();
  max.real_time_factor = std::max(max.real_time_factor, c.real_time_factor);
  max.laser_range = std::max(max.laser_range, c.laser_range);
  max.odom_linear = std::max(max.odom_linear, c.odom_linear);
  max.odom_angular = std::max(max.odom_angular, c.odom_angular);
  reconfigure_server_->setConfigMax(max);
  reconfigure_server_->updateConfig(c);
  // setCallback() calls onReconfigure() at once with these values: it finds nothing to change.
  reconfigure_server_->setCallback([this](SimulatorConfig& config, uint32_t) { onReconfigure(config); });
}

/// In force from the next step. A refused value is written back to `c` as the value in force, so
/// the server reports what runs.
void StageRos::onReconfigure(SimulatorConfig& c)
{
  if (c.real_time_factor != real_time_factor_)
  {
    if (c.real_time_factor >= 0.0)  // NaN is not
    {
      real_time_factor_ = c.real_time_factor;
      pacing_reset_ = true;  // pace from the current sim time on: sim time neither jumps nor catches up
      ROS_INFO("stage_node: real-time factor %g%s from sim time %.3f s", real_time_factor_,
               real_time_factor_ == 0.0 ? " (as fast as possible)" : "", world_->time());
    }
    else
    {
      ROS_ERROR("stage_node: real_time_factor: expected a number >= 0 (0 = as fast as possible), got %g; it stays %g",
                c.real_time_factor, real_time_factor_);
      c.real_time_factor = real_time_factor_;
    }
  }
  const NoiseConfig& now = world_->noise();
  if (c.laser_range != now.laser_range || c.odom_linear != now.odom_linear || c.odom_angular != now.odom_angular)
  {
    try
    {
      world_->setNoise(NoiseConfig{c.laser_range, c.odom_linear, c.odom_angular});
      ROS_INFO("stage_node: noise: laser_range %g m, odom_linear %g m/s, odom_angular %g rad/s from sim time %.3f s",
               c.laser_range, c.odom_linear, c.odom_angular, world_->time());
    }
    catch (const SimError& e)
    {
      ROS_ERROR("stage_node: %s; the noise stays", e.what());
    }
    c.laser_range = world_->noise().laser_range;
    c.odom_linear = world_->noise().odom_linear;
    c.odom_angular = world_->noise().odom_angular;
  }
}

// =============================================================================================
// the loop

void StageRos::publishClock()
{
  rosgraph_msgs::Clock clock;
  clock.clock.fromSec(world_->time());
  clock_pub_.publish(clock);
}

/// Lockstep: after a step, note whether /clock just reached (or crossed) a period boundary.
void StageRos::noteBoundary()
{
  const double now = world_->time();
  if (now + 1e-9 < next_boundary_) return;
  ++boundary_count_;
  next_boundary_ = (std::floor((now + 1e-9) / params_.lockstep_period) + 1.0) * params_.lockstep_period;
  boundary_wait_pending_ = true;
}

/// Lockstep: before stepping past the boundary just published (number n), wait until every
/// driven robot has sent a cmd_vel that arrived after boundary n-1 was published and has not
/// released a boundary yet. "After n-1" (not "after n") lets a controller whose timer ticks between
/// two boundaries (any phase) answer in time, so at real-time factors the controller keeps up with
/// it rarely waits; "one cmd_vel, one boundary" keeps sim time at most one period (+ one physics
/// step) ahead of the controller's last cycle. Callbacks and services are served while waiting.
/// Every robot whose localization publishes map -> <ns>/odom on /tf (driven or not) is also waited
/// for until that transform is at most ~lockstep_localization_lag behind sim time: otherwise sim
/// time runs away from a localization that cannot keep up (between goals, when no robot is driven,
/// or when a controller answers at once with a stop, as move_base does without a fresh pose) and
/// the robot never gets a fresh pose again.
/// Nodes that must keep pace with sim time without driving a robot (the fleet coordinator, whose
/// loss detection counts sim seconds) send a heartbeat (std_msgs/Header: frame_id their name,
/// stamp their sim time) on /lockstep/heartbeat every cycle; each is waited for until its newest
/// heartbeat is at most ~lockstep_pacer_lag behind sim time.
/// After ~lockstep_wall_timeout the robots whose controller did not answer count as not driven
/// until their next cmd_vel, and a localization still behind is not waited for until it has caught
/// up by itself, so a dead controller or localization costs one timeout, not one per boundary.
/// A pacer is waited for as long as its heartbeat moves on within ~lockstep_wall_timeout: it is
/// alive, only slow (a metrics collector on a loaded machine), and ignoring it would leave it
/// behind for good, since sim time then runs away from it. A silent one is ignored likewise.
/// @return false when paused or shut down while waiting (the wait is still pending)
bool StageRos::waitForControllers()
{
  ros::CallbackQueue& queue = *ros::getGlobalCallbackQueue();
  const ros::WallTime deadline = ros::WallTime::now() + ros::WallDuration(params_.lockstep_wall_timeout);
  const auto driven = [this](const RobotIo& io) {
    return world_->time() - io.last_cmd_time <= params_.lockstep_active_timeout;
  };
  const auto answered = [this](const RobotIo& io) { return io.cmd_unused && io.cmd_boundary >= boundary_count_ - 1; };
  const auto localized = [this](const RobotIo& io) {
    return io.localization_ignored || io.localization_stamp < -1e8 ||  // none seen: nothing to wait for
           localizationCurrent(io);
  };
  const auto waitingFor = [&](const RobotIo& io) { return (driven(io) && !answered(io)) || !localized(io); };
  const auto paced = [this](const Pacer& p) {
    return p.ignored || p.stamp + params_.lockstep_pacer_lag >= world_->time() - 1e-9;
  };
  while (true)
  {
    if (!ros::ok() || paused_) return false;
    bool all_answered = true;
    for (const auto& io : io_)
      if (io && waitingFor(*io)) all_answered = false;
    for (const auto& p : pacers_)
      if (!paced(p.second)) all_answered = false;
    if (all_answered) break;
    const ros::WallTime wall_now = ros::WallTime::now();
    bool pacer_moving = false;
    for (const auto& p : pacers_)
      if (!paced(p.second) && (wall_now - p.second.moved).toSec() < params_.lockstep_wall_timeout) pacer_moving = true;
    if (wall_now >= deadline && !pacer_moving)
    {
      std::string late;
      for (auto& io : io_)
        if (io && waitingFor(*io))
        {
          if (driven(*io) && !answered(*io))
          {
            late += (late.empty() ? "" : ", ") + io->name + " (no cmd_vel)";
            io->last_cmd_time = -1e9;  // not driven until its next cmd_vel
          }
          if (!localized(*io))
          {
            late += (late.empty() ? "" : ", ") + io->name + " (localization " +
                    std::to_string(world_->time() - io->localization_stamp) + " s behind)";
            io->localization_ignored = true;
          }
        }
      for (auto& p : pacers_)
        if (!paced(p.second))
        {
          late += (late.empty() ? "" : ", ") + p.first + " (heartbeat " +
                  std::to_string(world_->time() - p.second.stamp) + " s behind)";
          p.second.ignored = true;
        }
      ++lockstep_timeouts_;
      if ((wall_now - last_lockstep_warning_).toSec() >= 5.0)  // throttled: a slow controller times out often
      {
        ROS_WARN(
            "stage_node: lockstep: waited for %s for %g s wall at sim time %.3f s: going on "
            "(%ld such timeouts since the last warning)",
            late.c_str(), params_.lockstep_wall_timeout, world_->time(), lockstep_timeouts_);
        last_lockstep_warning_ = wall_now;
        lockstep_timeouts_ = 0;
      }
      break;
    }
    queue.callAvailable(ros::WallDuration(0.001));  // sleeps until a callback is ready, at most 1 ms
  }
  for (auto& io : io_)  // each cmd_vel releases one boundary
    if (io && io->cmd_boundary >= boundary_count_ - 1) io->cmd_unused = false;
  boundary_wait_pending_ = false;
  return true;
}

void StageRos::run()
{
  ros::CallbackQueue& queue = *ros::getGlobalCallbackQueue();
  ros::WallTime anchor_wall = ros::WallTime::now();
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

    world_->step();  // calls the on*() listeners, which publish
    if (!tf_batch_.empty())
    {
      tf_broadcaster_.sendTransform(tf_batch_);
      tf_batch_.clear();
    }
    publishClock();
    if (params_.lockstep) noteBoundary();
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
}

// =============================================================================================
// sensor samples -> messages

void StageRos::onOdometry(int robot, const OdometrySample& s)
{
  RobotIo& io = *io_[robot];
  fillOdometry(io.odom_msg, s.stamp, s.pose, s.twist);
  io.odom.publish(io.odom_msg);
  io.odom_tf.header.stamp = io.odom_msg.header.stamp;
  io.odom_tf.transform.translation.x = s.pose.x;
  io.odom_tf.transform.translation.y = s.pose.y;
  io.odom_tf.transform.translation.z = 0.0;
  io.odom_tf.transform.rotation = io.odom_msg.pose.pose.orientation;
  tf_batch_.push_back(io.odom_tf);
}

void StageRos::onGroundTruth(int robot, const GroundTruthSample& s)
{
  RobotIo& io = *io_[robot];
  fillOdometry(io.ground_truth_msg, s.stamp, s.pose, s.twist);
  io.ground_truth.publish(io.ground_truth_msg);
}

void StageRos::onJointState(int robot, const JointStateSample& s)
{
  RobotIo& io = *io_[robot];
  io.joint_msg.header.stamp.fromSec(s.stamp);
  io.joint_msg.position = s.position;
  io.joint_msg.velocity = s.velocity;
  io.joint_states.publish(io.joint_msg);
}

void StageRos::onScan(int robot, const ScanSample& s)
{
  RobotIo& io = *io_[robot];
  io.scan_msg.header.stamp.fromSec(s.stamp);
  io.scan_msg.ranges.assign(s.ranges.begin(), s.ranges.end());
  io.scan.publish(io.scan_msg);
}

void StageRos::onContact(const ContactEvent& e)
{
  mbot_msgs::Contact msg;
  msg.header.stamp.fromSec(e.stamp);
  msg.header.frame_id = "map";
  msg.body_a = e.body_a;
  msg.body_b = e.body_b;
  msg.position.x = e.x;
  msg.position.y = e.y;
  contact_pub_.publish(msg);
}

// =============================================================================================
// commands and services

void StageRos::onCmdVel(int robot, const geometry_msgs::Twist::ConstPtr& msg)
{
  if (!world_->hasRobot(robot)) return;  // removed while the message waited
  world_->setCommand(robot, Twist2D{msg->linear.x, msg->linear.y, msg->angular.z});
  io_[robot]->last_cmd_time = world_->time();
  io_[robot]->cmd_boundary = boundary_count_;
  io_[robot]->cmd_unused = true;
}

bool StageRos::localizationCurrent(const RobotIo& io) const
{
  return io.localization_stamp + params_.lockstep_localization_lag >= world_->time() - 1e-9;
}

/// Lockstep: the newest stamp of each robot's localization output, a transform to <ns>/odom.
void StageRos::onTf(const tf2_msgs::TFMessage::ConstPtr& msg)
{
  static const std::string suffix = "/odom";
  for (const auto& t : msg->transforms)
  {
    const std::string& child = t.child_frame_id;
    if (child.size() <= suffix.size() || child.compare(child.size() - suffix.size(), suffix.size(), suffix) != 0)
      continue;
    const int robot = world_->findRobot(child.substr(0, child.size() - suffix.size()));
    if (robot < 0 || robot >= static_cast<int>(io_.size()) || !io_[robot]) continue;
    RobotIo& io = *io_[robot];
    io.localization_stamp = std::max(io.localization_stamp, t.header.stamp.toSec());
    if (io.localization_ignored && localizationCurrent(io)) io.localization_ignored = false;  // caught up
  }
}

/// Lockstep: the newest heartbeat of a node that paces sim time (see waitForControllers()).
void StageRos::onHeartbeat(const std_msgs::Header::ConstPtr& msg)
{
  if (msg->frame_id.empty()) return;
  Pacer& p = pacers_[msg->frame_id];
  if (msg->stamp.toSec() > p.stamp)
  {
    p.stamp = msg->stamp.toSec();
    p.moved = ros::WallTime::now();
  }
  if (p.ignored && p.stamp + params_.lockstep_pacer_lag >= world_->time() - 1e-9) p.ignored = false;  // caught up
}

/// As stage_ros: a geometry_msgs/Pose in the map frame; z, roll and pitch are ignored.
void StageRos::onCmdPose(int robot, const geometry_msgs::Pose::ConstPtr& msg)
{
  if (!world_->hasRobot(robot)) return;
  const geometry_msgs::Quaternion& q = msg->orientation;
  const double yaw = mbot_common::yawOf(q.x, q.y, q.z, q.w);
  if (std::isnan(yaw))
  {
    ROS_WARN("stage_node: cmd_pose: %s: the orientation is not a rotation (zero or NaN quaternion)",
             world_->robotName(robot).c_str());
    return;
  }
  try
  {
    world_->teleport(world_->robotName(robot), Pose2D{msg->position.x, msg->position.y, yaw});
  }
  catch (const std::exception& e)
  {
    ROS_WARN("stage_node: cmd_pose: %s", e.what());
  }
}

bool StageRos::onReset(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  world_->resetPositions();
  ROS_INFO("stage_node: reset: robots back at their start poses, odometry at identity");
  return true;
}

bool StageRos::onPause(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  paused_ = true;
  return true;
}

bool StageRos::onUnpause(std_srvs::Empty::Request&, std_srvs::Empty::Response&)
{
  paused_ = false;
  return true;
}

bool StageRos::onSpawn(mbot_msgs::SpawnRobot::Request& req, mbot_msgs::SpawnRobot::Response& res)
{
  const std::string model_name = req.model.empty() ? "mbot" : req.model;
  try
  {
    const mbot_description::RobotModel& m = model(model_name);
    const int id = world_->addRobot(req.name, m, Pose2D{req.pose.x, req.pose.y, req.pose.theta});
    addRobotIo(id);
    publishRobotList();
    res.success = true;
    res.message = "spawned " + req.name + " (" + model_name + ")";
    ROS_INFO("stage_node: %s", res.message.c_str());
  }
  catch (const mbot_description::ModelError& e)
  {
    res.success = false;
    res.message = "unknown or invalid model \"" + model_name + "\": " + e.what();
  }
  catch (const std::exception& e)  // SimError: duplicate name, pose in a wall, ...
  {
    res.success = false;
    res.message = e.what();
  }
  return true;  // the service call itself worked; success says whether the spawn did
}

bool StageRos::onRemove(mbot_msgs::RemoveRobot::Request& req, mbot_msgs::RemoveRobot::Response& res)
{
  const int id = world_->findRobot(req.name);
  try
  {
    world_->removeRobot(req.name);
    io_[id].reset();  // unadvertises its topics
    publishRobotList();
    res.success = true;
    res.message = "removed " + req.name;
    ROS_INFO("stage_node: %s", res.message.c_str());
  }
  catch (const std::exception& e)  // SimError: unknown robot, bad pose or value
  {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

/// The latched /stage/markers are published at once (not at the next marker tick), so that a
/// late subscriber and a test get the obstacles as they are now, stamped with the sim time of
/// the change.
bool StageRos::onSpawnObstacle(mbot_msgs::SpawnObstacle::Request& req, mbot_msgs::SpawnObstacle::Response& res)
{
  try
  {
    world_->addObstacle(obstacleFromRequest(req.name, req.shape, req.length, req.width, req.radius,
                                            Pose2D{req.pose.x, req.pose.y, req.pose.theta}));
    publishMarkers();
    res.success = true;
    res.message = "spawned obstacle " + req.name + " (" + req.shape + ")";
    ROS_INFO("stage_node: %s at (%.2f, %.2f, %.2f) at sim time %.3f s", res.message.c_str(), req.pose.x, req.pose.y,
             req.pose.theta, world_->time());
  }
  catch (const std::exception& e)  // SimError: duplicate name, bad shape or size, on a robot, ...
  {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool StageRos::onRemoveObstacle(mbot_msgs::RemoveObstacle::Request& req, mbot_msgs::RemoveObstacle::Response& res)
{
  try
  {
    world_->removeObstacle(req.name);
    publishMarkers();
    res.success = true;
    res.message = "removed obstacle " + req.name;
    ROS_INFO("stage_node: %s at sim time %.3f s", res.message.c_str(), world_->time());
  }
  catch (const std::exception& e)  // SimError: unknown obstacle, a robot's name, ...
  {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool StageRos::onTeleport(mbot_msgs::TeleportRobot::Request& req, mbot_msgs::TeleportRobot::Response& res)
{
  try
  {
    world_->teleport(req.name, Pose2D{req.pose.x, req.pose.y, req.pose.theta});
    res.success = true;
    res.message = "teleported " + req.name;
  }
  catch (const std::exception& e)  // SimError: unknown robot, bad pose or value
  {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

bool StageRos::onSetFault(mbot_msgs::SetFault::Request& req, mbot_msgs::SetFault::Response& res)
{
  FaultConfig f;
  f.laser_dropout = req.laser_dropout;
  f.sensor_latency = req.sensor_latency;
  f.sensor_jitter = req.sensor_jitter;
  f.odom_drift = req.odom_drift;
  f.drive_frozen = req.drive_frozen;
  f.silenced = req.silenced;
  try
  {
    world_->setFaults(req.robot, f);
    res.success = true;
    res.message = "faults of " + req.robot + " set";
    ROS_INFO("stage_node: faults of %s: dropout %.2f, latency %.3f s, jitter %.3f s, drift %.3f rad/s%s%s",
             req.robot.c_str(), f.laser_dropout, f.sensor_latency, f.sensor_jitter, f.odom_drift,
             f.drive_frozen ? ", drive frozen" : "", f.silenced ? ", silenced" : "");
  }
  catch (const std::exception& e)  // SimError: unknown robot, bad pose or value
  {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

}  // namespace mbot_sim
