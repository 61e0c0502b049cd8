// The pure helpers of the costmaps' ROS edge (costmap_ros.h), without a master.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "mbot_navigation/ros/costmap_ros.h"

using namespace mbot_navigation;

TEST(CostmapRos, OccupancyTranslationIsCostmap2ds)
{
  EXPECT_EQ(occupancyFromCost(cost::FREE), 0);
  EXPECT_EQ(occupancyFromCost(1), 1);
  EXPECT_EQ(occupancyFromCost(128), 50);  // 1 + 97 * 127 / 251
  EXPECT_EQ(occupancyFromCost(252), 98);
  EXPECT_EQ(occupancyFromCost(cost::INSCRIBED), 99);
  EXPECT_EQ(occupancyFromCost(cost::LETHAL), 100);
  EXPECT_EQ(occupancyFromCost(cost::NO_INFORMATION), -1);
  int previous = 0;
  for (int c = 1; c < 253; ++c)
  {
    const int o = occupancyFromCost(static_cast<uint8_t>(c));
    EXPECT_GE(o, previous) << c;  // monotonic
    EXPECT_LE(o, 98) << c;
    previous = o;
  }
}

TEST(CostmapRos, GridMessageHasTheCostmapsGeometry)
{
  Costmap2D costmap(4, 3, 0.05, -1.0, 2.0);
  costmap.setCost(3, 2, cost::LETHAL);
  costmap.setCost(0, 1, cost::NO_INFORMATION);
  nav_msgs::OccupancyGrid grid;
  toOccupancyGrid(costmap, grid);
  EXPECT_EQ(grid.info.width, 4u);
  EXPECT_EQ(grid.info.height, 3u);
  EXPECT_FLOAT_EQ(grid.info.resolution, 0.05f);
  EXPECT_DOUBLE_EQ(grid.info.origin.position.x, -1.0);
  EXPECT_DOUBLE_EQ(grid.info.origin.position.y, 2.0);
  EXPECT_DOUBLE_EQ(grid.info.origin.orientation.w, 1.0);
  ASSERT_EQ(grid.data.size(), 12u);
  EXPECT_EQ(grid.data[2 * 4 + 3], 100);  // row-major, row 0 at the origin, as the costmap
  EXPECT_EQ(grid.data[1 * 4 + 0], -1);
  EXPECT_EQ(grid.data[0], 0);
}

TEST(CostmapRos, TeammatesArePaddedUnlessThatTrapsTheRobot)
{
  TeammateState mate;
  mate.radius = 0.15;
  const double own = 0.15, res = 0.05, padding = 0.1;
  // Far away: padded.
  mate.pose = Pose2D{2.0, 0.0, 0.0};
  EXPECT_DOUBLE_EQ(drawableTeammates({mate}, Pose2D{}, own, res, padding)[0].radius, 0.25);
  // 0.45 m away: the padding may only grow the disc to 0.45 - 0.15 - 0.1 = 0.2 m.
  mate.pose = Pose2D{0.45, 0.0, 0.0};
  EXPECT_NEAR(drawableTeammates({mate}, Pose2D{}, own, res, padding)[0].radius, 0.2, 1e-12);
  // Touching: never smaller than the footprint.
  mate.pose = Pose2D{0.0, 0.3, 0.0};
  EXPECT_DOUBLE_EQ(drawableTeammates({mate}, Pose2D{}, own, res, padding)[0].radius, 0.15);
  // Everything else is passed on.
  mate.vx = 0.4;
  const TeammateState out = drawableTeammates({mate}, Pose2D{}, own, res, padding)[0];
  EXPECT_DOUBLE_EQ(out.vx, 0.4);
  EXPECT_DOUBLE_EQ(out.pose.y, 0.3);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
