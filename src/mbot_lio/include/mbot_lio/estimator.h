// The laser-inertial odometry: IMU samples in, lidar frames in, the state of the IMU frame in the
// world out (FAST-LIO2's loop: propagate, deskew, iterated update, add to the map). No ROS types.
// Bad input throws std::invalid_argument naming the problem; the estimator keeps its last good state.
#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <stdexcept>
#include <vector>

#include "mbot_lio/local_map.h"
#include "mbot_lio/propagation.h"

namespace mbot_lio
{
// A lidar frame: points in the lidar frame and each point's time after the stamp [s] (the
// PointCloud2 "time" field). times must have one entry per point: a cloud without times is refused.
struct LidarFrame
{
  double stamp = 0.0;
  std::vector<Eigen::Vector3f> points;
  std::vector<float> times;
};

struct Options
{
  ImuNoise imu;
  Eigen::Vector3d gravity = Eigen::Vector3d(0.0, 0.0, -9.80665);
  Eigen::Matrix3d imu_R_lidar = Eigen::Matrix3d::Identity();  // the lidar's mount in the IMU frame
  Eigen::Vector3d imu_p_lidar = Eigen::Vector3d::Zero();
  double frame_voxel = 0.4;         // [m] downsampling of a frame before the update
  double map_voxel = 0.15;          // [m] one map point per voxel
  double min_range = 0.3;           // [m] points closer (the robot itself) are dropped
  int neighbours = 5;               // points of a plane fit
  double max_neighbour_dist = 1.0;  // [m] farthest neighbour of a plane fit
  double plane_tolerance = 0.1;     // [m] each neighbour this close to the fitted plane
  double max_residual = 1.0;        // [m] larger point-to-plane distances are outliers
  double point_sd = 0.03;           // [m] sd of a point-to-plane residual
  int max_iterations = 8;
  double converged_rot = 1e-4;  // [rad] the update stops when its correction is smaller
  double converged_pos = 1e-4;  // [m]
  int min_matches = 30;         // fewer point-plane matches: the frame updates nothing
  double max_imu_gap = 0.05;    // [s] the IMU may end this long before a frame's end
  // start covariance (sd)
  double init_rot_sd = 0.01, init_pos_sd = 0.01, init_vel_sd = 0.05, init_bg_sd = 5e-3, init_ba_sd = 0.05;
};

struct UpdateReport
{
  int iterations = 0;
  int matches = 0;  // point-plane matches of the last iteration
  bool converged = false;
};

struct FrameReport
{
  double t_end = 0.0;  // the state's time after the frame: its last point's time
  size_t points = 0, downsampled = 0, added_to_map = 0;
  UpdateReport update;
  bool updated = false;  // false for the first frame (it starts the map) or too few matches
};

class Estimator
{
public:
  explicit Estimator(const Options& options = Options());

  // Starts at time t with the IMU frame's pose and velocity (start covariance from Options or P, whose
  // diagonal must be positive). Throws on non-finite input.
  void initialize(double t, const State& x);
  void initialize(double t, const State& x, const Cov& P);
  bool initialized() const { return initialized_; }

  // Buffers one IMU sample. Throws on a non-finite value or a stamp not after the last one.
  void addImu(const ImuSample& s);
  // Propagates to the frame's end, deskews it, updates, adds it to the map. Throws (state
  // unchanged) on: not initialized, no or wrong-sized times, non-finite times, a frame ending before
  // the state's time, or IMU samples ending more than max_imu_gap before the frame's end.
  FrameReport addFrame(const LidarFrame& frame);

  // The iterated update alone, on points in the IMU frame at the state's time (tests, tools).
  UpdateReport update(const std::vector<Eigen::Vector3d>& points_imu);

  const State& state() const { return x_; }
  const Cov& covariance() const { return P_; }
  double time() const { return t_; }
  LocalMap& map() { return map_; }
  const Options& options() const { return opt_; }
  // The last frame, deskewed, in the world frame at the updated pose (full resolution).
  const std::vector<Eigen::Vector3d>& lastCloudWorld() const { return last_world_; }

private:
  Options opt_;
  bool initialized_ = false;
  double t_ = 0.0;
  State x_;
  Cov P_ = Cov::Identity();
  std::vector<ImuSample> imu_;
  LocalMap map_;
  std::vector<Eigen::Vector3d> last_world_;
};
}  // namespace mbot_lio
