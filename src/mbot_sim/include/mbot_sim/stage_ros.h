/**
 * @file stage_ros.h
 * @brief The ROS side of stage_node: reads the parameters once, builds the World from a world
 *        file, owns sim time (/clock, real-time factor, pause), converts sensor samples to
 *        messages and serves the run-time API, with live tuning of the real-time factor and the
 *        noise (dynamic_reconfigure, cfg/Simulator.cfg). All simulation logic lives in World.
 */
#pragma once

#include "mbot_sim/world.h"

#include <dynamic_reconfigure/server.h>
#include <geometry_msgs/Pose.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <geometry_msgs/Twist.h>
#include <mbot_msgs/AppliedCommands.h>
#include <mbot_msgs/RobotStates.h>
#include <mbot_msgs/RemoveObstacle.h>
#include <mbot_msgs/RemoveRobot.h>
#include <mbot_msgs/SetFault.h>
#include <mbot_msgs/SpawnObstacle.h>
#include <mbot_msgs/SpawnRobot.h>
#include <mbot_msgs/TeleportRobot.h>
#include <mbot_sim/SimulatorConfig.h>
#include <nav_msgs/Odometry.h>
#include <ros/ros.h>
#include <sensor_msgs/Imu.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/LaserScan.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Header.h>
#include <std_srvs/Empty.h>
#include <tf2_msgs/TFMessage.h>

#include <boost/thread/recursive_mutex.hpp>

#include <map>
#include <memory>
#include <stdexcept>
#include <string>
#include <vector>

namespace mbot_sim
{
/// @brief A startup problem (bad world file, missing parameter): main() prints it with
///        ROS_FATAL as one line and exits non-zero.
class StartupError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// @brief Parameters of stage_node, read once at startup.
struct StageParams
{
  std::string world;     ///< ~world: a world name (maps/NAME.world.yaml) or a path
  std::string maps_dir;  ///< ~maps_dir: where bare world names are looked up first
  bool has_real_time_factor = false;
  double real_time_factor = 1.0;  ///< ~real_time_factor: overrides the world file's when set
  bool has_seed = false;
  int seed = 0;                                 ///< ~seed: overrides the world file's when set
  double watchdog_timeout = 0.2;                ///< ~base_watchdog_timeout [s sim time]
  double marker_rate = 10.0;                    ///< ~marker_rate: /stage/markers for moving obstacles [Hz sim time]
  double clock_rate = 0.0;                      ///< ~clock_rate: /clock at most this often [Hz sim time], on
                                                ///< multiples of its period and at lockstep boundaries; 0: every step
  double wheel_tf_rate = 10.0;                  ///< ~wheel_tf_rate: <ns>/base_link -> <ns>/<wheel> on /tf [Hz sim
                                                ///< time]; 0: not published (robot_state_publisher from joint_states)
  bool lockstep = false;                        ///< ~lockstep: hold sim time at period boundaries for the controllers
  double lockstep_period = 0.05;                ///< ~lockstep_period: distance of the boundaries [s sim time]
  double lockstep_active_timeout = 0.5;         ///< ~lockstep_active_timeout: a robot is driven while its
                                                ///< last cmd_vel is at most this old [s sim time]
  double lockstep_wall_timeout = 2.0;           ///< ~lockstep_wall_timeout: longest wait at a boundary [s wall]
  double lockstep_localization_lag = 0.1;       ///< ~lockstep_localization_lag: each robot's localization
                                                ///< (map -> <ns>/odom on /tf) may lag sim time this much [s sim]
  double lockstep_localization_postdate = 0.1;  ///< ~lockstep_localization_postdate: the localizations post-date
                                                ///< map -> <ns>/odom by this much (their transform_tolerance) [s]
  double lockstep_pacer_lag = 0.3;              ///< ~lockstep_pacer_lag: a node that paces sim time (a heartbeat on
                                                ///< /lockstep/heartbeat) may lag it this much [s sim]
  std::string lockstep_report;                  ///< ~lockstep_report: at the end, the waits' summary to this file
};

/// @brief Read the private parameters. @throws StartupError for a missing world or a bad value
StageParams readStageParams(const ros::NodeHandle& private_nh);

/// @brief stage_node: one World, its topics, tf and services.
class StageRos : public SensorListener
{
public:
  /// @brief Load the world and advertise everything. @throws StartupError
  StageRos(const ros::NodeHandle& nh, const StageParams& params);

