#include "mbot_localization/particle_filter.h"

#include <algorithm>
#include <array>
#include <map>
#include <cmath>
#include <stdexcept>
#include <string>
#include <unordered_set>

namespace mbot_localization
{
std::vector<size_t> lowVarianceSample(const std::vector<double>& weights, size_t count, std::mt19937& rng)
{
  std::vector<size_t> picked;
  if (weights.empty() || count == 0) return picked;
  picked.reserve(count);
  // One random start in [0, 1/count), then `count` equally spaced pointers into the
  // cumulative weights: one draw instead of `count`, and no particle is over- or under-drawn
  // by more than one copy.
  const double step = 1.0 / static_cast<double>(count);
  const double start = std::uniform_real_distribution<double>(0.0, step)(rng);
  double cumulative = weights[0];
  size_t i = 0;
  for (size_t m = 0; m < count; ++m)
  {
    const double u = start + static_cast<double>(m) * step;
    while (u > cumulative && i + 1 < weights.size()) cumulative += weights[++i];
    picked.push_back(i);
  }
  return picked;
}

ParticleFilter::ParticleFilter(const ParticleFilterConfig& config, uint32_t seed) : config_(config), rng_(seed)
{
  if (config_.min_particles < 1 || config_.max_particles < config_.min_particles)
    throw std::invalid_argument(
        "min_particles, max_particles: expected 1 <= min_particles <= "
        "max_particles, got " +
        std::to_string(config_.min_particles) + ", " + std::to_string(config_.max_particles));
  if (config_.particles_per_bin < 1)
    throw std::invalid_argument("particles_per_bin: expected >= 1, got " + std::to_string(config_.particles_per_bin));
  if (!(config_.bin_size_xy > 0.0) || !(config_.bin_size_theta > 0.0))
    throw std::invalid_argument("bin sizes: expected > 0");
}

void ParticleFilter::initGaussian(const Pose2D& mean, const std::array<double, 9>& covariance)
{
  std::normal_distribution<double> unit(0.0, 1.0);
  const double sx = std::sqrt(std::max(0.0, covariance[0]));
  const double sy = std::sqrt(std::max(0.0, covariance[4]));
  const double sa = std::sqrt(std::max(0.0, covariance[8]));
  const size_t n = static_cast<size_t>(config_.max_particles);
  particles_.assign(n, Particle{});
  for (Particle& p : particles_)
  {
    p.pose.x = mean.x + sx * unit(rng_);
    p.pose.y = mean.y + sy * unit(rng_);
    p.pose.theta = normalizeAngle(mean.theta + sa * unit(rng_));
    p.weight = 1.0 / static_cast<double>(n);
  }
}

void ParticleFilter::normalizeWeights()
{
  double total = 0.0;
  for (const Particle& p : particles_) total += p.weight;
  const bool usable = total > 0.0 && std::isfinite(total);
  for (Particle& p : particles_) p.weight = usable ? p.weight / total : 1.0 / static_cast<double>(particles_.size());
}

size_t ParticleFilter::countBins(const std::vector<size_t>& indices) const
{
  std::unordered_set<uint64_t> bins;
  for (size_t i : indices)
  {
    const Pose2D& q = particles_[i].pose;
    // 21 bits per axis are plenty: 2^21 bins of 0.5 m span 1000 km
    const auto key = [](double v, double size) {
      return static_cast<uint64_t>(static_cast<int64_t>(std::floor(v / size)) & 0x1FFFFF);
    };
    bins.insert(key(q.x, config_.bin_size_xy) << 42 | key(q.y, config_.bin_size_xy) << 21 |
                key(q.theta, config_.bin_size_theta));
  }
  return bins.size();
}

size_t ParticleFilter::occupiedBins() const
{
  std::vector<size_t> all(particles_.size());
  for (size_t i = 0; i < all.size(); ++i) all[i] = i;
  return countBins(all);
}

size_t ParticleFilter::resample(double random_fraction, const std::function<Pose2D(std::mt19937&)>& random_pose)
{
  if (particles_.empty()) return 0;
  normalizeWeights();
  std::vector<double> weights(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) weights[i] = particles_[i].weight;

  // Draw at the current size, measure how spread the drawn set is, and redraw at the size that
  // this spread needs (see ParticleFilterConfig).
  std::vector<size_t> picked = lowVarianceSample(weights, particles_.size(), rng_);
  const size_t wanted =
      std::clamp<size_t>(countBins(picked) * config_.particles_per_bin, config_.min_particles, config_.max_particles);
  if (wanted != picked.size()) picked = lowVarianceSample(weights, wanted, rng_);

  const bool inject = random_fraction > 0.0 && random_pose;
  std::uniform_real_distribution<double> uniform(0.0, 1.0);
  size_t injected = 0;
  std::vector<Particle> next(picked.size());
  for (size_t m = 0; m < picked.size(); ++m)
  {
    if (inject && uniform(rng_) < random_fraction)
    {
      next[m].pose = random_pose(rng_);
      ++injected;
    }
    else
      next[m].pose = particles_[picked[m]].pose;
    next[m].weight = 1.0 / static_cast<double>(picked.size());
  }
  particles_.swap(next);
  return injected;
}

PoseWithCovariance ParticleFilter::meanOf(const std::vector<bool>& member) const
{
  PoseWithCovariance out;
  double total = 0.0, mx = 0.0, my = 0.0, mc = 0.0, ms = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i)
  {
    if (!member[i]) continue;
    const Particle& p = particles_[i];
    total += p.weight;
    mx += p.weight * p.pose.x;
    my += p.weight * p.pose.y;
    mc += p.weight * std::cos(p.pose.theta);
    ms += p.weight * std::sin(p.pose.theta);
  }
  if (!(total > 0.0)) return out;
  mx /= total;
  my /= total;
  mc /= total;
  ms /= total;
  double xx = 0.0, xy = 0.0, yy = 0.0;
  for (size_t i = 0; i < particles_.size(); ++i)
  {
    if (!member[i]) continue;
    const Particle& p = particles_[i];
    const double dx = p.pose.x - mx, dy = p.pose.y - my;
    xx += p.weight * dx * dx;
    xy += p.weight * dx * dy;
    yy += p.weight * dy * dy;
  }
  out.pose.x = mx;
  out.pose.y = my;
  out.pose.theta = std::atan2(ms, mc);
  out.covariance[0] = xx / total;
  out.covariance[1] = out.covariance[3] = xy / total;
  out.covariance[4] = yy / total;
  // circular variance of the heading, as amcl: -2 ln(R), R = length of the mean unit vector
  const double r = std::hypot(mc, ms);
  out.covariance[8] = r > 0.0 ? -2.0 * std::log(std::min(1.0, r)) : 4.0 * M_PI * M_PI;
  return out;
}

