/**
 * @file stage_ros_services.cpp
 * @brief The run-time control of stage_node: services (reset, pause, spawn, remove, teleport,
 *        faults, obstacles) and live tuning (dynamic_reconfigure). See stage_ros.h.
 */
#include "mbot_sim/stage_ros.h"

#include <algorithm>

namespace mbot_sim
{
// =============================================================================================
// services

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
      NoiseConfig noise = now;  // the IMU's part is not live-tunable: it stays
      noise.laser_range = c.laser_range;
      noise.odom_linear = c.odom_linear;
      noise.odom_angular = c.odom_angular;
      world_->setNoise(noise);
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

}  // namespace mbot_sim