  /// @brief Step the world until shutdown, paced by the real-time factor (0: as fast as
  ///        possible); callbacks and services are served between steps, on this thread.
  ///        With ~lockstep, sim time also waits for the driven robots' controllers and every
  ///        robot's localization at each ~lockstep_period boundary (see waitForControllers()).
  void run();

  // SensorListener: called by World::step()
  void onOdometry(int robot, const OdometrySample& sample) override;
  void onGroundTruth(int robot, const GroundTruthSample& sample) override;
  void onJointState(int robot, const JointStateSample& sample) override;
  void onScan(int robot, const ScanSample& sample) override;
  bool wantsPoints(int robot) const override;  ///< someone subscribes to its points topic
  void onPointCloud(int robot, const LidarFrame& frame) override;
  bool wantsImu(int robot) const override;  ///< someone subscribes to its imu topic
  void onImu(int robot, const ImuSample& sample) override;
  void onContact(const ContactEvent& event) override;

private:
  /// Publishers, subscribers and reusable messages of one robot.
  struct RobotIo
  {
    std::string name;
    std::string prefix;  ///< "<name>/" for frame ids
    ros::Publisher odom, ground_truth, scan, joint_states;
    ros::Subscriber cmd_vel, cmd_pose, cmd_pose_stamped;
    nav_msgs::Odometry odom_msg, ground_truth_msg;
    sensor_msgs::LaserScan scan_msg;
    sensor_msgs::JointState joint_msg;
    geometry_msgs::TransformStamped odom_tf;
    ros::Publisher points;  ///< only for a robot with a 3D lidar (stage_ros_lidar.cpp)
    sensor_msgs::PointCloud2 cloud_msg;
    ros::Publisher imu;  ///< only for a model with an imu_link; samples only while subscribed
    sensor_msgs::Imu imu_msg;
    std::vector<geometry_msgs::TransformStamped> wheel_tf;  ///< parent link -> wheel, one per wheel joint
    double next_wheel_tf = 0.0;                             ///< sim time the wheels go out next [s]
    double last_cmd_time = -1e9;        ///< sim time of the last cmd_vel [s]; -1e9: never, or dropped
    long cmd_boundary = -1;             ///< boundary_count_ when the last cmd_vel arrived
    bool cmd_unused = false;            ///< lockstep: the last cmd_vel has not released a boundary yet
    ros::WallTime last_cmd_wall;        ///< lockstep: wall time of the last cmd_vel
    bool cmd_zero = false;              ///< lockstep: the last cmd_vel was all zeros (a stop)
    int zeros_at_rest = 0;              ///< lockstep: zero cmd_vels in a row that found the robot at rest
    bool cmd_pending = false;           ///< /stage/applied_commands: a cmd_vel no step has used yet
    double cmd_received = 0.0;          ///< ... the sim time it arrived [s]
    geometry_msgs::Twist cmd_msg;       ///< ... as received
    double localization_stamp = -1e9;   ///< lockstep: newest stamp of a transform to <ns>/odom [s]
    bool localization_ignored = false;  ///< lockstep: its localization timed out; not waited for
                                        ///< until it has caught up
  };

  const mbot_description::RobotModel& model(const std::string& name);
  void addRobotIo(int robot);
  /// The 3D lidar's topic and the cloud's fixed fields, for a robot that has one.
  void addLidarIo(RobotIo& io, int robot);
  void publishRobotList();
  void publishMarkers();
  void publishClock();
  void noteAppliedCommands();
  void publishAppliedCommands();
  void noteBoundary();
  bool waitForControllers();