PoseWithCovariance ParticleFilter::estimate() const { return meanOf(std::vector<bool>(particles_.size(), true)); }

std::vector<size_t> ParticleFilter::clusters(size_t& count) const
{
  // bin of each particle; heading bins wrap around at +-pi
  const int theta_bins = std::max(1, static_cast<int>(std::ceil(2.0 * M_PI / config_.bin_size_theta)));
  std::map<std::array<int64_t, 3>, size_t> bin_index;
  std::vector<size_t> bin_of(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i)
  {
    const Pose2D& q = particles_[i].pose;
    const std::array<int64_t, 3> key = {
        static_cast<int64_t>(std::floor(q.x / config_.bin_size_xy)),
        static_cast<int64_t>(std::floor(q.y / config_.bin_size_xy)),
        static_cast<int64_t>(std::floor((q.theta + M_PI) / config_.bin_size_theta)) % theta_bins};
    bin_of[i] = bin_index.emplace(key, bin_index.size()).first->second;
  }
  // union-find over bins: a bin joins every occupied one of its 26 neighbours
  std::vector<size_t> parent(bin_index.size());
  for (size_t b = 0; b < parent.size(); ++b) parent[b] = b;
  const auto root = [&parent](size_t b) {
    while (parent[b] != b) b = parent[b] = parent[parent[b]];
    return b;
  };
  for (const auto& [key, b] : bin_index)
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int da = -1; da <= 1; ++da)
        {
          const std::array<int64_t, 3> next = {key[0] + dx, key[1] + dy, (key[2] + da + theta_bins) % theta_bins};
          const auto it = bin_index.find(next);
          if (it != bin_index.end()) parent[root(it->second)] = root(b);
        }
  std::map<size_t, size_t> number;  // root bin -> cluster number
  std::vector<size_t> cluster(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i)
    cluster[i] = number.emplace(root(bin_of[i]), number.size()).first->second;
  count = number.size();
  return cluster;
}

PoseWithCovariance ParticleFilter::bestClusterEstimate() const
{
  size_t count = 0;
  const std::vector<size_t> cluster = clusters(count);
  if (count == 0) return PoseWithCovariance{};
  std::vector<double> weight(count, 0.0);
  for (size_t i = 0; i < particles_.size(); ++i) weight[cluster[i]] += particles_[i].weight;
  const size_t best = static_cast<size_t>(std::max_element(weight.begin(), weight.end()) - weight.begin());
  std::vector<bool> member(particles_.size());
  for (size_t i = 0; i < particles_.size(); ++i) member[i] = cluster[i] == best;
  return meanOf(member);
}

}  // namespace mbot_localization
