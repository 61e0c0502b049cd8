/**
 * @file test_inflation_transform.cpp
 * @brief gtest (no master): the inflation layer's capped integer distance transform, built on
 *        mbot_common's shared 1-D pass, gives exactly the cost of the brute-force distance on
 *        mbot_common's test grids.
 */
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <mbot_common/testing/distance_transform_cases.h>

#include "mbot_navigation/costmap/inflation_layer.h"

using namespace mbot_navigation;
using namespace mbot_common_test;

TEST(InflationLayer, SquaredDistanceTransformMatchesBruteForce)
{
  // 0.05 m cells, inflation radius 8 cells: the inflated cost must be the cost table entry of
  // the brute-force squared distance (the layer only reads distances up to its cap).
  InflationLayerConfig cfg;
  cfg.inflation_radius = 0.4;
  cfg.cost_scaling_factor = 5.0;
  InflationLayer inflation(cfg);
  inflation.onFootprintChanged(0.12);
  const int R2 = 8 * 8;
  for (const DistanceGrid& g : distanceTestGrids())
  {
    Costmap2D grid(g.w, g.h, 0.05, 0.0, 0.0);
    for (size_t i = 0; i < g.occ.size(); ++i)
      if (g.occ[i]) grid.data()[i] = cost::LETHAL;
    inflation.inflate(grid);
    const auto d2 = bruteForceSquaredDistances(g);
    for (size_t i = 0; i < d2.size(); ++i)
    {
      const int expected = d2[i] < 0 || d2[i] > R2 ? cost::FREE : inflation.computeCost(std::sqrt(double(d2[i])));
      ASSERT_EQ(int(grid.data()[i]), expected) << g.w << "x" << g.h << " cell " << i;
    }
  }
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
