#include "mbot_navigation/ros/shared_tf.h"

#include <mutex>

namespace mbot_navigation
{
namespace
{
std::mutex mutex;
std::weak_ptr<tf2_ros::Buffer> shared_buffer;
std::weak_ptr<tf2_ros::TransformListener> shared_listener;
}  // namespace

std::shared_ptr<tf2_ros::Buffer> SharedTf::buffer()
{
  std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<tf2_ros::Buffer> buffer = shared_buffer.lock();
  if (!buffer)
  {
    buffer = std::make_shared<tf2_ros::Buffer>(ros::Duration(10.0));
    shared_buffer = buffer;
  }
  return buffer;
}

std::shared_ptr<tf2_ros::TransformListener> SharedTf::listen()
{
  std::shared_ptr<tf2_ros::Buffer> buffer = SharedTf::buffer();
  std::lock_guard<std::mutex> lock(mutex);
  std::shared_ptr<tf2_ros::TransformListener> listener = shared_listener.lock();
  if (!listener)
  {
    // What the buffer holds is from before the last listener stopped: stale. Cleared here, under
    // the lock and before the new listener subscribes (its latched /tf_static comes after), not
    // when the old one goes: that may be in another thread after a new listener has started.
    buffer->clear();
    // The deleter holds the buffer: it outlives its listener.
    listener.reset(new tf2_ros::TransformListener(*buffer), [buffer](tf2_ros::TransformListener* l) { delete l; });
    shared_listener = listener;
  }
  return listener;
}

}  // namespace mbot_navigation
