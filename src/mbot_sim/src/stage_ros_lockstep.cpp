/**
 * @file stage_ros_lockstep.cpp
 * @brief Lockstep (~lockstep): sim time waits at every ~lockstep_period boundary for the driven
 *        robots' controllers, every robot's localization and the nodes that pace sim time.
 *        See waitForControllers() for the rules.
 */
#include "mbot_sim/stage_ros.h"

#include "stage_ros_internal.h"

#include <ros/callback_queue.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <string>
#include <utility>
#include <vector>

namespace mbot_sim
{
/// Lockstep: the robot's controller has stopped commanding: its last cmd_vel was a stop (all zeros)
/// and it is not holding the robot still (fewer than kHoldingZeros zeros in a row found it at rest,
/// see onCmdVel()). The robot needs no controller to come to rest and stay there, so sim time does
/// not wait for it.
bool StageRos::stopped(const RobotIo& io) { return io.cmd_zero && io.zeros_at_rest < kHoldingZeros; }

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
/// A robot whose controller has stopped commanding (stopped(): its last cmd_vel was a stop that is
/// not one of a holding controller's repeated zeros) is not waited for until it sends again: move_base
/// goes silent after a goal, and waiting for its next cmd_vel cost one wall timeout per goal.
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
  const auto commandLate = [&](const RobotIo& io) { return driven(io) && !answered(io) && !stopped(io); };
  const auto localized = [this](const RobotIo& io) {
    return io.localization_ignored || io.localization_stamp < -1e8 ||  // none seen: nothing to wait for
           localizationCurrent(io);
  };
  const auto waitingFor = [&](const RobotIo& io) { return commandLate(io) || !localized(io); };
  const auto paced = [this](const Pacer& p) {
    return p.ignored || p.stamp + params_.lockstep_pacer_lag >= world_->time() - 1e-9;
  };
  const ros::WallTime started = ros::WallTime::now();
  std::vector<std::string> blockers;  // who sim time waited for in the last round (the last to answer)
  while (true)
  {
    if (!ros::ok() || paused_) return false;
    bool all_answered = true;
    for (const auto& io : io_)
      if (io && waitingFor(*io)) all_answered = false;
    for (const auto& p : pacers_)
      if (!paced(p.second)) all_answered = false;
    if (all_answered) break;
    blockers.clear();
    for (const auto& io : io_)
    {
      if (io && commandLate(*io)) blockers.push_back(io->name + " cmd_vel");
      if (io && !localized(*io)) blockers.push_back(io->name + " localization");
    }
    for (const auto& p : pacers_)
      if (!paced(p.second)) blockers.push_back(p.first + " heartbeat");
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
          if (commandLate(*io))
          {
            late += (late.empty() ? "" : ", ") + io->name + " (no cmd_vel)";
            io->last_cmd_time = -1e9;  // not driven until its next cmd_vel
          }
          if (!localized(*io))
          {
            late += (late.empty() ? "" : ", ") + io->name + " (localization " +
                    std::to_string(world_->time() - (io->localization_stamp - params_.lockstep_localization_postdate)) +
                    " s behind)";
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
      ++lockstep_timeouts_total_;
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
    // Sleeps until a callback is ready (an answer, a transform, a heartbeat, a service call), at most
    // 50 ms: besides callbacks only the wall clock and shutdown change what this loop waits for.
    queue.callAvailable(ros::WallDuration(0.05));
  }
  for (auto& io : io_)  // each cmd_vel releases one boundary
    if (io && io->cmd_boundary >= boundary_count_ - 1) io->cmd_unused = false;
  boundary_wait_pending_ = false;
  if (!blockers.empty())
  {
    // The wait is charged to the last to answer: what a faster fleet has to speed up.
    const double waited = (ros::WallTime::now() - started).toSec();
    lockstep_wait_total_ += waited;
    for (const std::string& name : blockers) lockstep_wait_by_[name] += waited / blockers.size();
  }
  return true;
}

/// Lockstep: the wall time spent waiting at boundaries, and who was waited for most (logged at the end).
std::string StageRos::lockstepWaitSummary(double run_wall) const
{
  std::vector<std::pair<double, std::string>> by_time;
  for (const auto& entry : lockstep_wait_by_) by_time.emplace_back(entry.second, entry.first);
  std::sort(by_time.rbegin(), by_time.rend());
  char line[160];
  std::snprintf(line, sizeof line, "%.1f s of %.1f s wall waiting at boundaries (%.0f %%)", lockstep_wait_total_,
                run_wall, run_wall > 0.0 ? 100.0 * lockstep_wait_total_ / run_wall : 0.0);
  std::string text = line;
  for (std::size_t i = 0; i < by_time.size() && i < 6; ++i)
  {
    std::snprintf(line, sizeof line, "%s %s %.1f s", i == 0 ? "; the last to answer:" : ",", by_time[i].second.c_str(),
                  by_time[i].first);
    text += line;
  }
  return text;
}

/// Lockstep: this robot's localization is at most ~lockstep_localization_lag behind sim time.
bool StageRos::localizationCurrent(const RobotIo& io) const
{
  // A localization stamps map -> odom with the time of its data plus its transform_tolerance (as
  // amcl), so that lookups a little newer than its last update succeed. What it has processed is
  // the stamp without that: waiting on the stamp itself let sim time run up to the tolerance
  // further ahead of a slow localization, and the followers then found poses too old.
  return io.localization_stamp - params_.lockstep_localization_postdate + params_.lockstep_localization_lag >=
         world_->time() - 1e-9;
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

}  // namespace mbot_sim
