#include "mbot_navigation/costmap/inflation_layer.h"

#include <mbot_common/distance_transform.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>

namespace mbot_navigation
{
InflationLayer::InflationLayer(const InflationLayerConfig& config) { setConfig(config); }

void InflationLayer::setConfig(const InflationLayerConfig& config)
{
  if (!(config.inflation_radius >= 0.0) || !(config.cost_scaling_factor >= 0.0))
    throw std::invalid_argument(
        "InflationLayerConfig: 'inflation_radius' [m] and 'cost_scaling_factor' [1/m] must be >= 0");
  config_ = config;
  computeCaches();
}

void InflationLayer::onFootprintChanged(double robot_radius)
{
  inscribed_radius_ = robot_radius;
  computeCaches();
}

void InflationLayer::matchSize(const Costmap2D& master)
{
  resolution_ = master.resolution();
  computeCaches();
}

uint8_t InflationLayer::computeCost(double distance_cells) const
{
  // costmap_2d's InflationLayer::computeCost, kept literally (including comparing d * resolution
  // with the inscribed radius as doubles: 3 cells * 0.05 = 0.15000000000000002 > 0.15).
  if (distance_cells == 0.0) return cost::LETHAL;
  const double d = distance_cells * resolution_;
  if (d <= inscribed_radius_) return cost::INSCRIBED;
  const double factor = std::exp(-1.0 * config_.cost_scaling_factor * (d - inscribed_radius_));
  return static_cast<uint8_t>((cost::INSCRIBED - 1) * factor);
}

void InflationLayer::computeCaches()
{
  if (!(resolution_ > 0.0)) return;
  // Whole cells within the radius; the 1e-9 keeps 0.55 / 0.05 = 10.999999... at 11.
  const double radius_cells = config_.inflation_radius / resolution_;
  cell_radius_ = static_cast<int>(std::floor(radius_cells + 1e-9));
  const int max_d2 = cell_radius_ * cell_radius_;
  cost_by_d2_.assign(max_d2 + 1, cost::FREE);
  for (int d2 = 0; d2 <= max_d2; ++d2)
  {
    // Zero beyond inflation_radius (d2 with no integer cell pair is never looked up).
    if (d2 > radius_cells * radius_cells * (1.0 + 1e-12)) continue;
    cost_by_d2_[d2] = computeCost(std::sqrt(static_cast<double>(d2)));
  }
}

void InflationLayer::updateBounds(const Pose2D& /*robot*/, Bounds& bounds)
{
  if (bounds.empty()) return;
  // A change at a cell can change inflated costs up to inflation_radius around it.
  const double r = config_.inflation_radius;
  bounds.include(bounds.min_x - r, bounds.min_y - r);
  bounds.include(bounds.max_x + r, bounds.max_y + r);
}

void InflationLayer::inflate(Costmap2D& grid)
{
  if (grid.resolution() != resolution_) matchSize(grid);
  updateCosts(grid, CellWindow{0, 0, static_cast<int>(grid.sizeX()), static_cast<int>(grid.sizeY())});
}

void InflationLayer::updateCosts(Costmap2D& master, const CellWindow& w)
{
  if (w.empty()) return;
  if (master.resolution() != resolution_) matchSize(master);
  const int R = cell_radius_;
  if (cost_by_d2_.empty()) return;  // no resolution yet

  // Sources: lethal cells up to R cells outside the window can inflate cells inside it.
  const int sx0 = std::max(0, w.x0 - R), sy0 = std::max(0, w.y0 - R);
  const int sxn = std::min(static_cast<int>(master.sizeX()), w.xn + R);
  const int syn = std::min(static_cast<int>(master.sizeY()), w.yn + R);
  const int W = sxn - sx0, H = syn - sy0;
  const int cap = R + 1;  // any distance >= cap is "far": it inflates nothing
  col_dist_.resize(static_cast<size_t>(W) * H);
  const uint8_t* costs = master.data();

  // Pass 1: distance along each column to the nearest lethal cell, down then up.
  for (int y = 0; y < H; ++y)
  {
    const uint8_t* row = costs + master.index(sx0, sy0 + y);
    int* out = &col_dist_[static_cast<size_t>(y) * W];
    const int* prev = y > 0 ? out - W : nullptr;
    for (int x = 0; x < W; ++x) out[x] = row[x] == cost::LETHAL ? 0 : (prev ? std::min(prev[x] + 1, cap) : cap);
  }
  for (int y = H - 2; y >= 0; --y)
  {
    int* out = &col_dist_[static_cast<size_t>(y) * W];
    const int* next = out + W;
    for (int x = 0; x < W; ++x) out[x] = std::min(out[x], next[x] + 1);
  }

  // Pass 2: per row of the window, the 1-D transform of the squared column distances gives the
  // exact squared Euclidean distance (Felzenszwalb & Huttenlocher 2012, distance_transform.h).
  // Distances stay capped ints, so the costs come from an exact table lookup.
  row_f_.resize(W);
  d2_.resize(W);
  env_v_.resize(W);
  env_z_.resize(W + 1);
  const int max_d2 = R * R;
  uint8_t* out_costs = master.data();
  for (int y = w.y0; y < w.yn; ++y)
  {
    const int* col = &col_dist_[static_cast<size_t>(y - sy0) * W];
    bool any = false;
    for (int x = 0; x < W; ++x)
    {
      row_f_[x] = col[x] * col[x];
      any |= col[x] < cap;
    }
    if (!any) continue;  // no lethal cell within R rows: nothing to inflate in this row

    mbot_common::squaredDistanceTransform1d(row_f_.data(), W, d2_.data(), env_v_.data(), env_z_.data());

    uint8_t* row = out_costs + master.index(0, y);
    for (int x = w.x0; x < w.xn; ++x)
    {
      const int d2 = d2_[x - sx0];
      if (d2 > max_d2) continue;
      const uint8_t c = cost_by_d2_[d2];
      uint8_t& old = row[x];
      // costmap_2d's rule: unknown cells only take costs that mean "robot would collide".
      if (old == cost::NO_INFORMATION)
      {
        if (config_.inflate_unknown ? c > cost::FREE : c >= cost::INSCRIBED) old = c;
      }
      else if (c > old)
      {
        old = c;
      }
    }
  }
}

}  // namespace mbot_navigation
