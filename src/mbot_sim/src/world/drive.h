/**
 * @file drive.h
 * @brief (private to the world) The drive models: a diff drive (`mbot`: forward speed and turn
 *        rate, no sideways motion) and a mecanum drive (`mbot_omni`: also sideways). Commands
 *        are clamped to the model's limits and reached within its acceleration limits; the
 *        body is kept on the plane; wheel speeds follow from the body's motion.
 */
#pragma once

#include "bodies.h"

namespace mbot_sim
{
namespace detail
{
/// The command a robot of this model can follow: clamped to its velocity limits, `vy` only for
/// an omni drive, NaN read as 0 (it must not reach ODE).
Twist2D clampCommand(const mbot_description::RobotModel& model, const Twist2D& command);

/// Wheel contact points in the robot frame [m], in the order of the model's wheel_joints:
/// diff [left, right] at +-separation/2; mecanum [front_left, front_right, rear_left,
/// rear_right] at +-wheel_base/2, +-separation/2.
std::vector<Point2D> wheelMounts(const mbot_description::RobotModel& model);

/// Rolling speed [m/s] of the wheel at `mount` when the robot moves with `twist` (robot frame).
double wheelRollingSpeed(mbot_description::DriveType drive, const Point2D& mount, const Twist2D& twist);

/// Put a robot's body at `pose`, at rest, with no command.
void placeBody(Robot& r, const Pose2D& pose);

/// Before a physics step: the setpoint approaches the command (or 0 after the watchdog timeout
/// or with a frozen drive) and becomes the body's velocity.
void driveRobot(Robot& r, double now, double watchdog_timeout, double dt);

/// [m/s] and [rad/s]: a robot whose drive stands still and that moves slower than this is at
/// rest. The contact solver leaves a few 1e-6 m/s on a robot resting against a wall; a push by
/// another robot or a moving obstacle is far faster.
constexpr double kRestSpeed = 1e-4;

/// After a physics step: back onto the plane (z, roll, pitch), then read the true pose and
/// velocity into r.pose and r.velocity. A robot at rest (setpoint zero, slower than kRestSpeed)
/// stays where it was and its velocity is exactly zero, as stage_ros's robots report ("true
/// zeros"); a pushed robot moves and reports its motion.
void settleRobot(Robot& r);

}  // namespace detail
}  // namespace mbot_sim
