/**
 * @file sensors.cpp
 * @brief Sensor timers, the laser scan (walls and bodies), the IMU's samples, and handing samples to the listener,
 *        at once or after a latency fault's delay. See sensors.h.
 */
#include "sensors.h"

#include "odometry.h"

#include <algorithm>
#include <cmath>
#include <deque>

namespace mbot_sim
{
namespace detail
{
namespace
{
/// True when a timer with `next` is due at `now`; then `next` moves on by one period.
bool due(double now, double& next, double period)
{
  if (now + kTimeEpsilon < next) return false;
  next += period;
  if (next <= now) next = now + period;  // after a long pause of the timer: no burst
  return true;
}

/// Hand over the samples a latency fault held back whose time has come (a silenced robot's
/// are dropped).
template <class Sample>
void releasePending(Robot& r, double now, SensorListener* listener, std::deque<Pending<Sample>>& queue,
                    void (SensorListener::*deliver)(int, const Sample&))
{
  while (!queue.empty() && queue.front().release <= now + kTimeEpsilon)
  {
    if (listener && !r.faults.silenced) (listener->*deliver)(r.id, queue.front().sample);
    queue.pop_front();
  }
}
}  // namespace

Sensors::Sensors() : shapes_(4.0) {}

void Sensors::run(double now, const NoiseConfig& noise, SensorListener* listener,
                  const std::vector<std::unique_ptr<Robot>>& robots,
                  const std::vector<std::unique_ptr<Obstacle>>& obstacles,
                  const std::vector<std::unique_ptr<Mover>>& movers)
{
  bool shapes_built = false;  // only when some laser is due
  bool prisms_built = false;  // only when some 3D lidar casts
  for (const auto& robot : robots)
  {
    Robot& r = *robot;
    if (due(now, r.next_ground_truth, r.ground_truth_period) && listener)
    {
      GroundTruthSample gt;
      gt.stamp = now;
      gt.pose = r.pose;
      gt.twist = r.velocity;
      listener->onGroundTruth(r.id, gt);
    }
    const bool silenced = r.faults.silenced;
    if (due(now, r.next_odom, r.odom_period) && !silenced)
    {
      OdometrySample odom;
      odom.stamp = now;
      odom.pose = r.odom;
      odom.twist = r.odom_twist;
      r.joints.stamp = now;
      if (delayed(r))
      {
        const double release = releaseTime(r, now);
        r.pending_odom.push_back({release, odom});
        r.pending_joints.push_back({release, r.joints});
      }
      else if (listener)
      {
        listener->onOdometry(r.id, odom);
        listener->onJointState(r.id, r.joints);
      }
    }
    if (due(now, r.next_scan, r.scan_period) && !silenced)
    {
      if (!shapes_built)
      {
        buildShapes(robots, obstacles, movers);
        shapes_built = true;
      }
      measureScan(r, now, noise);
      if (delayed(r))
        r.pending_scans.push_back({releaseTime(r, now), r.scan});
      else if (listener)
        listener->onScan(r.id, r.scan);
    }
    releasePending(r, now, listener, r.pending_odom, &SensorListener::onOdometry);
    releasePending(r, now, listener, r.pending_joints, &SensorListener::onJointState);
    releasePending(r, now, listener, r.pending_scans, &SensorListener::onScan);
    if (r.lidar) runLidar(r, now, listener, robots, obstacles, movers, prisms_built);
    if (r.imu.present) runImu(r, now, listener);
  }
}

void Sensors::runImu(Robot& r, double now, SensorListener* listener)
{
  ImuState& s = r.imu;
  ImuErrors& errors = *s.errors;
  const double period = errors.period();
  const Twist2D v = r.velocity;
  // Derivatives over the step just done (zero at the first step and after a teleport).
  const bool have_last = s.last_time >= 0.0 && now > s.last_time + kTimeEpsilon;
  const Twist2D last = have_last ? s.last_velocity : v;
  const double last_time = have_last ? s.last_time : now;
  const double dt = have_last ? now - s.last_time : 1.0;
  const double dvx = (v.vx - last.vx) / dt, dvy = (v.vy - last.vy) / dt, alpha = (v.wz - last.wz) / dt;
  s.last_velocity = v;
  s.last_time = now;

  const bool active = listener && !r.faults.silenced && listener->wantsImu(r.id);
  if (!active)  // skip the due samples; the bias walks over the gap at the next sample
  {
    const long long due_k = static_cast<long long>(std::floor((now + kTimeEpsilon - s.start) / period));
    s.k = std::max(s.k, due_k + 1);
  }
  else
  {
    std::array<double, 3> gyro{}, accel{};
    for (double t = s.start + s.k * period; t <= now + kTimeEpsilon; t = s.start + (++s.k) * period)
    {
      // The motion at t: velocities interpolated over the step, derivatives constant in it.
      const double f = dt > 0.0 ? std::min(1.0, std::max(0.0, (t - last_time) / dt)) : 1.0;
      Twist2D vt;
      vt.vx = last.vx + f * (v.vx - last.vx);
      vt.vy = last.vy + f * (v.vy - last.vy);
      vt.wz = last.wz + f * (v.wz - last.wz);
      s.mount.measure(vt, dvx, dvy, alpha, gyro, accel);
      errors.walk(t - period - s.bias_time);  // a gap nobody listened to (apply walks one period)
      s.bias_time = t;
      ImuSample sample;
      sample.stamp = t + errors.config().time_offset;
      errors.apply(gyro, accel, sample);
      if (delayed(r))
      {
        // Its own jitter draws, so the other sensors' noise does not depend on IMU listeners.
        const FaultConfig& fault = r.faults;
        double release = t + fault.sensor_latency;
        if (fault.sensor_jitter > 0.0) release += std::abs(fault.sensor_jitter * errors.gauss());
        s.last_release = std::max(release, s.last_release);
        s.pending.emplace_back(s.last_release, sample);
      }
      else
      {
        listener->onImu(r.id, sample);
      }
    }
  }
  while (!s.pending.empty() && s.pending.front().first <= now + kTimeEpsilon)
  {
    if (listener && !r.faults.silenced) listener->onImu(r.id, s.pending.front().second);
    s.pending.pop_front();
  }
}

void Sensors::buildShapes(const std::vector<std::unique_ptr<Robot>>& robots,
                          const std::vector<std::unique_ptr<Obstacle>>& obstacles,
                          const std::vector<std::unique_ptr<Mover>>& movers)
{
  shapes_.clear();
  for (const auto& o : obstacles) addShape(o->outline, o->pose, -1);
  for (const auto& m : movers) addShape(m->outline, m->pose, -1);
  for (const auto& r : robots) addShape(r->outline, r->pose, r->id);
}

void Sensors::addShape(const Outline& outline, const Pose2D& pose, int owner)
{
  const Pose2D p = outlinePose(outline, pose);
  if (outline.is_box)
  {
    OrientedBox b;
    b.x = p.x;
    b.y = p.y;
    b.yaw = p.theta;
    b.half_length = outline.half_length;
    b.half_width = outline.half_width;
    b.owner = owner;
    shapes_.addBox(b);
  }
  else
  {
    Circle c;
    c.x = p.x;
    c.y = p.y;
    c.radius = outline.radius;
    c.owner = owner;
    shapes_.addCircle(c);
  }
}

void Sensors::addPrism(const Outline& outline, const Pose2D& pose, double height, int owner, float intensity)
{
  const Pose2D p = outlinePose(outline, pose);
  Prism prism;
  prism.is_box = outline.is_box;
  prism.x = p.x;
  prism.y = p.y;
  prism.yaw = p.theta;
  prism.radius = outline.radius;
  prism.half_length = outline.half_length;
  prism.half_width = outline.half_width;
  prism.height = height;
  prism.owner = owner;
  prism.intensity = intensity;
  scene_.addPrism(prism);
}

void Sensors::runLidar(Robot& r, double now, SensorListener* listener,
                       const std::vector<std::unique_ptr<Robot>>& robots,
                       const std::vector<std::unique_ptr<Obstacle>>& obstacles,
                       const std::vector<std::unique_ptr<Mover>>& movers, bool& prisms_built)
{
  LidarScanner& lidar = *r.lidar;
  const bool active = listener && !r.faults.silenced && listener->wantsPoints(r.id);
  const bool moved_smoothly = r.lidar_last_time >= 0.0 && now > r.lidar_last_time + kTimeEpsilon;
  if (!active || !moved_smoothly)
  {
    lidar.restart(now);  // nobody listens, or a jump: the next frame starts now
  }
  else
  {
    if (!prisms_built)
    {
      // Intensities per kind of body (a model: no reflectivity per material).
      scene_.clearPrisms();
      for (const auto& o : obstacles) addPrism(o->outline, o->pose, o->height, -1, 150.0f);
      for (const auto& m : movers) addPrism(m->outline, m->pose, m->config.height, -1, 60.0f);
      for (const auto& b : robots) addPrism(b->outline, b->pose, std::max(b->model.height, 0.05), b->id, 200.0f);
      prisms_built = true;
    }
    // Bodies within reach of any point of the step: the range plus how far the robot moved.
    const Pose2D& last = r.lidar_last_pose;
    const double moved = std::hypot(r.pose.x - last.x, r.pose.y - last.y);
    near_.prepare(scene_, r.pose.x, r.pose.y, lidar.spec().range_max + moved + 1.0, r.id);
    frames_.clear();
    lidar_rays_ += lidar.advance(scene_, near_, r.lidar_last_time, PlanarPose{last.x, last.y, last.theta}, now,
                                 PlanarPose{r.pose.x, r.pose.y, r.pose.theta}, r.lidar_rng, frames_);
    for (LidarFrame& frame : frames_)
    {
      if (delayed(r))
        r.pending_clouds.push_back({releaseTime(r, now), std::move(frame)});
      else
        listener->onPointCloud(r.id, frame);
    }
  }
  r.lidar_last_time = now;
  r.lidar_last_pose = r.pose;
  releasePending(r, now, listener, r.pending_clouds, &SensorListener::onPointCloud);
}

void Sensors::measureScan(Robot& r, double now, const NoiseConfig& noise)
{
  const auto& laser = r.model.laser;
  ScanSpec& spec = r.scan_spec;
  const Point2D mount = mbot_common::transformPoint(r.pose, laser.mount_x, laser.mount_y);
  spec.x = mount.x;
  spec.y = mount.y;
  spec.yaw = r.pose.theta + laser.mount_yaw;
  castScan(grid_, shapes_, spec, r.scan.ranges);
  rays_cast_ += static_cast<unsigned long long>(spec.beams);
  r.scan.stamp = now;
  addLaserNoise(r, noise);
}

}  // namespace detail
}  // namespace mbot_sim
