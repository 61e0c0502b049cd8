/**
 * @file localization_core.h
 * @brief What the localization nodes do, free of ROS types, so that it is tested without a
 *        master:
 *        - PfLocalizer: the AMCL-like cycle (motion update, laser update, resampling) driven by
 *          scans and odometry poses, with amcl's update thresholds;
 *        - GroundTruthMatcher: fake localization, pairing ground-truth and odometry samples by
 *          time stamp to compute map -> odom.
 */
#pragma once

#include <cstdint>
#include <deque>
#include <memory>
#include <optional>
#include <vector>

#include "mbot_localization/likelihood_field.h"
#include "mbot_localization/localization_math.h"
#include "mbot_localization/localization_models.h"
#include "mbot_localization/particle_filter.h"

namespace mbot_localization
{
/// @brief All settings of the particle filter localizer (amcl's names in the comments).
struct PfLocalizerConfig
{
  ParticleFilterConfig filter;
  MotionModelConfig motion;
  LaserModelConfig laser;
  double update_min_d = 0.2;         ///< update_min_d: travel [m] before a filter update
  double update_min_a = M_PI / 6.0;  ///< update_min_a: rotation [rad] before a filter update
  int resample_interval = 2;         ///< resample_interval: filter updates per resampling
  double likelihood_max_dist = 2.0;  ///< laser_likelihood_max_dist [m]
  /// update_at_rest (not in amcl): one more update when the robot stops after moving less than
  /// the thresholds, so that where it stands is judged by a scan taken there
  bool update_at_rest = true;
  /// estimate: mean of the heaviest particle cluster (true, as amcl) or of the whole set
  bool cluster_estimate = true;
  /// recovery_alpha_slow, recovery_alpha_fast (amcl's; 0: off, as amcl's defaults): averages of
  /// how well the scans fit the map, one slow and one fast; when the fast one drops below the
  /// slow one (the robot is likely lost), resampling puts 1 - w_fast / w_slow of the particles
  /// at random free poses of the map, so that the filter can find the robot again
  double recovery_alpha_slow = 0.0;
  double recovery_alpha_fast = 0.0;
  double rest_d = 0.001;  ///< [m] odometry change between two scans that counts as standing still
  double rest_a = 0.002;  ///< [rad]
};

/// @brief The AMCL-like localization cycle for one robot.
///
/// Feed it every scan with the odometry pose of the base at the scan's time. The filter runs
/// when the robot moved update_min_d or turned update_min_a since the last update, once right
/// after (re)initialization, and (update_at_rest) once when the robot comes to rest after moving
/// less than that. Between updates mapToOdom() keeps the last correction: the odometry carries
/// the motion since then.
class PfLocalizer
{
public:
  /// @throws std::invalid_argument for invalid settings
  PfLocalizer(const PfLocalizerConfig& config, const OccupancyGridData& map, uint32_t seed);

  /// @brief Replace the map (rebuilds the likelihood field); the particles are kept.
  void setMap(const OccupancyGridData& map);

  /// @brief (Re)initialize the particles around `pose` (map frame) with `covariance`
  ///        (xx, yy, theta-theta used). The next scan triggers a laser update.
  void setInitialPose(const Pose2D& pose, const std::array<double, 9>& covariance);

  /// @brief Process one scan. `odom_pose` is the base in the odom frame at the scan's time,
  ///        `laser_in_base` the laser mount. @return true when the filter was updated
  bool processScan(const Pose2D& odom_pose, const LaserScanData& scan, const Pose2D& laser_in_base);

  /// @brief True once an initial pose was set.
  bool initialized() const { return initialized_; }

  /// @brief True once a laser update ran after the last initialization, so that estimate()
  ///        and mapToOdom() mean something.
  bool hasEstimate() const { return has_estimate_; }

  /// @brief Pose estimate of the base in the map, from the last filter update.
  const PoseWithCovariance& estimate() const { return estimate_; }

  /// @brief map -> odom from the last filter update: estimate * inverse(odom pose then).
  Pose2D mapToOdom() const { return mbot_localization::mapToOdom(estimate_.pose, odom_at_estimate_); }

  /// @brief Filter updates and resamplings done so far (for logs and tests).
  int updates() const { return updates_; }

