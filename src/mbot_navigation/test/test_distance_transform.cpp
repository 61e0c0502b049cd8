/**
 * @file test_distance_transform.cpp
 * @brief gtest (no master) of the shared 1-D squared distance transform (distance_transform.h)
 *        and of its two users, checked exactly against brute force: the likelihood field's
 *        full-map transform (double, "no obstacle" = huge) and the inflation layer's capped
 *        integer transform.
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mbot_navigation/distance_transform.h"
#include "mbot_navigation/inflation_layer.h"
#include "mbot_navigation/likelihood_field.h"

using namespace mbot_navigation;

namespace
{
/// min over p of (q - p)^2 + f[p], the definition, in O(n^2).
template <typename T>
std::vector<T> bruteForce1d(const std::vector<T>& f)
{
  const int n = static_cast<int>(f.size());
  std::vector<T> d(n);
  for (int q = 0; q < n; ++q)
  {
    d[q] = T(q) * q + f[0];
    for (int p = 1; p < n; ++p) d[q] = std::min(d[q], T(q - p) * T(q - p) + f[p]);
  }
  return d;
}

/// Runs the shared transform with exactly sized scratch buffers.
template <typename T>
std::vector<T> shared1d(const std::vector<T>& f)
{
  const int n = static_cast<int>(f.size());
  std::vector<T> d(n);
  std::vector<int> v(n);
  std::vector<double> z(n + 1);
  squaredDistanceTransform1d(f.data(), n, d.data(), v.data(), z.data());
  return d;
}

/// Squared distance [cells^2] from every cell to the nearest occupied one; -1 with no obstacle.
std::vector<long> bruteForce2d(const std::vector<uint8_t>& occ, int w, int h)
{
  std::vector<long> d(occ.size(), -1);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x)
      for (int oy = 0; oy < h; ++oy)
        for (int ox = 0; ox < w; ++ox)
          if (occ[oy * w + ox])
          {
            const long d2 = long(x - ox) * (x - ox) + long(y - oy) * (y - oy);
            long& best = d[y * w + x];
            if (best < 0 || d2 < best) best = d2;
          }
  return d;
}

/// Random grids, including the edge cases: no cell, empty, all occupied, 1xN and Nx1.
struct Grid
{
  int w, h;
  std::vector<uint8_t> occ;
};
std::vector<Grid> testGrids()
{
  std::mt19937 rng(42);
  std::vector<Grid> grids;
  auto add = [&](int w, int h, double density) {
    std::bernoulli_distribution occupied(density);
    Grid g{w, h, std::vector<uint8_t>(static_cast<size_t>(w) * h)};
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
}  // namespace

TEST(SquaredDistanceTransform1d, MatchesBruteForceForIntsAndDoubles)
{
  std::mt19937 rng(3);
  for (int n : {1, 2, 3, 5, 17, 64, 200})
    for (int trial = 0; trial < 20; ++trial)
    {
      // Like the inflation layer: squared column distances capped at cap^2, many ties at the cap.
      const int cap = 1 + rng() % 12;
      std::vector<int> fi(n);
      for (auto& x : fi)
      {
        const int c = std::min<int>(rng() % (2 * cap), cap);
        x = c * c;
      }
      if (trial == 0) std::fill(fi.begin(), fi.end(), 0);        // all occupied
      if (trial == 1) std::fill(fi.begin(), fi.end(), cap * cap);  // nothing within the cap
      ASSERT_EQ(shared1d(fi), bruteForce1d(fi)) << "n " << n << " trial " << trial;

      // Doubles with integer values (the likelihood field's values near obstacles) are exact too.
      std::vector<double> fd(n);
      for (auto& x : fd) x = rng() % 1000;
      ASSERT_EQ(shared1d(fd), bruteForce1d(fd)) << "n " << n << " trial " << trial;
    }
  // n = 0 touches nothing (not even the scratch).
  squaredDistanceTransform1d<int>(nullptr, 0, nullptr, nullptr, nullptr);
}

TEST(SquaredDistanceTransform, LikelihoodFieldTransformMatchesBruteForce)
{
  for (const Grid& g : testGrids())
  {
    const auto got = localization::squaredDistanceTransform(g.occ, g.w, g.h);
    const auto expected = bruteForce2d(g.occ, g.w, g.h);
    ASSERT_EQ(got.size(), expected.size());
    for (size_t i = 0; i < got.size(); ++i)
    {
      if (expected[i] >= 0)
        ASSERT_EQ(got[i], double(expected[i])) << g.w << "x" << g.h << " cell " << i;
      else
        ASSERT_GE(got[i], 1e19) << g.w << "x" << g.h << " cell " << i;  // no obstacle: huge
    }
  }
  // A grid without cells is fine too.
  EXPECT_TRUE(localization::squaredDistanceTransform({}, 0, 0).empty());
  EXPECT_TRUE(localization::squaredDistanceTransform({}, 5, 0).empty());
  EXPECT_TRUE(localization::squaredDistanceTransform({}, 0, 5).empty());
}

TEST(SquaredDistanceTransform, InflationLayerMatchesBruteForce)
{
  // 0.05 m cells, inflation radius 8 cells: the inflated cost must be the cost table entry of
  // the brute-force squared distance (the layer only reads distances up to its cap).
  InflationLayerConfig cfg;
  cfg.inflation_radius = 0.4;
  cfg.cost_scaling_factor = 5.0;
  InflationLayer inflation(cfg);
  inflation.onFootprintChanged(0.12);
  const int R2 = 8 * 8;
  for (const Grid& g : testGrids())
  {
    Costmap2D grid(g.w, g.h, 0.05, 0.0, 0.0);
    for (size_t i = 0; i < g.occ.size(); ++i)
      if (g.occ[i]) grid.data()[i] = cost::LETHAL;
    inflation.inflate(grid);
    const auto d2 = bruteForce2d(g.occ, g.w, g.h);
    for (size_t i = 0; i < d2.size(); ++i)
    {
      const int expected = d2[i] < 0 || d2[i] > R2 ? cost::FREE
                                                    : inflation.computeCost(std::sqrt(double(d2[i])));
      ASSERT_EQ(int(grid.data()[i]), expected) << g.w << "x" << g.h << " cell " << i;
    }
  }
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
