/**
 * @file distance_transform_cases.h
 * @brief For tests only: grids and the brute-force squared distance transform that the users of
 *        distance_transform.h are checked against (mbot_common's own test, the inflation layer
 *        in mbot_navigation, the likelihood field in mbot_localization), written once.
 *        Header-only, no gtest, free of ROS types.
 */
#pragma once

#include <cstddef>
#include <cstdint>
#include <random>
#include <vector>

namespace mbot_common_test
{
/// @brief An occupancy grid, row-major, 1 = occupied.
struct DistanceGrid
{
  int w, h;
  std::vector<uint8_t> occ;
};

/// @brief Squared distance [cells^2] from every cell to the nearest occupied one, by the
///        definition in O((w h)^2); -1 where there is no obstacle at all.
inline std::vector<long> bruteForceSquaredDistances(const DistanceGrid& g)
{
  std::vector<long> d(g.occ.size(), -1);
  for (int y = 0; y < g.h; ++y)
    for (int x = 0; x < g.w; ++x)
      for (int oy = 0; oy < g.h; ++oy)
        for (int ox = 0; ox < g.w; ++ox)
          if (g.occ[oy * g.w + ox])
          {
            const long d2 = long(x - ox) * (x - ox) + long(y - oy) * (y - oy);
            long& best = d[y * g.w + x];
            if (best < 0 || d2 < best) best = d2;
          }
  return d;
}

/// @brief Random grids (fixed seed), including the edge cases: a single cell, empty, all
///        occupied, 1xN and Nx1.
inline std::vector<DistanceGrid> distanceTestGrids()
{
  std::mt19937 rng(42);
  std::vector<DistanceGrid> grids;
  auto add = [&](int w, int h, double density) {
    std::bernoulli_distribution occupied(density);
    DistanceGrid g{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h)};
    for (auto& c : g.occ) c = occupied(rng) ? 1 : 0;
    grids.push_back(g);
  };
  for (double density : {0.0, 1.0, 0.05, 0.3})
  {
    add(1, 1, density);
    add(1, 37, density);  // 1xN
    add(41, 1, density);  // Nx1
    add(29, 23, density);
    add(64, 3, density);
  }
  for (int i = 0; i < 30; ++i)
    add(1 + rng() % 40, 1 + rng() % 40, std::uniform_real_distribution<double>(0.0, 0.2)(rng));
  return grids;
}

}  // namespace mbot_common_test
