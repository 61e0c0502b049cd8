/**
 * @file drive.cpp
 * @brief The diff and mecanum drive models: command limits, acceleration limits, the watchdog,
 *        keeping bodies on the plane, wheel rolling speeds. See drive.h.
 */
#include "drive.h"

#include <algorithm>
#include <cmath>

namespace mbot_sim
{
namespace detail
{
using mbot_common::normalizeAngle;
using mbot_description::DriveType;
using mbot_description::RobotModel;

namespace
{
double clamp(double v, double lo, double hi) { return std::min(std::max(v, lo), hi); }

/// Move `v` towards `target` by at most `max_change`.
double approach(double v, double target, double max_change) { return v + clamp(target - v, -max_change, max_change); }
}  // namespace

Twist2D clampCommand(const RobotModel& model, const Twist2D& c)
{
  const auto& lim = model.limits;
  auto finite = [](double v) { return std::isfinite(v) ? v : 0.0; };  // NaN must not reach ODE
  Twist2D out;
  out.vx = clamp(finite(c.vx), std::min(lim.min_vel_x, 0.0), lim.max_vel_x);
  out.vy = model.drive == DriveType::OMNI ? clamp(finite(c.vy), -lim.max_vel_y, lim.max_vel_y) : 0.0;
  out.wz = clamp(finite(c.wz), -lim.max_vel_theta, lim.max_vel_theta);
  return out;
}

std::vector<Point2D> wheelMounts(const RobotModel& model)
{
  const double half_sep = model.wheel_separation / 2.0, half_base = model.wheel_base / 2.0;
  std::vector<Point2D> mounts;
  if (model.drive == DriveType::DIFF)
    mounts = {{0.0, half_sep}, {0.0, -half_sep}};
  else
    mounts = {{half_base, half_sep}, {half_base, -half_sep}, {-half_base, half_sep}, {-half_base, -half_sep}};
  mounts.resize(model.wheel_joints.size());
  return mounts;
}

double wheelRollingSpeed(DriveType drive, const Point2D& w, const Twist2D& m)
{
  // Rolling speed of the wheel's contact point; mecanum rollers at 45 degrees add the sideways
  // speed with the sign of x*y (front left and rear right: +).
  double rolling = m.vx - m.wz * w.y;
  if (drive == DriveType::OMNI) rolling -= (w.x * w.y >= 0.0 ? 1.0 : -1.0) * (m.vy + m.wz * w.x);
  return rolling;
}

void placeBody(Robot& r, const Pose2D& pose)
{
  dBodySetPosition(r.body.get(), pose.x, pose.y, kBodyZ);
  dQuaternion q = {std::cos(pose.theta / 2.0), 0.0, 0.0, std::sin(pose.theta / 2.0)};
  dBodySetQuaternion(r.body.get(), q);
  dBodySetLinearVel(r.body.get(), 0, 0, 0);
  dBodySetAngularVel(r.body.get(), 0, 0, 0);
  r.pose = Pose2D{pose.x, pose.y, normalizeAngle(pose.theta)};
  r.velocity = Twist2D{};
  r.at_rest = true;
  r.setpoint = Twist2D{};
  r.command = Twist2D{};
  r.command_time = -kInf;
}

void driveRobot(Robot& r, double now, double watchdog_timeout, double dt)
{
  const auto& lim = r.model.limits;
  Twist2D target;
  if (!r.faults.drive_frozen && now - r.command_time <= watchdog_timeout + kTimeEpsilon) target = r.command;
  if (r.faults.drive_frozen)
    r.setpoint = Twist2D{};
  else
  {
    r.setpoint.vx = approach(r.setpoint.vx, target.vx, lim.acc_lim_x * dt);
    r.setpoint.vy = approach(r.setpoint.vy, target.vy, std::max(lim.acc_lim_y, 0.0) * dt);
    r.setpoint.wz = approach(r.setpoint.wz, target.wz, lim.acc_lim_theta * dt);
  }
  // The robot-frame velocity in the map frame at the middle of the step: a constant
  // twist then moves the robot along the exact chord of its arc.
  const double yaw_mid = r.pose.theta + 0.5 * r.setpoint.wz * dt;
  const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
  dBodySetLinearVel(r.body.get(), c * r.setpoint.vx - s * r.setpoint.vy, s * r.setpoint.vx + c * r.setpoint.vy, 0.0);
  dBodySetAngularVel(r.body.get(), 0.0, 0.0, r.setpoint.wz);
}

void settleRobot(Robot& r)
{
  dBodyID b = r.body.get();
  const dReal* p = dBodyGetPosition(b);
  const dReal* q = dBodyGetQuaternion(b);  // w, x, y, z
  // Dropping x and y of the quaternion keeps only the rotation about z.
  const double qn = std::hypot(q[0], q[3]);
  const double qw = qn > 0.0 ? q[0] / qn : 1.0, qz = qn > 0.0 ? q[3] / qn : 0.0;
  const dQuaternion flat = {qw, 0.0, 0.0, qz};
  dBodySetQuaternion(b, flat);
  dBodySetPosition(b, p[0], p[1], kBodyZ);
  const dReal* v = dBodyGetLinearVel(b);
  const dReal* w = dBodyGetAngularVel(b);
  const double vx = v[0], vy = v[1], wz = w[2];
  const bool drive_stopped = r.setpoint.vx == 0.0 && r.setpoint.vy == 0.0 && r.setpoint.wz == 0.0;
  if (drive_stopped && std::hypot(vx, vy) < kRestSpeed && std::abs(wz) < kRestSpeed)
  {
    // At rest: undo the solver's residue, so that the pose stays and agrees with the zero velocity.
    const dQuaternion still = {std::cos(r.pose.theta / 2.0), 0.0, 0.0, std::sin(r.pose.theta / 2.0)};
    dBodySetQuaternion(b, still);
    dBodySetPosition(b, r.pose.x, r.pose.y, kBodyZ);
    dBodySetLinearVel(b, 0.0, 0.0, 0.0);
    dBodySetAngularVel(b, 0.0, 0.0, 0.0);
    r.velocity = Twist2D{};
    r.at_rest = true;
    return;
  }
  r.at_rest = false;
  dBodySetLinearVel(b, vx, vy, 0.0);
  dBodySetAngularVel(b, 0.0, 0.0, wz);

  const double previous_yaw = r.pose.theta;
  r.pose = Pose2D{p[0], p[1], normalizeAngle(2.0 * std::atan2(qz, qw))};
  // The robot-frame velocity over the step: rotate by the heading in the middle of the step,
  // as driveRobot() did, so that an unobstructed robot measures exactly its setpoint.
  const double yaw_mid = previous_yaw + 0.5 * normalizeAngle(r.pose.theta - previous_yaw);
  const double c = std::cos(yaw_mid), s = std::sin(yaw_mid);
  r.velocity = Twist2D{c * vx + s * vy, -s * vx + c * vy, wz};
}

}  // namespace detail
}  // namespace mbot_sim
