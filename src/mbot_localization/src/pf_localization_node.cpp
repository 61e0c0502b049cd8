/**
 * @file pf_localization_node.cpp
 * @brief pf_localization: AMCL-like particle filter localization for one robot (run it in the
 *        robot's namespace). The filter itself is PfLocalizer (ROS-free); this file only wires
 *        topics, tf and parameters.
 *
 * Subscribes `/map` (nav_msgs/OccupancyGrid, latched), `scan` (sensor_msgs/LaserScan) and
 * `initialpose` (PoseWithCovarianceStamped, rviz "2D Pose Estimate"). Odometry and the laser
 * mount come from tf (`<ns>/odom -> <ns>/base_footprint -> ... -> <scan frame>`).
 * Publishes `amcl_pose` (PoseWithCovarianceStamped), `particlecloud` (PoseArray) and tf
 * `map -> <ns>/odom`, post-dated by ~transform_tolerance as amcl does.
 * Parameters use amcl's names; see config/localization.yaml for the list and their units.
 */
#include <cmath>
#include <map>
#include <memory>
#include <stdexcept>
#include <string>

#include <geometry_msgs/PoseArray.h>
#include <geometry_msgs/PoseWithCovarianceStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <message_filters/subscriber.h>
#include <nav_msgs/OccupancyGrid.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/message_filter.h>
#include <tf2_ros/transform_broadcaster.h>
#include <tf2_ros/transform_listener.h>

#include "mbot_localization/localization_core.h"
#include "mbot_localization/localization_ros.h"

namespace mbot_localization
{
class PfLocalizationNode
{
public:
  PfLocalizationNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : tf_listener_(tf_buffer_)
  {
    readParameters(pnh, nh);
    pose_pub_ = nh.advertise<geometry_msgs::PoseWithCovarianceStamped>("amcl_pose", 2, true);
    cloud_pub_ = nh.advertise<geometry_msgs::PoseArray>("particlecloud", 2, true);
    map_sub_ = nh.subscribe("/map", 1, &PfLocalizationNode::onMap, this);
    // As amcl: a scan is handed on once tf can place it in the odom frame at its stamp. Waiting
    // for that inside the callback would sleep in sim time, and under the simulator's lockstep
    // sim time waits for this node: both would wait until the simulator gives up.
    scan_sub_.subscribe(nh, "scan", 5, ros::TransportHints().tcpNoDelay());  // no Nagle wait (fake_localization)
    scan_filter_ =
        std::make_unique<tf2_ros::MessageFilter<sensor_msgs::LaserScan>>(scan_sub_, tf_buffer_, odom_frame_, 10, nh);
    scan_filter_->registerCallback(&PfLocalizationNode::onScan, this);
    initial_pose_sub_ = nh.subscribe("initialpose", 2, &PfLocalizationNode::onInitialPose, this);
    ROS_INFO("pf_localization: %s -> %s from %s, %d..%d particles, seed %u", global_frame_.c_str(), odom_frame_.c_str(),
             scan_sub_.getSubscriber().getTopic().c_str(), config_.filter.min_particles, config_.filter.max_particles,
             seed_);
  }

private:
  void readParameters(ros::NodeHandle& pnh, ros::NodeHandle& nh)
  {
    StrictParams p(pnh);
    const std::string robot = robotName(p, nh);
    global_frame_ = p.getString("global_frame_id", "map");
    odom_frame_ = p.getString("odom_frame_id", prefixedFrame(robot, "odom"));
    base_frame_ = p.getString("base_frame_id", prefixedFrame(robot, "base_footprint"));
    transform_tolerance_ = ros::Duration(p.getDouble("transform_tolerance", 0.1));
    tf_broadcast_ = p.getBool("tf_broadcast", true);
    seed_ = static_cast<uint32_t>(p.getInt("seed", 0));

    ParticleFilterConfig& f = config_.filter;
    f.min_particles = p.getInt("min_particles", f.min_particles);
    f.max_particles = p.getInt("max_particles", f.max_particles);
    f.particles_per_bin = p.getInt("particles_per_bin", f.particles_per_bin);
    config_.update_min_d = p.getDouble("update_min_d", config_.update_min_d);
    config_.update_min_a = p.getDouble("update_min_a", config_.update_min_a);
    config_.resample_interval = p.getInt("resample_interval", config_.resample_interval);
    config_.update_at_rest = p.getBool("update_at_rest", config_.update_at_rest);
    config_.recovery_alpha_slow = p.getDouble("recovery_alpha_slow", config_.recovery_alpha_slow);
    config_.recovery_alpha_fast = p.getDouble("recovery_alpha_fast", config_.recovery_alpha_fast);

    const std::string laser_model = p.getString("laser_model_type", "likelihood_field_prob");
    if (laser_model != "likelihood_field" && laser_model != "likelihood_field_prob")
      throw std::runtime_error("parameter " + pnh.resolveName("laser_model_type") +
                               ": expected \"likelihood_field\" or \"likelihood_field_prob\", got \"" + laser_model +
                               "\"");
    LaserModelConfig& l = config_.laser;
    l.product = laser_model == "likelihood_field_prob";
    l.z_hit = p.getDouble("laser_z_hit", l.z_hit);
    l.z_rand = p.getDouble("laser_z_rand", l.z_rand);
    l.sigma_hit = p.getDouble("laser_sigma_hit", l.sigma_hit);
    l.max_beams = p.getInt("laser_max_beams", l.max_beams);
    l.min_range = p.getDouble("laser_min_range", l.min_range);
    l.max_range = p.getDouble("laser_max_range", l.max_range);
    config_.likelihood_max_dist = p.getDouble("laser_likelihood_max_dist", config_.likelihood_max_dist);

    MotionModelConfig& m = config_.motion;
    m.type = parseOdomModelType(p.getString("odom_model_type", "diff"));
    m.alpha1 = p.getDouble("odom_alpha1", m.alpha1);
    m.alpha2 = p.getDouble("odom_alpha2", m.alpha2);
    m.alpha3 = p.getDouble("odom_alpha3", m.alpha3);
    m.alpha4 = p.getDouble("odom_alpha4", m.alpha4);
    m.alpha5 = p.getDouble("odom_alpha5", m.alpha5);

    initial_pose_.x = p.getDouble("initial_pose_x", 0.0);
    initial_pose_.y = p.getDouble("initial_pose_y", 0.0);
    initial_pose_.theta = p.getDouble("initial_pose_a", 0.0);
    initial_cov_.fill(0.0);
    initial_cov_[0] = p.getDouble("initial_cov_xx", 0.5 * 0.5);  // amcl's defaults
    initial_cov_[4] = p.getDouble("initial_cov_yy", 0.5 * 0.5);
    initial_cov_[8] = p.getDouble("initial_cov_aa", (M_PI / 12.0) * (M_PI / 12.0));
    p.checkNoUnknown();
    validateConfig(config_);  // now, not only when the map arrives
  }

