/**
 * @file shape_set.cpp
 * @brief ShapeSet: the circles and boxes a laser sees besides the walls, in spatial buckets so a
 *        scan looks only at shapes near the sensor. See raycast.h; scans use it in scan.cpp.
 */
#include "mbot_sim/raycast.h"

#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot_sim
{
ShapeSet::ShapeSet(double bucket_size) : bucket_size_(bucket_size)
{
  if (!(bucket_size > 0.0))
    throw std::invalid_argument("ShapeSet: bucket_size must be > 0 [m], got " + std::to_string(bucket_size));
}

void ShapeSet::clear()
{
  for (auto& kv : buckets_)
  {
    kv.second.circles.clear();
    kv.second.boxes.clear();
  }
  count_ = 0;
  max_extent_ = 0.0;
}

int64_t ShapeSet::bucketIndex(double v) const { return static_cast<int64_t>(std::floor(v / bucket_size_)); }

namespace
{
/// One key for a bucket (bx, by): the low 32 bits of each index, side by side.
inline int64_t packBucketKey(int64_t bx, int64_t by)
{
  const uint64_t key = (static_cast<uint64_t>(bx) << 32) | (static_cast<uint64_t>(by) & 0xffffffffu);
  return static_cast<int64_t>(key);
}
}  // namespace

ShapeSet::Bucket& ShapeSet::bucketAt(double x, double y)
{
  return buckets_[packBucketKey(bucketIndex(x), bucketIndex(y))];
}

const ShapeSet::Bucket* ShapeSet::findBucket(int64_t bx, int64_t by) const
{
  const auto it = buckets_.find(packBucketKey(bx, by));
  return it == buckets_.end() ? nullptr : &it->second;
}

void ShapeSet::addCircle(const Circle& c)
{
  if (!std::isfinite(c.x) || !std::isfinite(c.y) || !(c.radius >= 0.0) || !std::isfinite(c.radius))
    throw std::invalid_argument("ShapeSet::addCircle: x, y must be finite and radius >= 0 [m]");
  bucketAt(c.x, c.y).circles.push_back(c);
  max_extent_ = std::max(max_extent_, c.radius);
  ++count_;
}

void ShapeSet::addBox(const OrientedBox& b)
{
  if (!std::isfinite(b.x) || !std::isfinite(b.y) || !std::isfinite(b.yaw) || !(b.half_length >= 0.0) ||
      !(b.half_width >= 0.0) || !std::isfinite(b.half_length) || !std::isfinite(b.half_width))
    throw std::invalid_argument("ShapeSet::addBox: x, y, yaw must be finite and half sizes >= 0 [m]");
  PreparedBox p;
  p.box = b;
  p.cos_yaw = std::cos(b.yaw);
  p.sin_yaw = std::sin(b.yaw);
  bucketAt(b.x, b.y).boxes.push_back(p);
  max_extent_ = std::max(max_extent_, std::hypot(b.half_length, b.half_width));
  ++count_;
}

size_t ShapeSet::size() const { return count_; }

}  // namespace mbot_sim
