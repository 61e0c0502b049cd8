/**
 * @file particle_filter.h
 * @brief A particle set for planar localization, free of ROS types: Gaussian initialization,
 *        low-variance resampling with a fixed or adaptive particle count, and the pose estimate
 *        (weighted mean and covariance). The models that move and weigh the particles are in
 *        localization_models.h; PfLocalizer (localization_core.h) runs the whole cycle.
 */
#pragma once

#include <cstdint>
#include <functional>
#include <random>
#include <vector>

#include "mbot_localization/localization_math.h"
#include "mbot_localization/localization_models.h"

namespace mbot_localization
{
/// @brief Size of the particle set (amcl's min_particles/max_particles).
///
/// Instead of amcl's KLD sampling the count adapts with a simpler rule: after resampling, the
/// particles are sorted into bins of bin_size_xy x bin_size_xy x bin_size_theta and the next set
/// gets particles_per_bin particles per occupied bin, clamped to [min_particles, max_particles].
/// A spread-out (uncertain) set covers many bins and keeps many particles; a converged set
/// shrinks to min_particles. min_particles == max_particles gives a fixed count.
struct ParticleFilterConfig
{
  int min_particles = 100;
  int max_particles = 5000;
  int particles_per_bin = 50;
  double bin_size_xy = 0.5;                     ///< [m] (amcl's pf histogram bins)
  double bin_size_theta = 10.0 * M_PI / 180.0;  ///< [rad]
};

/// @brief The particle set and the operations on it that do not depend on the models.
class ParticleFilter
{
public:
  /// @throws std::invalid_argument for inconsistent counts or bin sizes
  ParticleFilter(const ParticleFilterConfig& config, uint32_t seed);

  /// @brief Replace the set by max_particles particles drawn from a Gaussian around `mean`,
  ///        with the variances of `covariance` (xx, yy, theta-theta; cross terms are ignored).
  void initGaussian(const Pose2D& mean, const std::array<double, 9>& covariance);

  /// @brief Scale the weights to sum to 1 (uniform when they sum to 0 or are not finite).
  void normalizeWeights();

  /// @brief Draw a new set with low-variance (systematic) resampling and adapt its size; the
  ///        new particles have equal weights.
  /// @param random_fraction each new particle is instead a pose from `random_pose` with this
  ///        probability (amcl's recovery; 0: none)
  /// @return the number of random particles
  size_t resample(double random_fraction = 0.0, const std::function<Pose2D(std::mt19937&)>& random_pose = {});

  /// @brief Weighted mean pose and covariance of the set (circular mean for the heading).
  PoseWithCovariance estimate() const;

  /// @brief Weighted mean pose and covariance of the heaviest cluster, as amcl reports: the
  ///        particles are binned (ParticleFilterConfig's bins) and touching bins (also across
  ///        the +-pi seam) form a cluster. When the set holds two hypotheses, the whole set's
  ///        mean lies between them, where the robot is not.
  PoseWithCovariance bestClusterEstimate() const;

  /// @brief The cluster of each particle (see bestClusterEstimate()), numbered from 0.
  std::vector<size_t> clusters(size_t& count) const;

  /// @brief Number of occupied bins (see ParticleFilterConfig) of the current set.
  size_t occupiedBins() const;

  std::vector<Particle>& particles() { return particles_; }
  const std::vector<Particle>& particles() const { return particles_; }
  std::mt19937& rng() { return rng_; }
  const ParticleFilterConfig& config() const { return config_; }

private:
  size_t countBins(const std::vector<size_t>& indices) const;
  /// Weighted mean and covariance of the particles whose `member` flag is set.
  PoseWithCovariance meanOf(const std::vector<bool>& member) const;

  ParticleFilterConfig config_;
  std::mt19937 rng_;
  std::vector<Particle> particles_;
};

/// @brief Low-variance (systematic) resampling: `count` indices into `weights` (normalized),
///        drawn with one random offset so that index i is picked floor or ceil of
///        count * weights[i] times.
std::vector<size_t> lowVarianceSample(const std::vector<double>& weights, size_t count, std::mt19937& rng);

}  // namespace mbot_localization