  void onMap(const nav_msgs::OccupancyGrid& msg)
  {
    try
    {
      const OccupancyGridData map = toOccupancyGridData(msg);
      if (!localizer_)
      {
        // the first map: start the filter at the initial pose from the parameters (or from an
        // initialpose message that came before the map)
        localizer_ = std::make_unique<PfLocalizer>(config_, map, seed_);
        localizer_->setInitialPose(initial_pose_, initial_cov_);
      }
      else
        localizer_->setMap(map);
      ROS_INFO("pf_localization: map %u x %u at %.3f m/cell; initial pose (%.2f, %.2f, %.2f)", map.width, map.height,
               map.resolution, initial_pose_.x, initial_pose_.y, initial_pose_.theta);
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("pf_localization: ignoring the map: %s", e.what());
    }
  }

  void onInitialPose(const geometry_msgs::PoseWithCovarianceStamped& msg)
  {
    if (!msg.header.frame_id.empty() && msg.header.frame_id != global_frame_)
    {
      ROS_WARN("pf_localization: ignoring an initial pose in frame '%s'; it must be in '%s'",
               msg.header.frame_id.c_str(), global_frame_.c_str());
      return;
    }
    initial_pose_ = toPose2D(msg.pose.pose);
    initial_cov_.fill(0.0);
    initial_cov_[0] = msg.pose.covariance[0];   // xx
    initial_cov_[4] = msg.pose.covariance[7];   // yy
    initial_cov_[8] = msg.pose.covariance[35];  // yaw-yaw
    ROS_INFO("pf_localization: initial pose (%.2f, %.2f, %.2f)", initial_pose_.x, initial_pose_.y, initial_pose_.theta);
    if (localizer_) localizer_->setInitialPose(initial_pose_, initial_cov_);
  }

