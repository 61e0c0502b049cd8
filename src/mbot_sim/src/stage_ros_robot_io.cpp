/**
 * @file stage_ros_robot_io.cpp
 * @brief Each robot's topics: its publishers and subscribers, sensor samples -> messages, and
 *        the commands it takes (cmd_vel, cmd_pose, cmd_pose_stamped). See stage_ros.h.
 */
#include "mbot_sim/stage_ros.h"

#include "stage_ros_internal.h"

#include <mbot_msgs/Contact.h>

#include <algorithm>
#include <cmath>

namespace mbot_sim
{
namespace
{
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

/// The rotation `q` (x, y, z, w) followed by `angle` about the unit `axis`: a revolute joint's
/// origin rotation composed with its position.
geometry_msgs::Quaternion jointRotation(const double q[4], const double axis[3], double angle)
{
  const double s = std::sin(angle / 2.0);
  const double b[4] = {axis[0] * s, axis[1] * s, axis[2] * s, std::cos(angle / 2.0)};
  geometry_msgs::Quaternion out;
  out.x = q[3] * b[0] + q[0] * b[3] + q[1] * b[2] - q[2] * b[1];
  out.y = q[3] * b[1] - q[0] * b[2] + q[1] * b[3] + q[2] * b[0];
  out.z = q[3] * b[2] + q[0] * b[1] - q[1] * b[0] + q[2] * b[3];
  out.w = q[3] * b[3] - q[0] * b[0] - q[1] * b[1] - q[2] * b[2];
  return out;
}

}  // namespace

// =============================================================================================
// a robot's topics

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
      ns + "cmd_pose", 1, [this, id](const geometry_msgs::Pose::ConstPtr& msg) { onCmdPose(id, *msg, "cmd_pose"); });
  // As stage_ros: the header is ignored, the pose is in the map frame like cmd_pose's.
  io->cmd_pose_stamped = nh_.subscribe<geometry_msgs::PoseStamped>(
      ns + "cmd_pose_stamped", 1,
      [this, id](const geometry_msgs::PoseStamped::ConstPtr& msg) { onCmdPose(id, msg->pose, "cmd_pose_stamped"); });

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
  addLidarIo(*io, id);
  if (m.imu.present)
  {
    // 400: 2 s at 200 Hz. A raw gyro and accelerometer (REP-145): no orientation (covariance -1);
    // the diagonals are the variance of one white-noise sample, density^2 * rate.
    io->imu = nh_.advertise<sensor_msgs::Imu>(ns + "imu", 400);
    const ImuNoiseConfig& imu = world_->noise().imu;
    io->imu_msg.header.frame_id = io->prefix + "imu_link";
    io->imu_msg.orientation.w = 1.0;
    io->imu_msg.orientation_covariance[0] = -1.0;
    for (int i = 0; i < 3; ++i)
    {
      io->imu_msg.angular_velocity_covariance[4 * i] = imu.gyro_noise_density * imu.gyro_noise_density * imu.rate;
      io->imu_msg.linear_acceleration_covariance[4 * i] = imu.accel_noise_density * imu.accel_noise_density * imu.rate;
    }
  }
  // The wheels' transforms (as Gazebo's diff drive plugin's publishWheelTF): robot_state_publisher
  // then needs no joint_states, and publishes only the fixed joints, once, on /tf_static.
  for (const auto& frame : m.wheel_frames)
  {
    geometry_msgs::TransformStamped tf;
    tf.header.frame_id = io->prefix + frame.parent;
    tf.child_frame_id = io->prefix + frame.child;
    tf.transform.translation.x = frame.origin_xyz[0];
    tf.transform.translation.y = frame.origin_xyz[1];
    tf.transform.translation.z = frame.origin_xyz[2];
    io->wheel_tf.push_back(tf);
  }
  if (id >= static_cast<int>(io_.size())) io_.resize(id + 1);
  io_[id] = std::move(io);
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
  if (!report_fleet_truth_) return;
  mbot_msgs::RobotState state;
  state.name = io.name;
  state.stamp = io.ground_truth_msg.header.stamp;
  state.pose.x = s.pose.x;
  state.pose.y = s.pose.y;
  state.pose.theta = s.pose.theta;
  state.twist = io.ground_truth_msg.twist.twist;
  fleet_truth_.robots.push_back(state);
}

