#include "mbot_lio/local_map.h"

#include <cmath>

namespace mbot_lio
{
LocalMap::LocalMap(double voxel, size_t rebuild_min, double rebuild_fraction)
    : voxel_(voxel),
      rebuild_min_(rebuild_min),
      rebuild_fraction_(rebuild_fraction),
      main_(new pcl::PointCloud<pcl::PointXYZ>),
      recent_(new pcl::PointCloud<pcl::PointXYZ>)
{}

int64_t LocalMap::key(const Eigen::Vector3d& p) const
{
  // 21 bits per axis: +-1e6 voxels, +-150 km at 0.15 m
  const auto c = [this](double v) { return (static_cast<int64_t>(std::floor(v / voxel_)) + (1 << 20)) & 0x1FFFFF; };
  return (c(p.x()) << 42) | (c(p.y()) << 21) | c(p.z());
}

size_t LocalMap::add(const std::vector<Eigen::Vector3d>& world_points)
{
  size_t added = 0;
  for (const auto& p : world_points)
  {
    if (!occupied_.insert(key(p)).second) continue;
    recent_->push_back(pcl::PointXYZ(float(p.x()), float(p.y()), float(p.z())));
    ++added;
  }
  if (added == 0) return 0;
  if (main_->empty() || recent_->size() > std::max<double>(rebuild_min_, rebuild_fraction_ * main_->size()))
    rebuild();
  else
    recent_tree_.setInputCloud(recent_);
  return added;
}

void LocalMap::rebuild()
{
  *main_ += *recent_;
  recent_->clear();
  main_tree_.setInputCloud(main_);
}

bool LocalMap::nearest(const Eigen::Vector3d& q, int k, std::vector<Eigen::Vector3d>& points,
                       std::vector<float>& sq_dist) const
{
  points.clear();
  sq_dist.clear();
  if (static_cast<int>(size()) < k) return false;
  const pcl::PointXYZ pq(float(q.x()), float(q.y()), float(q.z()));
  const int ka = std::min<int>(k, main_->size()), kb = std::min<int>(k, recent_->size());
  idx_a_.resize(ka);
  d_a_.resize(ka);
  idx_b_.resize(kb);
  d_b_.resize(kb);
  const int na = ka > 0 ? main_tree_.nearestKSearch(pq, ka, idx_a_, d_a_) : 0;
  const int nb = kb > 0 ? recent_tree_.nearestKSearch(pq, kb, idx_b_, d_b_) : 0;
  int ia = 0, ib = 0;
  while (static_cast<int>(points.size()) < k && (ia < na || ib < nb))
  {
    const bool take_a = ib >= nb || (ia < na && d_a_[ia] <= d_b_[ib]);
    const pcl::PointXYZ& p = take_a ? (*main_)[idx_a_[ia]] : (*recent_)[idx_b_[ib]];
    sq_dist.push_back(take_a ? d_a_[ia++] : d_b_[ib++]);
    points.emplace_back(p.x, p.y, p.z);
  }
  return static_cast<int>(points.size()) == k;
}
}  // namespace mbot_lio
