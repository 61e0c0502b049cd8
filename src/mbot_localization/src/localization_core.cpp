#include "mbot_localization/localization_core.h"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>

namespace mbot_localization
{
// ---------------------------------------------------------------- particle filter localizer

PfLocalizer::PfLocalizer(const PfLocalizerConfig& config, const OccupancyGridData& map, uint32_t seed)
    : config_(config),
      field_(std::make_shared<LikelihoodField>(map, config.likelihood_max_dist)),
      filter_(config.filter, seed),
      motion_(config.motion),
      laser_(config.laser, field_)
{
  if (!(config_.update_min_d >= 0.0) || !(config_.update_min_a >= 0.0))
    throw std::invalid_argument("update_min_d, update_min_a: expected >= 0");
  if (!(config_.rest_d >= 0.0) || !(config_.rest_a >= 0.0))
    throw std::invalid_argument("rest_d, rest_a: expected >= 0");
  if (config_.resample_interval < 1)
    throw std::invalid_argument("resample_interval: expected >= 1, got " + std::to_string(config_.resample_interval));
  if (!(config_.recovery_alpha_slow >= 0.0 && config_.recovery_alpha_slow <= 1.0) ||
      !(config_.recovery_alpha_fast >= 0.0 && config_.recovery_alpha_fast <= 1.0))
    throw std::invalid_argument("recovery_alpha_slow, recovery_alpha_fast: expected in [0, 1], got " +
                                std::to_string(config_.recovery_alpha_slow) + ", " +
                                std::to_string(config_.recovery_alpha_fast));
  collectFreeCells();
}

void PfLocalizer::collectFreeCells()
{
  free_cells_.clear();
  if (!recoveryEnabled()) return;  // only random particles need them (a 2000 x 2000 map: 32 MB)
  const LikelihoodField& f = *field_;
  for (unsigned my = 0; my < f.height(); ++my)
    for (unsigned mx = 0; mx < f.width(); ++mx)
      if (f.isFree(f.originX() + (mx + 0.5) * f.resolution(), f.originY() + (my + 0.5) * f.resolution()))
        free_cells_.push_back(static_cast<size_t>(my) * f.width() + mx);
}

Pose2D PfLocalizer::randomFreePose(std::mt19937& rng) const
{
  const LikelihoodField& f = *field_;
  std::uniform_real_distribution<double> unit(0.0, 1.0);
  Pose2D p;
  p.theta = normalizeAngle(2.0 * M_PI * unit(rng));
  if (free_cells_.empty()) return p;  // no free cell: nothing better than the origin
  const size_t cell = free_cells_[std::uniform_int_distribution<size_t>(0, free_cells_.size() - 1)(rng)];
  p.x = f.originX() + (static_cast<double>(cell % f.width()) + unit(rng)) * f.resolution();
  p.y = f.originY() + (static_cast<double>(cell / f.width()) + unit(rng)) * f.resolution();
  return p;
}

void validateConfig(const PfLocalizerConfig& config)
{
  OccupancyGridData one_cell;
  one_cell.width = one_cell.height = 1;
  one_cell.data = {0};
  PfLocalizer check(config, one_cell, 0);
}

void PfLocalizer::setMap(const OccupancyGridData& map)
{
  field_ = std::make_shared<LikelihoodField>(map, config_.likelihood_max_dist);
  laser_ = LikelihoodFieldModel(config_.laser, field_);
  collectFreeCells();
}

void PfLocalizer::setInitialPose(const Pose2D& pose, const std::array<double, 9>& covariance)
{
  filter_.initGaussian(pose, covariance);
  initialized_ = true;
  has_estimate_ = false;
  force_update_ = true;
  updates_since_init_ = 0;
  w_slow_ = w_fast_ = 0.0;
}

bool PfLocalizer::processScan(const Pose2D& odom_pose, const LaserScanData& scan, const Pose2D& laser_in_base)
{
  if (!initialized_) return false;

  // standing still: no odometry change since the previous scan
  const bool at_rest =
      have_previous_scan_ &&
      std::hypot(odom_pose.x - previous_scan_odom_.x, odom_pose.y - previous_scan_odom_.y) <= config_.rest_d &&
      std::fabs(angleDiff(odom_pose.theta, previous_scan_odom_.theta)) <= config_.rest_a;
  previous_scan_odom_ = odom_pose;
  have_previous_scan_ = true;

  if (!force_update_)
  {
    // amcl's rule: update only after enough motion, so that a robot standing still does not
    // collapse its particles onto one (possibly wrong) hypothesis. One update when it stops
    // after a shorter move: otherwise the estimate where it stands (at a goal) is the one from
    // up to update_min_d back, made while moving.
    const double moved = std::hypot(odom_pose.x - last_odom_.x, odom_pose.y - last_odom_.y);
    const double turned = std::fabs(angleDiff(odom_pose.theta, last_odom_.theta));
    const bool enough = moved > config_.update_min_d || turned > config_.update_min_a;
    const bool settled = config_.update_at_rest && at_rest && (moved > config_.rest_d || turned > config_.rest_a);
    if (!enough && !settled) return false;
    motion_.apply(last_odom_, odom_pose, filter_.particles(), filter_.rng());
  }
  force_update_ = false;
  last_odom_ = odom_pose;

  double fit = 0.0;
  laser_.apply(scan, laser_in_base, filter_.particles(), &fit);
  if (std::isfinite(fit))
  {
    // amcl's recovery averages: started at the first fit, then exponential
    last_fit_ = fit;
    w_slow_ = w_slow_ == 0.0 ? fit : w_slow_ + config_.recovery_alpha_slow * (fit - w_slow_);
    w_fast_ = w_fast_ == 0.0 ? fit : w_fast_ + config_.recovery_alpha_fast * (fit - w_fast_);
  }
  filter_.normalizeWeights();
  estimate_ = config_.cluster_estimate ? filter_.bestClusterEstimate() : filter_.estimate();
  odom_at_estimate_ = odom_pose;
  has_estimate_ = true;
  ++updates_;
  ++updates_since_init_;
  // the weights carry over between updates until the set is resampled (counted from the
  // initialization: the first scan alone does not collapse a fresh set)
  if (updates_since_init_ % config_.resample_interval == 0)
  {
    const double random_fraction = recoveryEnabled() && w_slow_ > 0.0 ? std::max(0.0, 1.0 - w_fast_ / w_slow_) : 0.0;
    random_particles_ += filter_.resample(random_fraction, [this](std::mt19937& rng) { return randomFreePose(rng); });
    if (random_fraction > 0.0) w_slow_ = w_fast_ = 0.0;  // as amcl: start the averages again
  }
  return true;
}

// ---------------------------------------------------------------- fake localization

GroundTruthMatcher::GroundTruthMatcher(int64_t buffer_ns, int64_t match_tolerance_ns)
    : buffer_ns_(buffer_ns), tolerance_ns_(match_tolerance_ns)
{
  if (buffer_ns_ <= 0 || tolerance_ns_ < 0)
    throw std::invalid_argument("ground truth matcher: expected buffer > 0 and tolerance >= 0");
}

void GroundTruthMatcher::append(std::deque<StampedPose>& samples, int64_t& last_stamp_ns, const StampedPose& sample)
{
  // One publisher's messages arrive in order, so an older stamp means that time jumped back
  // (the simulation was reset): everything buffered belongs to the old timeline.
  if (sample.stamp_ns + tolerance_ns_ < last_stamp_ns)
  {
    truth_.clear();
    odom_.clear();
    ++time_jumps_;
  }
  last_stamp_ns = sample.stamp_ns;
  if (!samples.empty() && sample.stamp_ns <= samples.back().stamp_ns)
    samples.back() = sample;  // the same stamp again: keep the newer message
  else
    samples.push_back(sample);
  prune();
}

void GroundTruthMatcher::addGroundTruth(const StampedPose& map_base) { append(truth_, last_truth_ns_, map_base); }

void GroundTruthMatcher::addOdometry(const StampedPose& odom_base) { append(odom_, last_odom_ns_, odom_base); }

void GroundTruthMatcher::prune()
{
  int64_t newest = 0;
  if (!truth_.empty()) newest = truth_.back().stamp_ns;
  if (!odom_.empty()) newest = std::max(newest, odom_.back().stamp_ns);
  while (!truth_.empty() && truth_.front().stamp_ns < newest - buffer_ns_) truth_.pop_front();
  while (!odom_.empty() && odom_.front().stamp_ns < newest - buffer_ns_) odom_.pop_front();
}

std::optional<Pose2D> GroundTruthMatcher::groundTruthAt(int64_t stamp_ns) const
{
  auto after = std::lower_bound(truth_.begin(), truth_.end(), stamp_ns - tolerance_ns_,
                                [](const StampedPose& a, int64_t t) { return a.stamp_ns < t; });
  if (after == truth_.end()) return std::nullopt;                       // not received yet
  if (after->stamp_ns <= stamp_ns + tolerance_ns_) return after->pose;  // same stamp
  if (after == truth_.begin()) return std::nullopt;                     // older than everything we have
  const StampedPose& before = *(after - 1);
  const double ratio =
      static_cast<double>(stamp_ns - before.stamp_ns) / static_cast<double>(after->stamp_ns - before.stamp_ns);
  Pose2D p;
  p.x = before.pose.x + ratio * (after->pose.x - before.pose.x);
  p.y = before.pose.y + ratio * (after->pose.y - before.pose.y);
  p.theta = normalizeAngle(before.pose.theta + ratio * angleDiff(after->pose.theta, before.pose.theta));
  return p;
}

std::vector<GroundTruthMatcher::Match> GroundTruthMatcher::takeMatches()
{
  std::vector<Match> matches;
  while (!odom_.empty())
  {
    const StampedPose& odom = odom_.front();
    const std::optional<Pose2D> truth = groundTruthAt(odom.stamp_ns);
    if (truth)
    {
      matches.push_back({odom.stamp_ns, *truth, odom.pose, mapToOdom(*truth, odom.pose)});
      odom_.pop_front();
    }
    else if (!truth_.empty() && odom.stamp_ns < truth_.front().stamp_ns - tolerance_ns_)
      odom_.pop_front();  // older than all ground truth: can never be matched
    else
      break;  // its ground truth has not arrived; newer odometry waits behind it
  }
  return matches;
}

}  // namespace mbot_localization
