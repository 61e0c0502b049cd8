// The map: world-frame points, one per voxel (map_voxel), searched with PCL KD-trees.
// In place of FAST-LIO2's ikd-tree (an incrementally balanced tree) two pcl::KdTreeFLANN are kept:
// a main tree over most points, rebuilt only when the points added since its last build exceed a
// fraction of it, and a small tree over those recent points, rebuilt after each insertion. A query
// merges the k nearest of both. Nothing is removed yet (no local-map window).
#pragma once

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <Eigen/Core>
#include <cstdint>
#include <unordered_set>
#include <vector>

namespace mbot_lio
{
class LocalMap
{
public:
  explicit LocalMap(double voxel = 0.15, size_t rebuild_min = 2000, double rebuild_fraction = 0.3);

  // Adds the points whose voxel holds none yet; returns how many were added.
  size_t add(const std::vector<Eigen::Vector3d>& world_points);
  // The k nearest map points to q (ascending distance); false when the map has fewer than k.
  bool nearest(const Eigen::Vector3d& q, int k, std::vector<Eigen::Vector3d>& points,
               std::vector<float>& sq_dist) const;
  size_t size() const { return main_->size() + recent_->size(); }
  double voxel() const { return voxel_; }

private:
  void rebuild();
  int64_t key(const Eigen::Vector3d& p) const;

  double voxel_;
  size_t rebuild_min_;
  double rebuild_fraction_;
  std::unordered_set<int64_t> occupied_;
  pcl::PointCloud<pcl::PointXYZ>::Ptr main_, recent_;
  pcl::KdTreeFLANN<pcl::PointXYZ> main_tree_, recent_tree_;
  // scratch of nearest() (the map is used from one thread)
  mutable std::vector<int> idx_a_, idx_b_;
  mutable std::vector<float> d_a_, d_b_;
};
}  // namespace mbot_lio
