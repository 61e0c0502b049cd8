/**
 * @file odometry.h
 * @brief (private to the world) What a robot measures about itself, with its errors: odometry
 *        and wheel joints from the wheel motion, Gaussian noise (odometry, laser ranges), and the
 *        faults that spoil measurements (odometry drift, laser dropout, sensor latency).
 *        Every random draw comes from the robot's own generator, in a fixed order.
 */
#pragma once

#include "bodies.h"

namespace mbot_sim
{
namespace detail
{
/// Odometry from the wheels after a step: they measure the robot's motion along the directions
/// they drive (a diff drive cannot sense being pushed sideways), plus noise (only while the
/// wheels turn) and the odom_drift fault. Updates r.odom, r.odom_twist and r.joints.
void integrateOdometry(Robot& r, const NoiseConfig& noise, double dt);

/// Range noise and the laser_dropout fault on r.scan, just measured: a dropped beam is NaN;
/// a noisy range beyond the limits becomes +-Inf (REP-117).
void addLaserNoise(Robot& r, const NoiseConfig& noise);

/// True when a latency or jitter fault holds the robot's samples back.
bool delayed(const Robot& r);

/// When a sample measured at `now` reaches the listener (latency fault), keeping the order.
double releaseTime(Robot& r, double now);

}  // namespace detail
}  // namespace mbot_sim
