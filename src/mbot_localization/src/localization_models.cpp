#include "mbot_localization/localization_models.h"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace mbot_localization
{
OdomModelType parseOdomModelType(const std::string& name)
{
  if (name == "diff" || name == "diff-corrected") return OdomModelType::DIFF;
  if (name == "omni" || name == "omni-corrected") return OdomModelType::OMNI;
  throw std::invalid_argument("odom_model_type: expected \"diff\" or \"omni\", got \"" + name + "\"");
}

// ---------------------------------------------------------------- odometry motion model

OdomMotionModel::OdomMotionModel(const MotionModelConfig& config) : config_(config)
{
  const double alphas[] = {config.alpha1, config.alpha2, config.alpha3, config.alpha4, config.alpha5};
  for (int i = 0; i < 5; ++i)
    if (!(alphas[i] >= 0.0))
      throw std::invalid_argument("odom_alpha" + std::to_string(i + 1) + ": expected >= 0, got " +
                                  std::to_string(alphas[i]));
}

void OdomMotionModel::apply(const Pose2D& odom_old, const Pose2D& odom_new, std::vector<Particle>& particles,
                            std::mt19937& rng) const
{
  if (config_.type == OdomModelType::DIFF)
    applyDiff(odom_old, odom_new, particles, rng);
  else
    applyOmni(odom_old, odom_new, particles, rng);
}

namespace
{
/// A zero-mean Gaussian sample with std dev `sigma`; exactly 0 when sigma is 0 (no draw), so
/// that a noise-free model moves particles exactly.
double gaussian(double sigma, std::mt19937& rng)
{
  if (sigma <= 0.0) return 0.0;
  return std::normal_distribution<double>(0.0, sigma)(rng);
}
}  // namespace

void OdomMotionModel::applyDiff(const Pose2D& odom_old, const Pose2D& odom_new, std::vector<Particle>& particles,
                                std::mt19937& rng) const
{
  // The odometry motion as rotate (rot1), translate (trans), rotate (rot2), in the old pose.
  const double dx = odom_new.x - odom_old.x;
  const double dy = odom_new.y - odom_old.y;
  const double trans = std::hypot(dx, dy);
  const double rot1 = trans > 0.0 ? angleDiff(std::atan2(dy, dx), odom_old.theta) : 0.0;
  const double rot2 = angleDiff(angleDiff(odom_new.theta, odom_old.theta), rot1);

  // Noise sizes, as amcl: a very short translation has an ill-defined direction, so its rot1
  // counts as no rotation (all turning is rot2); and driving backwards (rot1 near pi) is not a
  // half turn, so a rotation counts by its distance to 0 or pi, whichever is smaller.
  const bool short_move = trans < 0.01;  // [m]
  const auto rotation_size = [](double r) { return std::min(std::fabs(r), std::fabs(angleDiff(r, M_PI))); };
  const double rot1_size = short_move ? 0.0 : rotation_size(rot1);
  const double rot2_size = rotation_size(short_move ? angleDiff(odom_new.theta, odom_old.theta) : rot2);
  const MotionModelConfig& a = config_;
  const double sigma_rot1 = std::sqrt(a.alpha1 * rot1_size * rot1_size + a.alpha2 * trans * trans);
  const double sigma_trans =
      std::sqrt(a.alpha3 * trans * trans + a.alpha4 * rot1_size * rot1_size + a.alpha4 * rot2_size * rot2_size);
  const double sigma_rot2 = std::sqrt(a.alpha1 * rot2_size * rot2_size + a.alpha2 * trans * trans);

  for (Particle& p : particles)
  {
    const double rot1_hat = rot1 - gaussian(sigma_rot1, rng);
    const double trans_hat = trans - gaussian(sigma_trans, rng);
    const double rot2_hat = rot2 - gaussian(sigma_rot2, rng);
    p.pose.x += trans_hat * std::cos(p.pose.theta + rot1_hat);
    p.pose.y += trans_hat * std::sin(p.pose.theta + rot1_hat);
    p.pose.theta = normalizeAngle(p.pose.theta + rot1_hat + rot2_hat);
  }
}

void OdomMotionModel::applyOmni(const Pose2D& odom_old, const Pose2D& odom_new, std::vector<Particle>& particles,
                                std::mt19937& rng) const
{
  // The odometry motion as a translation along a bearing (relative to the old heading) and a
  // rotation; the robot may also slip sideways (strafe).
  const double dx = odom_new.x - odom_old.x;
  const double dy = odom_new.y - odom_old.y;
  const double trans = std::hypot(dx, dy);
  const double rot = angleDiff(odom_new.theta, odom_old.theta);
  const double bearing = trans > 0.0 ? angleDiff(std::atan2(dy, dx), odom_old.theta) : 0.0;

  const MotionModelConfig& a = config_;
  const double sigma_trans = std::sqrt(a.alpha3 * trans * trans + a.alpha1 * rot * rot);
  const double sigma_rot = std::sqrt(a.alpha4 * trans * trans + a.alpha2 * rot * rot);
  const double sigma_strafe = std::sqrt(a.alpha1 * rot * rot + a.alpha5 * trans * trans);

  for (Particle& p : particles)
  {
    const double heading = p.pose.theta + bearing;
    const double c = std::cos(heading), s = std::sin(heading);
    const double trans_hat = trans + gaussian(sigma_trans, rng);
    const double rot_hat = rot + gaussian(sigma_rot, rng);
    const double strafe_hat = gaussian(sigma_strafe, rng);
    p.pose.x += trans_hat * c + strafe_hat * s;
    p.pose.y += trans_hat * s - strafe_hat * c;
    p.pose.theta = normalizeAngle(p.pose.theta + rot_hat);
  }
}

// ---------------------------------------------------------------- likelihood-field laser model

LikelihoodFieldModel::LikelihoodFieldModel(const LaserModelConfig& config, std::shared_ptr<const LikelihoodField> field)
    : config_(config), field_(std::move(field))
{
  if (!field_) throw std::invalid_argument("likelihood field model: no map (null field)");
  if (!(config_.sigma_hit > 0.0))
    throw std::invalid_argument("laser_sigma_hit: expected > 0, got " + std::to_string(config_.sigma_hit));
  if (!(config_.z_hit >= 0.0) || !(config_.z_rand >= 0.0) || !(config_.z_hit + config_.z_rand > 0.0))
    throw std::invalid_argument("laser_z_hit, laser_z_rand: expected >= 0 and not both 0, got " +
                                std::to_string(config_.z_hit) + ", " + std::to_string(config_.z_rand));
  if (config_.max_beams < 2)
    throw std::invalid_argument("laser_max_beams: expected >= 2, got " + std::to_string(config_.max_beams));
}

namespace
{
/// A beam that the model uses: its range [m] and its angle in the laser frame [rad].
struct Beam
{
  double range;
  double bearing;
};

/// The usable beams of a scan, thinned to at most `max_beams` evenly spread ones (as amcl:
/// every step-th beam). Beams without a valid return are left out.
std::vector<Beam> selectBeams(const LaserScanData& scan, const LaserModelConfig& config, double& range_max)
{
  range_max = config.max_range > 0.0 ? config.max_range : scan.range_max;
  const double range_min = config.min_range > 0.0 ? config.min_range : scan.range_min;
  const size_t n = scan.ranges.size();
  std::vector<Beam> beams;
  if (n == 0) return beams;
  const size_t step = std::max<size_t>(1, (n - 1) / static_cast<size_t>(config.max_beams - 1));
  for (size_t i = 0; i < n; i += step)
  {
    const double r = scan.ranges[i];
    // REP-117: +Inf (no return) and max-range readings carry no obstacle; -Inf and NaN neither
    if (!std::isfinite(r) || r >= range_max || r < range_min) continue;
    beams.push_back({r, scan.angle_min + static_cast<double>(i) * scan.angle_increment});
  }
  return beams;
}

/// The log-likelihood of the beams seen from `laser_in_map` (see LikelihoodFieldModel::likelihood).
double logScoreBeams(const std::vector<Beam>& beams, const Pose2D& laser_in_map, double range_max,
                     const LaserModelConfig& config, const LikelihoodField& field)
{
  const double two_sigma_sq = 2.0 * config.sigma_hit * config.sigma_hit;
  const double rand_part = range_max > 0.0 ? config.z_rand / range_max : 0.0;
  double sum = config.product ? 0.0 : 1.0;
  for (const Beam& b : beams)
  {
    const double angle = laser_in_map.theta + b.bearing;
    const double hx = laser_in_map.x + b.range * std::cos(angle);
    const double hy = laser_in_map.y + b.range * std::sin(angle);
    const double d = config.surface_distance ? field.surfaceDistance(hx, hy) : field.distance(hx, hy);
    const double pz = config.z_hit * std::exp(-d * d / two_sigma_sq) + rand_part;
    sum += config.product ? std::log(pz) : pz * pz * pz;
  }
  return config.product ? sum : std::log(sum);
}
}  // namespace

double LikelihoodFieldModel::apply(const LaserScanData& scan, const Pose2D& laser_in_base,
                                   std::vector<Particle>& particles, double* fit) const
{
  double range_max = 0.0;
  const std::vector<Beam> beams = selectBeams(scan, config_, range_max);
  std::vector<double> log_p(particles.size());
  double best = -std::numeric_limits<double>::infinity();
  // per beam, so that the fit does not depend on the number of beams (a product of 60 beam
  // scores swings by orders of magnitude when one person hides a wall)
  double mean_fit = 0.0;
  for (size_t i = 0; i < particles.size(); ++i)
  {
    log_p[i] = logScoreBeams(beams, compose(particles[i].pose, laser_in_base), range_max, config_, *field_);
    best = std::max(best, log_p[i]);
    if (fit && !beams.empty()) mean_fit += particles[i].weight * std::exp(log_p[i] / static_cast<double>(beams.size()));
  }
  if (fit) *fit = beams.empty() ? std::numeric_limits<double>::quiet_NaN() : mean_fit;
  // A product of many beam scores underflows a double: scale all by the best particle's, which
  // normalizing the weights cancels.
  double total = 0.0;
  for (size_t i = 0; i < particles.size(); ++i)
  {
    particles[i].weight *= std::exp(log_p[i] - best);
    total += particles[i].weight;
  }
  return total;
}

double LikelihoodFieldModel::likelihood(const LaserScanData& scan, const Pose2D& laser_in_base,
                                        const Pose2D& base_in_map) const
{
  return std::exp(logLikelihood(scan, laser_in_base, base_in_map));
}

double LikelihoodFieldModel::logLikelihood(const LaserScanData& scan, const Pose2D& laser_in_base,
                                           const Pose2D& base_in_map) const
{
  double range_max = 0.0;
  const std::vector<Beam> beams = selectBeams(scan, config_, range_max);
  return logScoreBeams(beams, compose(base_in_map, laser_in_base), range_max, config_, *field_);
}

}  // namespace mbot_localization