  void onCmdVel(int robot, const geometry_msgs::Twist::ConstPtr& msg);
  void onTf(const tf2_msgs::TFMessage::ConstPtr& msg);
  void onHeartbeat(const std_msgs::Header::ConstPtr& msg);
  bool localizationCurrent(const RobotIo& io) const;
  static bool stopped(const RobotIo& io);
  /// cmd_pose and cmd_pose_stamped (`topic` names which, for the log).
  void onCmdPose(int robot, const geometry_msgs::Pose& pose, const char* topic);
  bool onReset(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool onPause(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool onUnpause(std_srvs::Empty::Request& req, std_srvs::Empty::Response& res);
  bool onSpawn(mbot_msgs::SpawnRobot::Request& req, mbot_msgs::SpawnRobot::Response& res);
  bool onRemove(mbot_msgs::RemoveRobot::Request& req, mbot_msgs::RemoveRobot::Response& res);
  bool onSpawnObstacle(mbot_msgs::SpawnObstacle::Request& req, mbot_msgs::SpawnObstacle::Response& res);
  bool onRemoveObstacle(mbot_msgs::RemoveObstacle::Request& req, mbot_msgs::RemoveObstacle::Response& res);
  bool onTeleport(mbot_msgs::TeleportRobot::Request& req, mbot_msgs::TeleportRobot::Response& res);
  bool onSetFault(mbot_msgs::SetFault::Request& req, mbot_msgs::SetFault::Response& res);
  /// Live tuning (cfg/Simulator.cfg): start the server with the values in force.
  void startReconfigureServer();
  void onReconfigure(SimulatorConfig& config);

  ros::NodeHandle nh_;
  StageParams params_;
  std::string description_dir_;  ///< mbot_description package path
  std::map<std::string, mbot_description::RobotModel> models_;
  std::unique_ptr<World> world_;
  double real_time_factor_ = 1.0;
  bool paused_ = false;
  bool pacing_reset_ = true;  ///< re-anchor wall time to sim time (after start, pause, lag)

  std::vector<std::unique_ptr<RobotIo>> io_;  ///< by robot id; nullptr for removed robots
  ros::Publisher clock_pub_, contact_pub_, marker_pub_;
  ros::Subscriber tf_sub_;         ///< lockstep only: the robots' localization transforms
  ros::Subscriber heartbeat_sub_;  ///< lockstep only: nodes that pace sim time (the fleet coordinator)
  std::vector<ros::ServiceServer> services_;
  // dynamic_reconfigure at ~: its set_parameters service is served by run()'s callback queue, on
  // the loop's thread between two steps, like every other service here; no step runs meanwhile.
  boost::recursive_mutex reconfigure_mutex_;  ///< given to the server, so that updateConfig() is safe
  std::unique_ptr<dynamic_reconfigure::Server<SimulatorConfig>> reconfigure_server_;
  ros::Publisher tf_pub_;                                  ///< /tf: the robots' odom and wheel transforms
  std::vector<geometry_msgs::TransformStamped> tf_batch_;  ///< all transforms of one step
  // /stage/ground_truth: every robot's ground truth of one step in one message, while subscribed
  ros::Publisher fleet_truth_pub_;
  bool report_fleet_truth_ = false;     ///< someone subscribes (checked after each step)
  mbot_msgs::RobotStates fleet_truth_;  ///< this step's ground truth samples
  double next_marker_time_ = 0.0;
  // /stage/applied_commands (end-to-end control latency): every robot's cmd_vels as the steps used them
  ros::Publisher applied_pub_;
  bool report_applied_ = false;     ///< someone subscribes (checked at each publication)
  double next_applied_time_ = 0.0;  ///< the next message when sim time reaches this [s]
  mbot_msgs::AppliedCommands applied_batch_;
  double next_clock_time_ = 0.0;  ///< ~clock_rate: /clock when sim time reaches this
  ros::WallTime next_marker_wall_;

  // lockstep (see waitForControllers())
  long boundary_count_ = 0;             ///< boundaries published so far
  double next_boundary_ = 0.0;          ///< sim time of the next boundary [s]
  bool boundary_wait_pending_ = false;  ///< a boundary was published and not yet waited at
  /// A node that sim time waits for besides the controllers: its newest heartbeat stamp [s sim],
  /// and whether it timed out (not waited for until it has caught up by itself).
  struct Pacer
  {
    double stamp = -1e9;
    bool ignored = false;
    ros::WallTime moved;  ///< wall time the stamp last moved on
  };
  std::map<std::string, Pacer> pacers_;             ///< by node name (the heartbeat's frame_id)
  long lockstep_timeouts_ = 0;                      ///< wall timeouts since the last warning
  long lockstep_timeouts_total_ = 0;                ///< wall timeouts since the start (logged at the end)
  double lockstep_wait_total_ = 0.0;                ///< wall time spent waiting at boundaries [s]
  std::map<std::string, double> lockstep_wait_by_;  ///< ... charged to the last to answer [s]
  std::string lockstepWaitSummary(double run_wall) const;
  ros::WallTime last_lockstep_warning_;
};

}  // namespace mbot_sim
