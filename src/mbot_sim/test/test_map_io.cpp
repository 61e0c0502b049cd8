/**
 * @file test_map_io.cpp
 * @brief map_server-compatible map loading: thresholds, negate, trinary values, the image flip,
 *        P2/P5/maxval, and the error messages for bad files.
 */
#include "mbot_sim/map_io.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

using mbot_sim::loadMap;
using mbot_sim::MapError;
using mbot_sim::OccupancyMap;

namespace
{
const std::string kFixtures = MBOT_SIM_FIXTURES;

/// The error message of loading `file`, or "" when it loads.
std::string loadError(const std::string& file)
{
  try
  {
    loadMap(kFixtures + "/" + file);
  }
  catch (const MapError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

// tiny.pgm, top row first: 0 100 160 / 200 254 255. With occupied 0.65 and free 0.196,
// occupancy p = (255 - v) / 255: 1.0 -> 100, 0.61 / 0.37 / 0.22 -> -1, 0.004 / 0 -> 0.
// Map row 0 is the image's bottom row.
TEST(MapIo, TrinaryValuesAndFlipAsMapServer)
{
  const OccupancyMap map = loadMap(kFixtures + "/tiny.yaml");
  EXPECT_EQ(map.width, 3u);
  EXPECT_EQ(map.height, 2u);
  EXPECT_DOUBLE_EQ(map.resolution, 0.1);
  EXPECT_DOUBLE_EQ(map.origin_x, -1.0);
  EXPECT_DOUBLE_EQ(map.origin_y, 2.0);
  const std::vector<int8_t> expected = {-1, 0, 0, 100, -1, -1};
  EXPECT_EQ(map.data, expected);
  EXPECT_EQ(map.at(0, 1), 100);  // the image's top-left pixel (black) is the top-left cell
}

TEST(MapIo, NegateInvertsTheGreyValues)
{
  // negated: v' = 255 - v: 255 155 95 / 55 1 0 -> p = 0 0.39 0.63 / 0.78 0.996 1.0
  const OccupancyMap map = loadMap(kFixtures + "/tiny_negate.yaml");
  const std::vector<int8_t> expected = {100, 100, 100, 0, -1, -1};
  EXPECT_EQ(map.data, expected);
}

TEST(MapIo, ThresholdsAreStrictComparisons)
{
  // occupied 0.5, free 0.25: p = 1.0 0.61 0.37 / 0.22 0.004 0 -> 100 100 -1 / 0 0 0
  const OccupancyMap map = loadMap(kFixtures + "/tiny_thresholds.yaml");
  const std::vector<int8_t> expected = {0, 0, 0, 100, 100, -1};
  EXPECT_EQ(map.data, expected);
}

TEST(MapIo, BinaryP5AndScaledMaxvalGiveTheSameMap)
{
  const OccupancyMap text = loadMap(kFixtures + "/tiny.yaml");
  const OccupancyMap binary = loadMap(kFixtures + "/tiny_p5.yaml");
  EXPECT_EQ(binary.data, text.data);
  // maxval 15: 0 6 10 / 12 15 15 scale to 0 102 170 / 204 255 255 -> same classes as tiny.pgm
  const OccupancyMap scaled = loadMap(kFixtures + "/tiny_maxval15.yaml");
  EXPECT_EQ(scaled.data, text.data);
}

TEST(MapIo, RoomFixtureHasWallsAroundAndFreeInside)
{
  const OccupancyMap map = loadMap(kFixtures + "/room.yaml");
  ASSERT_EQ(map.width, 200u);
  ASSERT_EQ(map.height, 160u);
  EXPECT_EQ(map.at(0, 0), 100);
  EXPECT_EQ(map.at(1, 80), 100);     // x = 0.075 m: inside the 0.1 m west wall
  EXPECT_EQ(map.at(2, 80), 0);       // x = 0.125 m: free
  EXPECT_EQ(map.at(100, 80), 0);     // the middle
  EXPECT_EQ(map.at(145, 30), 100);   // x = 7.25, y = 1.5: the wall block
  EXPECT_EQ(map.at(145, 70), 0);     // x = 7.25, y = 3.5: above the block
}

TEST(MapIo, ErrorsNameTheFileKeyAndProblem)
{
  std::string e = loadError("invalid_header.yaml");
  EXPECT_NE(e.find("invalid_header.pgm: bad PGM header: expected magic P5 (binary) or P2 (text), got \"P6\""),
            std::string::npos)
      << e;
  e = loadError("invalid_truncated.yaml");
  EXPECT_NE(e.find("invalid_truncated.pgm: truncated PGM: expected 16 bytes"), std::string::npos) << e;
  e = loadError("invalid_missing_image.yaml");
  EXPECT_NE(e.find("invalid_missing_image.yaml: image: cannot read"), std::string::npos) << e;
  EXPECT_NE(e.find("no_such_image.pgm"), std::string::npos) << e;
  e = loadError("invalid_map_key.yaml");
  EXPECT_NE(e.find("invalid_map_key.yaml: colour: unknown key"), std::string::npos) << e;
  e = loadError("invalid_map_origin.yaml");
  EXPECT_NE(e.find("invalid_map_origin.yaml: origin: expected a list of 3 numbers [x, y, yaw], got a list of 2"),
            std::string::npos)
      << e;
  e = loadError("no_such_map.yaml");
  EXPECT_NE(e.find("no_such_map.yaml: cannot read the file"), std::string::npos) << e;
}
