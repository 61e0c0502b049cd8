/**
 * @file shared_tf.h
 * @brief One tf2 buffer per process, and one listener that feeds it while someone needs it.
 *
 * Nav nodes loaded as nodelets into one manager share them: the fleet's /tf arrives once per
 * manager and each transform is inserted once, whatever the number of robots in it. In a process
 * of its own (the nav_node executable) the buffer and the listener are the node's alone.
 */
#pragma once

#include <memory>

#include <tf2_ros/buffer.h>
#include <tf2_ros/transform_listener.h>

namespace mbot_navigation
{
/// @brief The process's shared tf2 buffer and listener (see the file comment). Thread-safe.
class SharedTf
{
public:
  /// @brief The process's buffer (10 s of history), made at the first call.
  static std::shared_ptr<tf2_ros::Buffer> buffer();
  /**
   * @brief Keep the buffer fed: the listener (subscribing /tf and /tf_static) lives while one of
   *        the handles returned here lives. When the last one goes, the listener stops; a new one
   *        starts on a cleared buffer (the old data is stale; /tf_static comes again, latched).
   */
  static std::shared_ptr<tf2_ros::TransformListener> listen();
};

}  // namespace mbot_navigation
