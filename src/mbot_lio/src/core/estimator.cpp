#include "mbot_lio/estimator.h"

#include <pcl/filters/voxel_grid.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <sstream>

namespace mbot_lio
{
namespace
{
std::string fmt(double v)
{
  std::ostringstream s;
  s.precision(6);
  s << std::fixed << v;
  return s.str();
}

Cov startCovariance(const Options& o)
{
  Cov P = Cov::Zero();
  const double sd[5] = {o.init_rot_sd, o.init_pos_sd, o.init_vel_sd, o.init_bg_sd, o.init_ba_sd};
  for (int b = 0; b < 5; ++b) P.block<3, 3>(3 * b, 3 * b).diagonal().setConstant(sd[b] * sd[b]);
  return P;
}
}  // namespace

Estimator::Estimator(const Options& options) : opt_(options), map_(options.map_voxel)
{
  if (!(opt_.point_sd > 0) || opt_.neighbours < 3 || !(opt_.frame_voxel > 0) || !(opt_.map_voxel > 0))
    throw std::invalid_argument("mbot_lio: options need point_sd > 0, neighbours >= 3 and voxel sizes > 0");
}

void Estimator::initialize(double t, const State& x) { initialize(t, x, startCovariance(opt_)); }

void Estimator::initialize(double t, const State& x, const Cov& P)
{
  if (!std::isfinite(t) || !x.R.allFinite() || !x.p.allFinite() || !x.v.allFinite() || !P.allFinite())
    throw std::invalid_argument("mbot_lio: initialize() with a non-finite time, state or covariance");
  if ((P.diagonal().array() <= 0.0).any())
    throw std::invalid_argument(
        "mbot_lio: initialize() with a covariance whose diagonal is not positive (the update "
        "inverts it)");
  t_ = t;
  x_ = x;
  P_ = P;
  initialized_ = true;
  // samples older than the start are kept: the one just before t is the first interval's input
}

void Estimator::addImu(const ImuSample& s)
{
  if (!std::isfinite(s.t) || !s.gyro.allFinite() || !s.acc.allFinite())
    throw std::invalid_argument("mbot_lio: IMU sample at t = " + fmt(s.t) +
                                " has a NaN or infinite time, angular velocity or acceleration; sample dropped");
  if (!imu_.empty() && s.t <= imu_.back().t)
    throw std::invalid_argument("mbot_lio: IMU stamp " + fmt(s.t) + " is not after the previous one " +
                                fmt(imu_.back().t) + " (stamps out of order); sample dropped");
  imu_.push_back(s);
}

FrameReport Estimator::addFrame(const LidarFrame& f)
{
  // Every check before anything changes: a refused frame leaves the estimator as it was.
  if (!initialized_) throw std::invalid_argument("mbot_lio: lidar frame before initialize()");
  if (!std::isfinite(f.stamp)) throw std::invalid_argument("mbot_lio: lidar frame with a non-finite stamp");
  if (f.points.empty()) throw std::invalid_argument("mbot_lio: lidar frame at " + fmt(f.stamp) + " has no points");
  if (f.times.empty())
    throw std::invalid_argument("mbot_lio: lidar frame at " + fmt(f.stamp) +
                                " has no per-point times (the cloud needs a 'time' field to be deskewed)");
  if (f.times.size() != f.points.size())
    throw std::invalid_argument("mbot_lio: lidar frame at " + fmt(f.stamp) + " has " + std::to_string(f.points.size()) +
                                " points but " + std::to_string(f.times.size()) + " point times");
  float max_time = 0.0f;
  for (size_t i = 0; i < f.times.size(); ++i)
  {
    if (!std::isfinite(f.times[i]) || f.times[i] < 0.0f)
      throw std::invalid_argument("mbot_lio: lidar frame at " + fmt(f.stamp) + ": point " + std::to_string(i) +
                                  " has a negative or non-finite time");
    max_time = std::max(max_time, f.times[i]);
  }
  const double t_end = f.stamp + max_time;
  if (f.stamp + 1e-6 < t_ || t_end <= t_)
    throw std::invalid_argument("mbot_lio: lidar frame at " + fmt(f.stamp) + " starts before the estimator's time " +
                                fmt(t_) + " (stamps out of order)");
  if (imu_.empty() || imu_.back().t < t_end - opt_.max_imu_gap)
    throw std::invalid_argument("mbot_lio: lidar frame ending at " + fmt(t_end) + " but the IMU samples end at " +
                                (imu_.empty() ? std::string("(none)") : fmt(imu_.back().t)) +
                                " (more than max_imu_gap before; no IMU?)");

  FrameReport rep;
  rep.t_end = t_end;
  // forward propagation to the frame's end
  State x = x_;
  Cov P = P_;
  const std::vector<Segment> segs = propagate(x, P, t_, t_end, imu_, opt_.imu, opt_.gravity);
  x_ = x;
  P_ = P;
  t_ = t_end;
  // drop the samples before the new state time but the last one (the next interval's input)
  const auto first_kept =
      std::upper_bound(imu_.begin(), imu_.end(), t_, [](double a, const ImuSample& s) { return a < s.t; });
  if (first_kept - imu_.begin() > 1) imu_.erase(imu_.begin(), first_kept - 1);

  // backward propagation: every point into the IMU frame at t_end
  const Deskewer deskew(segs, x.R, x.p);
  std::vector<Eigen::Vector3d> body;
  body.reserve(f.points.size());
  const double min_r2 = opt_.min_range * opt_.min_range;
  for (size_t i = 0; i < f.points.size(); ++i)
  {
    const Eigen::Vector3d pl = f.points[i].cast<double>();
    if (!pl.allFinite() || pl.squaredNorm() < min_r2) continue;
    body.push_back(deskew.toEnd(opt_.imu_R_lidar * pl + opt_.imu_p_lidar, f.stamp + f.times[i]));
  }
  rep.points = body.size();

  // voxel downsampling of the frame (pcl::VoxelGrid: one centroid per occupied voxel)
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud(new pcl::PointCloud<pcl::PointXYZ>);
  cloud->reserve(body.size());
  for (const auto& q : body) cloud->push_back(pcl::PointXYZ(float(q.x()), float(q.y()), float(q.z())));
  pcl::PointCloud<pcl::PointXYZ> filtered;
  pcl::VoxelGrid<pcl::PointXYZ> grid;
  grid.setLeafSize(float(opt_.frame_voxel), float(opt_.frame_voxel), float(opt_.frame_voxel));
  grid.setInputCloud(cloud);
  grid.filter(filtered);
  std::vector<Eigen::Vector3d> ds;
  ds.reserve(filtered.size());
  for (const auto& p : filtered) ds.emplace_back(p.x, p.y, p.z);
  rep.downsampled = ds.size();

  if (map_.size() > 0)
  {
    rep.update = update(ds);
    rep.updated = rep.update.matches >= opt_.min_matches;
  }
  last_world_.resize(body.size());
  for (size_t i = 0; i < body.size(); ++i) last_world_[i] = x_.R * body[i] + x_.p;
  rep.added_to_map = map_.add(last_world_);
  return rep;
}

UpdateReport Estimator::update(const std::vector<Eigen::Vector3d>& pts)
{
  UpdateReport rep;
  const int k = opt_.neighbours;
  if (static_cast<int>(map_.size()) < k) return rep;
  const State x0 = x_;
  const Cov P_inv = P_.ldlt().solve(Cov::Identity());
  const double w = 1.0 / (opt_.point_sd * opt_.point_sd);
  const double max_nd2 = opt_.max_neighbour_dist * opt_.max_neighbour_dist;
  State x = x0;
  Cov A = P_inv;
  std::vector<Eigen::Vector3d> nb;
  std::vector<float> d2;
  for (int it = 0; it < opt_.max_iterations; ++it)
  {
    // point-to-plane residuals and Jacobians at the current iterate (FAST-LIO eq. (12)-(13))
    Eigen::Matrix<double, 6, 6> HtH = Eigen::Matrix<double, 6, 6>::Zero();
    Eigen::Matrix<double, 6, 1> Htz = Eigen::Matrix<double, 6, 1>::Zero();
    int m = 0;
    for (const auto& q : pts)
    {
      const Eigen::Vector3d pw = x.R * q + x.p;
      if (!map_.nearest(pw, k, nb, d2) || d2.back() > max_nd2) continue;
      // plane through the neighbours: centroid and the covariance's smallest eigenvector
      Eigen::Vector3d c = Eigen::Vector3d::Zero();
      for (const auto& p : nb) c += p;
      c /= k;
      Eigen::Matrix3d C = Eigen::Matrix3d::Zero();
      for (const auto& p : nb) C += (p - c) * (p - c).transpose();
      Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es;
      es.computeDirect(C);
      const Eigen::Vector3d n = es.eigenvectors().col(0);
      bool flat = true;
      for (const auto& p : nb) flat = flat && std::abs(n.dot(p - c)) < opt_.plane_tolerance;
      if (!flat) continue;
      const double z = n.dot(pw - c);
      if (std::abs(z) > opt_.max_residual) continue;
      Eigen::Matrix<double, 6, 1> h;
      h.head<3>() = q.cross(x.R.transpose() * n);  // dz/dtheta, R = R_hat Exp(dtheta)
      h.tail<3>() = n;                             // dz/dp
      HtH += h * h.transpose();
      Htz += h * z;
      ++m;
    }
    rep.matches = m;
    if (m < opt_.min_matches) return rep;  // too little to correct anything: the prediction stands
    // iterated update (FAST-LIO eq. (18)) in information form:
    // dx = -(H^T R^-1 H + P^-1)^-1 (H^T R^-1 z + P^-1 (x boxminus x_prior))
    A = P_inv;
    A.topLeftCorner<6, 6>() += w * HtH;
    ErrorVec b = P_inv * boxminus(x, x0);
    b.head<6>() += w * Htz;
    const ErrorVec dx = -A.ldlt().solve(b);
    x = boxplus(x, dx);
    rep.iterations = it + 1;
    if (dx.segment<3>(kRot).norm() < opt_.converged_rot && dx.segment<3>(kPos).norm() < opt_.converged_pos)
    {
      rep.converged = true;
      break;
    }
  }
  // P = (I - K H) P = (H^T R^-1 H + P^-1)^-1 (FAST-LIO eq. (19))
  x_ = x;
  P_ = A.ldlt().solve(Cov::Identity());
  P_ = 0.5 * (P_ + P_.transpose()).eval();
  return rep;
}
}  // namespace mbot_lio
