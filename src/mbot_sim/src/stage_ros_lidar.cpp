/**
 * @file stage_ros_lidar.cpp
 * @brief StageRos: the 3D lidar's topic `/<ns>/points` (sensor_msgs/PointCloud2 with x, y, z,
 *        intensity and time, all float32) for robots whose world file entry has `lidar`. The
 *        world casts only while someone subscribes (wantsPoints()).
 */
#include "mbot_sim/stage_ros.h"

#include <sensor_msgs/PointField.h>

#include <cstddef>
#include <cstring>

namespace mbot_sim
{
void StageRos::addLidarIo(RobotIo& io, int robot)
{
  if (!world_->hasLidar(robot)) return;
  // 20: 2 s at 10 Hz, a frame is 400 kB at the default 20000 points.
  io.points = nh_.advertise<sensor_msgs::PointCloud2>(io.name + "/points", 20);
  sensor_msgs::PointCloud2& c = io.cloud_msg;
  c.header.frame_id = io.prefix + "lidar_link";
  c.height = 1;
  c.is_bigendian = false;
  c.is_dense = true;  // no NaN points: a ray without a return gives no point
  c.point_step = sizeof(LidarPoint);
  // The field names and types of the Velodyne point of the common LIO packages (FAST-LIO's
  // velodyne_ros::Point, LIO-SAM's VelodynePointXYZIRT): time is float32 seconds after the stamp.
  const char* names[] = {"x", "y", "z", "intensity", "time"};
  const uint32_t offsets[] = {offsetof(LidarPoint, x), offsetof(LidarPoint, y), offsetof(LidarPoint, z),
                              offsetof(LidarPoint, intensity), offsetof(LidarPoint, time)};
  c.fields.clear();
  for (int i = 0; i < 5; ++i)
  {
    sensor_msgs::PointField f;
    f.name = names[i];
    f.offset = offsets[i];
    f.datatype = sensor_msgs::PointField::FLOAT32;
    f.count = 1;
    c.fields.push_back(f);
  }
}

bool StageRos::wantsPoints(int robot) const
{
  return robot < static_cast<int>(io_.size()) && io_[robot] && io_[robot]->points.getNumSubscribers() > 0;
}

void StageRos::onPointCloud(int robot, const LidarFrame& frame)
{
  RobotIo& io = *io_[robot];
  if (!io.points) return;
  sensor_msgs::PointCloud2& c = io.cloud_msg;
  c.header.stamp.fromSec(frame.stamp);
  c.width = static_cast<uint32_t>(frame.points.size());
  c.row_step = c.width * c.point_step;
  c.data.resize(c.row_step);
  if (!frame.points.empty()) std::memcpy(c.data.data(), frame.points.data(), c.row_step);
  io.points.publish(c);
}

}  // namespace mbot_sim
