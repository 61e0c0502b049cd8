/**
 * @file test_map_io.cpp
 * @brief map_io.h: map_server's values for every mode (trinary, scale, raw), negate, thresholds,
 *        the image flip, P2/P5/maxval/16-bit images, cell <-> world, and each invalid map
 *        fixture's message (the same expectations as test_common_maps.py).
 */
#include "mbot_common/map_io.h"

#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "mbot_common/testing/fixture_cases.h"

using mbot_common::loadMap;
using mbot_common::MapError;
using mbot_common::MapMode;
using mbot_common::OccupancyMap;

namespace
{
const std::string kMaps = std::string(MBOT_COMMON_FIXTURES) + "/maps";

std::vector<int8_t> dataOf(const std::string& file) { return loadMap(kMaps + "/" + file).data; }
}  // namespace

// tiny.pgm, top row first: 0 100 160 / 200 254 255. With occupied 0.65 and free 0.196,
// p = (255 - v) / 255: 1.0 -> 100, 0.61 / 0.37 / 0.22 -> -1, 0.004 / 0 -> 0.
// Map row 0 is the image's bottom row.
TEST(MapIo, TrinaryValuesAndFlipAsMapServer)
{
  const OccupancyMap map = loadMap(kMaps + "/tiny.yaml");
  EXPECT_EQ(map.width, 3u);
  EXPECT_EQ(map.height, 2u);
  EXPECT_DOUBLE_EQ(map.resolution, 0.1);
  EXPECT_DOUBLE_EQ(map.origin_x, -1.0);
  EXPECT_DOUBLE_EQ(map.origin_y, 2.0);
  EXPECT_DOUBLE_EQ(map.occupied_thresh, 0.65);
  EXPECT_DOUBLE_EQ(map.free_thresh, 0.196);
  EXPECT_FALSE(map.negate);
  EXPECT_EQ(map.mode, MapMode::TRINARY);
  EXPECT_EQ(map.image_path, kMaps + "/tiny.pgm");
  EXPECT_EQ(map.data, (std::vector<int8_t>{-1, 0, 0, 100, -1, -1}));
  EXPECT_EQ(map.at(0, 1), 100);  // the image's top-left pixel (black) is the top-left cell
}

TEST(MapIo, NegateAndThresholds)
{
  // negated: v' = 255 - v: 255 155 95 / 55 1 0 -> p = 0 0.39 0.63 / 0.78 0.996 1.0
  EXPECT_EQ(dataOf("tiny_negate.yaml"), (std::vector<int8_t>{100, 100, 100, 0, -1, -1}));
  // occupied 0.5, free 0.25: p = 1.0 0.61 0.37 / 0.22 0.004 0 -> 100 100 -1 / 0 0 0
  EXPECT_EQ(dataOf("tiny_thresholds.yaml"), (std::vector<int8_t>{0, 0, 0, 100, 100, -1}));
}

TEST(MapIo, ScaleAndRawModes)
{
  // scale: between the thresholds 1 + 98 (p - 0.196) / (0.65 - 0.196), truncated:
  // v 200 -> p 0.2157 -> 5.25 -> 5; v 100 -> p 0.6078 -> 89.9 -> 89; v 160 -> p 0.3725 -> 39.1 -> 39
  EXPECT_EQ(dataOf("tiny_scale.yaml"), (std::vector<int8_t>{5, 0, 0, 100, 89, 39}));
  // raw: the grey value in an int8, as map_server stores it: 200 -> -56, 254 -> -2, 160 -> -96
  EXPECT_EQ(dataOf("tiny_raw.yaml"), (std::vector<int8_t>{-56, -2, -1, 0, 100, -96}));
  // raw with negate: 255 - v: 55 1 0 / 255 155 95
  EXPECT_EQ(dataOf("tiny_raw_negate.yaml"), (std::vector<int8_t>{55, 1, 0, -1, -101, 95}));
  EXPECT_EQ(loadMap(kMaps + "/tiny_raw_negate.yaml").mode, MapMode::RAW);
}

TEST(MapIo, EveryImageFlavourGivesTheSameMap)
{
  const std::vector<int8_t> text = dataOf("tiny.yaml");
  EXPECT_EQ(dataOf("tiny_p5.yaml"), text);
  // maxval 15: 0 6 10 / 12 15 15 scale to 0 102 170 / 204 255 255 -> same classes as tiny.pgm
  EXPECT_EQ(dataOf("tiny_maxval15.yaml"), text);
  // 16-bit big-endian, maxval 1000: 0 392 627 / 784 996 1000 -> 0 99 159 / 199 253 255
  EXPECT_EQ(dataOf("tiny_16bit.yaml"), text);
}

TEST(MapIo, CellsAndWorldPoints)
{
  const OccupancyMap map = loadMap(kMaps + "/tiny.yaml");  // origin (-1, 2), 0.1 m/cell
  EXPECT_EQ(map.worldToCell(-0.95, 2.15), (std::array<int, 2>{0, 1}));
  EXPECT_EQ(map.worldToCell(-0.71, 2.01), (std::array<int, 2>{2, 0}));
  EXPECT_EQ(map.worldToCell(-1.01, 2.0), (std::array<int, 2>{-1, 0}));
  EXPECT_FALSE(map.inBounds(-1, 0));
  EXPECT_NEAR(map.cellToWorld(2, 1).x, -0.75, 1e-12);
  EXPECT_NEAR(map.cellToWorld(2, 1).y, 2.15, 1e-12);
  // origin (1, 1) turned by pi/2, 0.5 m/cell: the grid's x runs along the map's +y
  const OccupancyMap rotated = loadMap(kMaps + "/tiny_rotated.yaml");
  EXPECT_NEAR(rotated.cellToWorld(2, 1).x, 0.25, 1e-12);
  EXPECT_NEAR(rotated.cellToWorld(2, 1).y, 2.25, 1e-12);
  EXPECT_EQ(rotated.worldToCell(0.25, 2.25), (std::array<int, 2>{2, 1}));
}

TEST(MapIo, EachInvalidFixtureGivesItsMessage)
{
  const auto cases = mbot_common_test::invalidFixtures(kMaps, ".yaml");
  EXPECT_GE(cases.size(), 14u);
  for (const auto& c : cases)
  {
    ASSERT_FALSE(c.expected.empty()) << c.path << ": no '# expect: ' first line";
    std::string message;
    try
    {
      loadMap(c.path);
    }
    catch (const MapError& e)
    {
      message = e.what();
    }
    EXPECT_NE(message.find(c.expected), std::string::npos)
        << "fixture " << c.path << "\n  got:      " << message << "\n  expected: " << c.expected;
    EXPECT_EQ(message.find('\n'), std::string::npos) << "one line: " << message;
  }
  std::string missing;
  try
  {
    loadMap(kMaps + "/no_such_map.yaml");
  }
  catch (const MapError& e)
  {
    missing = e.what();
  }
  EXPECT_EQ(missing, kMaps + "/no_such_map.yaml: cannot read the file (missing or unreadable)");
}