  /// @brief The recovery's state (for logs and tests): the last scan's fit (see
  ///        LikelihoodFieldModel::apply), its slow and fast averages, and the random particles
  ///        put in so far.
  double lastFit() const { return last_fit_; }
  double wSlow() const { return w_slow_; }
  double wFast() const { return w_fast_; }
  size_t randomParticles() const { return random_particles_; }

  const std::vector<Particle>& particles() const { return filter_.particles(); }
  const PfLocalizerConfig& config() const { return config_; }
  const LikelihoodField& field() const { return *field_; }

private:
  bool recoveryEnabled() const { return config_.recovery_alpha_slow > 0.0 && config_.recovery_alpha_fast > 0.0; }
  /// The free cells of the map (indices into the likelihood field), for random poses; none
  /// while the recovery is off.
  void collectFreeCells();
  /// A pose uniformly drawn over the free cells and headings.
  Pose2D randomFreePose(std::mt19937& rng) const;

  PfLocalizerConfig config_;
  std::shared_ptr<const LikelihoodField> field_;
  std::vector<size_t> free_cells_;
  ParticleFilter filter_;
  OdomMotionModel motion_;
  LikelihoodFieldModel laser_;

  bool initialized_ = false;
  bool has_estimate_ = false;
  bool force_update_ = false;  ///< set by setInitialPose: update on the next scan
  Pose2D last_odom_;           ///< odometry pose at the last filter update
  Pose2D previous_scan_odom_;  ///< odometry pose at the previous scan
  bool have_previous_scan_ = false;
  PoseWithCovariance estimate_;
  Pose2D odom_at_estimate_;
  int updates_ = 0;
  int updates_since_init_ = 0;
  double last_fit_ = 0.0;
  double w_slow_ = 0.0;  ///< 0: not started (the next fit starts it, as amcl)
  double w_fast_ = 0.0;
  size_t random_particles_ = 0;
};

/// @brief Check every setting of `config` (the constructors of the filter and its models do).
/// @throws std::invalid_argument naming the first bad setting
void validateConfig(const PfLocalizerConfig& config);

/// @brief A pose with a time stamp [ns] (integer, so that equal stamps compare equal).
struct StampedPose
{
  int64_t stamp_ns = 0;
  Pose2D pose;
};

/// @brief Fake localization: pairs ground truth (base in map) and odometry (base in odom)
///        samples taken at the same time and gives T_map_odom = T_map_base * inverse(T_odom_base).
///
/// The simulator stamps both with the same sim time, but they arrive on different topics in any
/// order. Odometry samples wait until the ground truth at their stamp is known: an equal stamp
/// (within `match_tolerance_ns`) is used as is, otherwise the ground truth is interpolated
/// between the samples just before and after. Samples older than `buffer_ns` are dropped, and
/// a stamp older than its topic's previous one (sim time jumped back) clears both buffers.
class GroundTruthMatcher
{
public:
  /// @param buffer_ns how long samples are kept [ns]; match_tolerance_ns: "same stamp" [ns]
  explicit GroundTruthMatcher(int64_t buffer_ns = 2000000000, int64_t match_tolerance_ns = 1000);

  void addGroundTruth(const StampedPose& map_base);
  void addOdometry(const StampedPose& odom_base);

  /// @brief A matched pair: the odometry stamp, ground truth at that stamp and map -> odom.
  struct Match
  {
    int64_t stamp_ns;
    Pose2D map_base;
    Pose2D odom_base;
    Pose2D map_odom;
  };

  /// @brief Every odometry sample that can be matched now, oldest first (removed from the queue).
  std::vector<Match> takeMatches();

  size_t pendingOdometry() const { return odom_.size(); }

  /// @brief How often time jumped back and the buffers were cleared.
  int timeJumps() const { return time_jumps_; }

private:
  void append(std::deque<StampedPose>& samples, int64_t& last_stamp_ns, const StampedPose& sample);
  /// Ground truth at `stamp_ns`, or nothing when it is not known (yet).
  std::optional<Pose2D> groundTruthAt(int64_t stamp_ns) const;
  void prune();

  int64_t buffer_ns_;
  int64_t tolerance_ns_;
  std::deque<StampedPose> truth_;      ///< ascending stamps
  std::deque<StampedPose> odom_;       ///< waiting for their ground truth, ascending stamps
  int64_t last_truth_ns_ = INT64_MIN;  ///< newest stamp seen on each topic
  int64_t last_odom_ns_ = INT64_MIN;
  int time_jumps_ = 0;
};

}  // namespace mbot_localization
