/**
 * @file test_distance_transform.cpp
 * @brief gtest of the shared 1-D squared distance transform (distance_transform.h), checked
 *        exactly against brute force, alone and as the two passes of a 2-D transform. Its users
 *        are checked in their packages: the inflation layer (mbot_navigation,
 *        test_inflation_transform) and the likelihood field (mbot_localization,
 *        test_likelihood_transform).
 */
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "mbot_common/distance_transform.h"
#include "mbot_common/testing/distance_transform_cases.h"

using mbot_common::squaredDistanceTransform1d;
using namespace mbot_common_test;

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
      if (trial == 0) std::fill(fi.begin(), fi.end(), 0);          // all occupied
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

TEST(SquaredDistanceTransform1d, TwoPassesGiveTheExact2dTransform)
{
  // Columns, then rows on the squared column distances, as both users do; an int big enough
  // that no sum overflows stands for "no obstacle in this column".
  for (const DistanceGrid& g : distanceTestGrids())
  {
    const int far = 4 * (g.w + g.h) * (g.w + g.h);
    std::vector<int> cols(g.occ.size()), out(g.occ.size());
    const int n = std::max(g.w, g.h);
    std::vector<int> f(n), d(n), v(n);
    std::vector<double> z(n + 1);
    for (int x = 0; x < g.w; ++x)
    {
      for (int y = 0; y < g.h; ++y) f[y] = g.occ[y * g.w + x] ? 0 : far;
      squaredDistanceTransform1d(f.data(), g.h, d.data(), v.data(), z.data());
      for (int y = 0; y < g.h; ++y) cols[y * g.w + x] = d[y];
    }
    for (int y = 0; y < g.h; ++y) squaredDistanceTransform1d(&cols[y * g.w], g.w, &out[y * g.w], v.data(), z.data());
    const auto expected = bruteForceSquaredDistances(g);
    for (size_t i = 0; i < out.size(); ++i)
    {
      if (expected[i] >= 0)
        ASSERT_EQ(out[i], expected[i]) << g.w << "x" << g.h << " cell " << i;
      else
        ASSERT_GE(out[i], far) << g.w << "x" << g.h << " cell " << i;  // no obstacle: "far"
    }
  }
}