void StageRos::onJointState(int robot, const JointStateSample& s)
{
  RobotIo& io = *io_[robot];
  io.joint_msg.header.stamp.fromSec(s.stamp);
  io.joint_msg.position = s.position;
  io.joint_msg.velocity = s.velocity;
  io.joint_states.publish(io.joint_msg);  // serialized only when someone subscribes

  if (params_.wheel_tf_rate <= 0.0 || s.stamp < io.next_wheel_tf) return;
  const double period = 1.0 / params_.wheel_tf_rate;
  io.next_wheel_tf += period;
  if (io.next_wheel_tf <= s.stamp) io.next_wheel_tf = s.stamp + period;  // first time, or after a reset
  const auto& frames = world_->robotModel(robot).wheel_frames;
  for (std::size_t i = 0; i < io.wheel_tf.size() && i < s.position.size(); ++i)
  {
    geometry_msgs::TransformStamped& tf = io.wheel_tf[i];
    tf.header.stamp = io.joint_msg.header.stamp;
    tf.transform.rotation = jointRotation(frames[i].origin_q, frames[i].axis, s.position[i]);
    tf_batch_.push_back(tf);
  }
}

void StageRos::onScan(int robot, const ScanSample& s)
{
  RobotIo& io = *io_[robot];
  io.scan_msg.header.stamp.fromSec(s.stamp);
  io.scan_msg.ranges.assign(s.ranges.begin(), s.ranges.end());
  io.scan.publish(io.scan_msg);
}

bool StageRos::wantsImu(int robot) const
{
  return robot < static_cast<int>(io_.size()) && io_[robot] && io_[robot]->imu.getNumSubscribers() > 0;
}

void StageRos::onImu(int robot, const ImuSample& s)
{
  RobotIo& io = *io_[robot];
  io.imu_msg.header.stamp.fromSec(std::max(0.0, s.stamp));  // a negative time_offset at start
  io.imu_msg.angular_velocity.x = s.angular_velocity[0];
  io.imu_msg.angular_velocity.y = s.angular_velocity[1];
  io.imu_msg.angular_velocity.z = s.angular_velocity[2];
  io.imu_msg.linear_acceleration.x = s.linear_acceleration[0];
  io.imu_msg.linear_acceleration.y = s.linear_acceleration[1];
  io.imu_msg.linear_acceleration.z = s.linear_acceleration[2];
  io.imu.publish(io.imu_msg);
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
// commands

void StageRos::onCmdVel(int robot, const geometry_msgs::Twist::ConstPtr& msg)
{
  if (!world_->hasRobot(robot)) return;  // removed while the message waited
  RobotIo& io = *io_[robot];
  const ros::WallTime wall_now = ros::WallTime::now();
  // Lockstep: count the zeros in a row that find the robot at rest: a controller that repeats them
  // soon after each other holds its robot still (see stopped()). "Soon" in sim time, or in wall
  // time for sim time that runs free because nothing holds it.
  const bool soon = world_->time() - io.last_cmd_time <= params_.lockstep_active_timeout ||
                    (wall_now - io.last_cmd_wall).toSec() <= kHoldingWallGap;
  io.cmd_zero = msg->linear.x == 0.0 && msg->linear.y == 0.0 && msg->angular.z == 0.0;
  if (!io.cmd_zero || !soon) io.zeros_at_rest = 0;
  if (io.cmd_zero && world_->atRest(robot)) ++io.zeros_at_rest;  // a zero while it brakes or is pushed: no count
  world_->setCommand(robot, Twist2D{msg->linear.x, msg->linear.y, msg->angular.z});
  io.last_cmd_time = world_->time();
  io.last_cmd_wall = wall_now;
  io.cmd_boundary = boundary_count_;
  io.cmd_unused = true;
  io.cmd_pending = true;  // a newer one replaces it: only the newest before a step is applied
  io.cmd_received = world_->time();
  io.cmd_msg = *msg;
}

/// As stage_ros: a pose in the map frame; z, roll and pitch are ignored. The robot is moved at
/// once, at rest, and its odometry moves with it (the odom frame stays put in the map), as a
/// Stage robot's does with Stage's default localization "gps" (odometry = the true pose), which
/// stage_ros's own worlds use. /teleport_robot leaves the odometry alone (a kidnapping).
void StageRos::onCmdPose(int robot, const geometry_msgs::Pose& pose, const char* topic)
{
  if (!world_->hasRobot(robot)) return;
  const geometry_msgs::Quaternion& q = pose.orientation;
  const double yaw = mbot_common::yawOf(q.x, q.y, q.z, q.w);
  if (std::isnan(yaw))
  {
    ROS_WARN("stage_node: %s: %s: the orientation is not a rotation (zero or NaN quaternion)", topic,
             world_->robotName(robot).c_str());
    return;
  }
  try
  {
    world_->teleport(world_->robotName(robot), Pose2D{pose.position.x, pose.position.y, yaw}, true);
  }
  catch (const std::exception& e)
  {
    ROS_WARN("stage_node: %s: %s", topic, e.what());
  }
}

}  // namespace mbot_sim
