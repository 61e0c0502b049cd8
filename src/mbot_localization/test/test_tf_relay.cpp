#include <gtest/gtest.h>

#include "mbot_localization/tf_relay.h"

using mbot_localization::robotOfTransform;

TEST(TfRelay, APoseTransformBelongsToTheRobotOfItsPrefix)
{
  const std::vector<std::string> frames{"odom", "base_footprint"};
  EXPECT_EQ(robotOfTransform("robot_3/base_footprint", frames), "robot_3");
  EXPECT_EQ(robotOfTransform("leader/odom", frames), "leader");
  EXPECT_EQ(robotOfTransform("/leader/odom", frames), "leader");  // tf1-style leading slash
}

TEST(TfRelay, OtherTransformsBelongToNoRobot)
{
  const std::vector<std::string> frames{"odom", "base_footprint"};
  EXPECT_EQ(robotOfTransform("robot_3/left_wheel", frames), "");  // a moving joint of the description
  EXPECT_EQ(robotOfTransform("odom", frames), "");                // no prefix
  EXPECT_EQ(robotOfTransform("/odom", frames), "");
  EXPECT_EQ(robotOfTransform("fleet/robot_3/odom", frames), "");  // a nested prefix is not a robot name
  EXPECT_EQ(robotOfTransform("", frames), "");
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
