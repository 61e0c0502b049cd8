/**
 * @file distance_transform.h
 * @brief The 1-D pass of the exact squared Euclidean distance transform of Felzenszwalb and
 *        Huttenlocher ("Distance Transforms of Sampled Functions", 2012), shared by the
 *        costmap's InflationLayer (mbot_navigation) and the particle filter's LikelihoodField
 *        (mbot_localization). Header-only, free of ROS types.
 *
 * A 2-D transform is two 1-D passes: first along every column (giving the vertical distance to
 * the nearest obstacle), then along every row on the squared column distances. Each user keeps
 * its own first pass and loop over rows (the inflation layer works on a window with a distance
 * cap, the likelihood field on the whole map); only the 1-D lower envelope below is common.
 */
#pragma once

#include <limits>

namespace mbot_common
{
/**
 * @brief 1-D squared distance transform: d[q] = min over p of (q - p)^2 + f[p], for q in [0, n).
 *
 * Every sample p is a parabola (q - p)^2 + f[p]; the answer is their lower envelope, built in one
 * left-to-right sweep and read off in a second one, so the cost is O(n) instead of O(n^2).
 *
 * @tparam T int (inflation: small exact integers) or double (likelihood field, where "no
 *         obstacle" is a huge finite value). The sums are done in T and only the crossing point
 *         in double, so that int inputs give exact int outputs.
 * @param f n input values; d: n outputs (must not overlap f)
 * @param v, z scratch of at least n ints and n + 1 doubles, owned by the caller so that a hot
 *        path can reuse them and allocate nothing: v[k] is the sample of the k-th envelope
 *        parabola, which is the lowest one on [z[k], z[k + 1]]
 */
template <typename T>
inline void squaredDistanceTransform1d(const T* f, int n, T* d, int* v, double* z)
{
  if (n <= 0) return;
  constexpr double INF = std::numeric_limits<double>::infinity();
  int k = 0;  // index of the rightmost parabola of the envelope so far
  v[0] = 0;
  z[0] = -INF;
  z[1] = INF;
  for (int q = 1; q < n; ++q)
  {
    // s: where parabola q crosses the envelope's rightmost parabola. If that is left of where
    // the latter starts to be lowest, q hides it completely: drop it and try the previous one.
    // (z[0] is -inf, so k never goes below 0.)
    double s;
    while (true)
    {
      const int p = v[k];
      s = ((f[q] + T(q) * q) - (f[p] + T(p) * p)) / (2.0 * (q - p));
      if (s > z[k]) break;
      --k;
    }
    ++k;
    v[k] = q;
    z[k] = s;
    z[k + 1] = INF;
  }
  // Read the envelope: for each q, move to the parabola that is lowest at q.
  k = 0;
  for (int q = 0; q < n; ++q)
  {
    while (z[k + 1] < q) ++k;
    const T dq = T(q - v[k]);
    d[q] = dq * dq + f[v[k]];
  }
}

}  // namespace mbot_common