  /// The laser frame in the base frame; mounts are static, so each frame is looked up once.
  bool laserMount(const std::string& laser_frame, Pose2D& mount)
  {
    auto it = mounts_.find(laser_frame);
    if (it != mounts_.end())
    {
      mount = it->second;
      return true;
    }
    try
    {
      const geometry_msgs::TransformStamped t = tf_buffer_.lookupTransform(base_frame_, laser_frame, ros::Time(0));
      mount = toPose2D(t.transform);
      mounts_[laser_frame] = mount;
      ROS_INFO("pf_localization: laser %s at (%.3f, %.3f, %.3f) in %s", laser_frame.c_str(), mount.x, mount.y,
               mount.theta, base_frame_.c_str());
      return true;
    }
    catch (const tf2::TransformException& e)
    {
      ROS_WARN_THROTTLE(5.0, "pf_localization: no laser mount yet: %s", e.what());
      return false;
    }
  }

  void onScan(const sensor_msgs::LaserScan::ConstPtr& scan)
  {
    const sensor_msgs::LaserScan& msg = *scan;
    if (!localizer_)
    {
      ROS_WARN_THROTTLE(5.0, "pf_localization: waiting for the map on /map");
      return;
    }
    Pose2D mount, odom;
    if (!laserMount(msg.header.frame_id, mount)) return;
    try
    {
      odom = toPose2D(tf_buffer_.lookupTransform(odom_frame_, base_frame_, msg.header.stamp).transform);
    }
    catch (const tf2::TransformException& e)
    {
      ROS_WARN_THROTTLE(5.0, "pf_localization: no odometry at the scan's time: %s", e.what());
      return;
    }

    const size_t random_before = localizer_->randomParticles();
    if (localizer_->processScan(odom, toLaserScanData(msg), mount)) publishEstimate(msg.header.stamp);
    if (localizer_->randomParticles() > random_before)
      ROS_INFO_THROTTLE(2.0, "pf_localization: the scans fit the map worse than they did: %zu random particles",
                        localizer_->randomParticles() - random_before);

    // like amcl: re-send the last correction with every scan so that map -> odom stays fresh
    if (tf_broadcast_ && localizer_->hasEstimate())
    {
      geometry_msgs::TransformStamped tf;
      tf.header.stamp = msg.header.stamp + transform_tolerance_;
      tf.header.frame_id = global_frame_;
      tf.child_frame_id = odom_frame_;
      tf.transform = toTransformMsg(localizer_->mapToOdom());
      broadcaster_.sendTransform(tf);
    }
  }

  void publishEstimate(const ros::Time& stamp)
  {
    const PoseWithCovariance& e = localizer_->estimate();
    geometry_msgs::PoseWithCovarianceStamped pose;
    pose.header.stamp = stamp;
    pose.header.frame_id = global_frame_;
    pose.pose.pose = toPoseMsg(e.pose);
    // 3x3 (x, y, yaw) into the 6x6 (x, y, z, roll, pitch, yaw) layout
    const int rows[3] = {0, 1, 5};
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) pose.pose.covariance[rows[r] * 6 + rows[c]] = e.covariance[r * 3 + c];
    pose_pub_.publish(pose);

    geometry_msgs::PoseArray cloud;
    cloud.header = pose.header;
    cloud.poses.reserve(localizer_->particles().size());
    for (const Particle& particle : localizer_->particles()) cloud.poses.push_back(toPoseMsg(particle.pose));
    cloud_pub_.publish(cloud);
  }

  // settings
  PfLocalizerConfig config_;
  std::string global_frame_, odom_frame_, base_frame_;
  ros::Duration transform_tolerance_;
  bool tf_broadcast_ = true;
  uint32_t seed_ = 0;
  Pose2D initial_pose_;
  std::array<double, 9> initial_cov_{};

  // state
  std::unique_ptr<PfLocalizer> localizer_;  ///< created with the first map
  std::map<std::string, Pose2D> mounts_;

  tf2_ros::Buffer tf_buffer_;
  tf2_ros::TransformListener tf_listener_;
  tf2_ros::TransformBroadcaster broadcaster_;
  ros::Publisher pose_pub_, cloud_pub_;
  ros::Subscriber map_sub_, initial_pose_sub_;
  message_filters::Subscriber<sensor_msgs::LaserScan> scan_sub_;
  std::unique_ptr<tf2_ros::MessageFilter<sensor_msgs::LaserScan>> scan_filter_;  ///< after tf_buffer_: uses it
};

}  // namespace mbot_localization

int main(int argc, char** argv)
{
  ros::init(argc, argv, "pf_localization");
  ros::NodeHandle nh, pnh("~");
  try
  {
    mbot_localization::PfLocalizationNode node(nh, pnh);
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("pf_localization: %s", e.what());
    return 1;
  }
  return 0;
}
