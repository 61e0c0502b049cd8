/**
 * @file localization_models.h
 * @brief The two models of the particle filter, free of ROS types: the odometry motion model
 *        (how particles move) and the likelihood-field laser model (how well a scan fits a
 *        particle). Parameter names follow amcl so that amcl configurations carry over.
 */
#pragma once

#include <memory>
#include <random>
#include <string>
#include <vector>

#include "mbot_localization/likelihood_field.h"
#include "mbot_localization/localization_math.h"

namespace mbot_localization
{
/// @brief One hypothesis of the robot pose (base frame in the map) and its importance weight.
struct Particle
{
  Pose2D pose;
  double weight = 0.0;
};

/// @brief Odometry model kind (amcl's odom_model_type).
enum class OdomModelType
{
  DIFF,  ///< differential drive: rotate, translate, rotate (amcl "diff-corrected")
  OMNI   ///< holonomic: translate along a bearing, strafe, rotate (amcl "omni-corrected")
};

/// @brief Parse amcl's odom_model_type: "diff" or "omni" (the "-corrected" spellings are
///        accepted as the same models). @throws std::invalid_argument for anything else
OdomModelType parseOdomModelType(const std::string& name);

/// @brief Noise of the odometry model, amcl's odom_alpha1..5 (dimensionless variance factors).
struct MotionModelConfig
{
  OdomModelType type = OdomModelType::DIFF;
  double alpha1 = 0.2;  ///< rotation noise from rotation
  double alpha2 = 0.2;  ///< rotation noise from translation
  double alpha3 = 0.2;  ///< translation noise from translation
  double alpha4 = 0.2;  ///< translation noise from rotation
  double alpha5 = 0.2;  ///< strafe noise from translation (omni only)
};

/// @brief Sample-based odometry motion model (Probabilistic Robotics, table 5.6), as amcl's
///        "diff-corrected" and "omni-corrected" models.
///
/// The motion between two odometry poses is applied to every particle in the particle's own
/// frame, with zero-mean Gaussian noise whose variance grows with the size of the motion.
class OdomMotionModel
{
public:
  explicit OdomMotionModel(const MotionModelConfig& config);

  /// @brief Move all particles by the odometry change from `odom_old` to `odom_new` (both the
  ///        base pose in the odom frame [m, m, rad]), drawing noise from `rng`.
  void apply(const Pose2D& odom_old, const Pose2D& odom_new, std::vector<Particle>& particles, std::mt19937& rng) const;

  const MotionModelConfig& config() const { return config_; }

private:
  void applyDiff(const Pose2D& odom_old, const Pose2D& odom_new, std::vector<Particle>& particles,
                 std::mt19937& rng) const;
  void applyOmni(const Pose2D& odom_old, const Pose2D& odom_new, std::vector<Particle>& particles,
                 std::mt19937& rng) const;

  MotionModelConfig config_;
};

/// @brief A planar laser scan, REP-117 ranges (+Inf: no return, -Inf: too close, NaN: invalid).
struct LaserScanData
{
  std::vector<float> ranges;     ///< [m]
  double angle_min = 0.0;        ///< angle of ranges[0] in the laser frame [rad]
  double angle_increment = 0.0;  ///< [rad]
  double range_min = 0.0;        ///< [m]
  double range_max = 0.0;        ///< [m]
};

/// @brief Parameters of the likelihood-field model, amcl's laser_* names.
struct LaserModelConfig
{
  double z_hit = 0.95;      ///< laser_z_hit: weight of the Gaussian "hit" part
  double z_rand = 0.05;     ///< laser_z_rand: weight of the uniform "random reading" part
  double sigma_hit = 0.2;   ///< laser_sigma_hit: std dev of the hit Gaussian [m]
  int max_beams = 30;       ///< laser_max_beams: beams used per scan (evenly spread)
  double min_range = -1.0;  ///< laser_min_range [m]; <= 0: use the scan's range_min
  double max_range = -1.0;  ///< laser_max_range [m]; <= 0: use the scan's range_max
  /// laser_model_type likelihood_field_prob (true) or likelihood_field (false): how the beams'
  /// scores combine, see LikelihoodFieldModel::likelihood()
  bool product = true;
  /// score by LikelihoodField::surfaceDistance (true) or amcl's cell distance (false)
  bool surface_distance = true;
};

/// @brief Likelihood-field laser model (Probabilistic Robotics, table 6.3), as amcl's
///        likelihood_field and likelihood_field_prob models: a beam end point at distance d from
///        the nearest obstacle scores p = z_hit * exp(-d^2 / (2 sigma_hit^2)) + z_rand / range_max.
class LikelihoodFieldModel
{
public:
  /// @throws std::invalid_argument for a null field or out-of-range parameters
  LikelihoodFieldModel(const LaserModelConfig& config, std::shared_ptr<const LikelihoodField> field);

  /// @brief Multiply every particle's weight by the likelihood of `scan` seen from it.
  /// @param laser_in_base the laser frame in the robot's base frame [m, m, rad]
  /// @param fit if not null: how well the scan fits the map as seen from the particles, the
  ///        weighted mean (by the weights before the update, which must sum to 1) of each
  ///        particle's per-beam geometric mean likelihood, in (0, 1]; NaN without usable beams.
  ///        The recovery (amcl's w_slow/w_fast) follows it.
  /// @return the sum of the new weights (all likelihoods are scaled by the best one's, so that
  ///         many beams do not underflow; normalizing the weights cancels the scale)
  double apply(const LaserScanData& scan, const Pose2D& laser_in_base, std::vector<Particle>& particles,
               double* fit = nullptr) const;

  /// @brief The (unnormalized) likelihood of `scan` for one robot pose in the map.
  ///
  /// With `product` (amcl's likelihood_field_prob) the beam scores multiply, as independent
  /// beams do; laser_max_beams bounds how confident that makes the filter. Without it (amcl's
  /// likelihood_field) they combine as 1 + sum(p^3): that score changes only a few per cent for a
  /// pose a few centimetres off, so the particles hardly converge closer than that.
  double likelihood(const LaserScanData& scan, const Pose2D& laser_in_base, const Pose2D& base_in_map) const;

  /// @brief log(likelihood()), without its overflow or underflow for many beams.
  double logLikelihood(const LaserScanData& scan, const Pose2D& laser_in_base, const Pose2D& base_in_map) const;

  const LaserModelConfig& config() const { return config_; }
  const LikelihoodField& field() const { return *field_; }

private:
  LaserModelConfig config_;
  std::shared_ptr<const LikelihoodField> field_;
};

}  // namespace mbot_localization
