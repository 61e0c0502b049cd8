/**
 * @file test_likelihood_transform.cpp
 * @brief gtest (no master): the likelihood field's full-map squared distance transform, built on
 *        mbot_common's shared 1-D pass (double, "no obstacle" = huge), matches brute force
 *        exactly on mbot_common's test grids.
 */
#include <gtest/gtest.h>

#include <vector>

#include <mbot_common/testing/distance_transform_cases.h>

#include "mbot_localization/likelihood_field.h"

using mbot_localization::squaredDistanceTransform;
using namespace mbot_common_test;

TEST(LikelihoodField, SquaredDistanceTransformMatchesBruteForce)
{
  for (const DistanceGrid& g : distanceTestGrids())
  {
    const auto got = squaredDistanceTransform(g.occ, g.w, g.h);
    const auto expected = bruteForceSquaredDistances(g);
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
  EXPECT_TRUE(squaredDistanceTransform({}, 0, 0).empty());
  EXPECT_TRUE(squaredDistanceTransform({}, 5, 0).empty());
  EXPECT_TRUE(squaredDistanceTransform({}, 0, 5).empty());
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
