// MovingAI readers: the shipped benchmark files read as their SOURCE.txt describes them; every kind
// of malformed file is an error naming the file, the line and the problem.
#include <gtest/gtest.h>

#include <string>

#include "mbot_coordination/movingai.h"

using namespace mbot_coordination;

namespace
{
const std::string kDir = MAPF_BENCH_DIR;
const std::string kMap = "type octile\nheight 2\nwidth 3\nmap\n.@.\n..T\n";

// The message of the FormatError parsing `text` throws ("" when none).
std::string mapError(const std::string& text)
{
  try
  {
    parseMap(text, "bad.map");
  }
  catch (const FormatError& e)
  {
    return e.what();
  }
  return "";
}

std::string scenError(const std::string& text, const Grid* grid)
{
  try
  {
    parseScen(text, "bad.scen", grid);
  }
  catch (const FormatError& e)
  {
    return e.what();
  }
  return "";
}

std::string row(const std::string& fields) { return "version 1\n" + fields + "\n"; }
}  // namespace

TEST(MapReader, SmallMap)
{
  const Grid g = parseMap(kMap, "small.map");
  EXPECT_EQ(g.width(), 3);
  EXPECT_EQ(g.height(), 2);
  EXPECT_TRUE(g.isFree(0, 0));
  EXPECT_FALSE(g.isFree(1, 0));
  EXPECT_FALSE(g.isFree(2, 1));
  EXPECT_EQ(g.freeCount(), 4);
  EXPECT_EQ(g.neighbours(g.id(0, 0)).size(), 1u);  // only (0,1): (1,0) is blocked
  EXPECT_TRUE(g.adjacent(g.id(0, 1), g.id(1, 1)));
}

TEST(MapReader, BenchmarkMaps)
{
  // free cell counts from SOURCE.txt (counted there independently of this reader)
  const std::pair<const char*, int> maps[] = {{"empty-32-32", 1024},
                                              {"random-32-32-10", 922},
                                              {"room-32-32-4", 682},
                                              {"maze-32-32-2", 666},
                                              {"warehouse-10-20-10-2-1", 5699}};
  for (const auto& m : maps)
  {
    const Grid g = readMap(kDir + "/" + m.first + ".map");
    EXPECT_EQ(g.freeCount(), m.second) << m.first;
  }
  const Grid w = readMap(kDir + "/warehouse-10-20-10-2-1.map");
  EXPECT_EQ(w.width(), 161);
  EXPECT_EQ(w.height(), 63);
}

TEST(MapReader, BadFiles)
{
  EXPECT_EQ(mapError("type grid\nheight 2\nwidth 3\nmap\n...\n...\n"),
            "bad.map:1: expected 'type octile', got 'type grid'");
  EXPECT_EQ(mapError("type octile\nheight x\nwidth 3\nmap\n...\n...\n"),
            "bad.map:2: expected 'height N', got 'height x'");
  EXPECT_EQ(mapError("type octile\nheight 2\nwidth 0\nmap\n...\n...\n"), "bad.map:3: width must be positive, got 0");
  EXPECT_EQ(mapError("type octile\nheight 2\nwidth 3\nmaps\n...\n...\n"), "bad.map:4: expected 'map', got 'maps'");
  EXPECT_EQ(mapError("type octile\nheight 2\nwidth 3\nmap\n...\n..\n"),
            "bad.map:6: row 1 has 2 characters, width is 3");
  EXPECT_EQ(mapError("type octile\nheight 3\nwidth 3\nmap\n...\n...\n"), "bad.map:7: expected 3 map rows, found 2");
  EXPECT_EQ(mapError("type octile\nheight 2\nwidth 3\nmap\n...\n.x.\n"),
            "bad.map:6: unknown map character 'x' at column 1");
  EXPECT_EQ(mapError("type octile\nheight 1\nwidth 3\nmap\n...\n...\n"),
            "bad.map:6: text after the 1 map rows (height too small?)");
  EXPECT_EQ(mapError("type octile\nheight 2\n"), "bad.map:3: header ends early");
  try
  {
    readMap(kDir + "/no-such.map");
    FAIL() << "no error for a missing file";
  }
  catch (const FormatError& e)
  {
    EXPECT_EQ(std::string(e.what()), kDir + "/no-such.map: cannot open the file");
  }
}

TEST(ScenReader, BenchmarkScenario)
{
  const Grid g = readMap(kDir + "/random-32-32-10.map");
  const auto rows = readScen(kDir + "/random-32-32-10-random-1.scen", &g);
  ASSERT_EQ(rows.size(), 461u);  // SOURCE.txt
  // the file's first row: 3 random-32-32-10.map 32 32 11 6 7 18 13.65685425
  EXPECT_EQ(rows[0].bucket, 3);
  EXPECT_EQ(rows[0].map, "random-32-32-10.map");
  EXPECT_EQ(rows[0].start_x, 11);
  EXPECT_EQ(rows[0].start_y, 6);
  EXPECT_EQ(rows[0].goal_x, 7);
  EXPECT_EQ(rows[0].goal_y, 18);
  EXPECT_NEAR(rows[0].optimal_length, 13.65685425, 1e-9);
  EXPECT_EQ(rows[0].line, 2);
}

TEST(ScenReader, BadFiles)
{
  const Grid g = parseMap(kMap, "small.map");
  EXPECT_EQ(scenError("version 2\n", nullptr), "bad.scen:1: expected 'version 1', got 'version 2'");
  EXPECT_EQ(scenError("version 1\n", nullptr), "bad.scen:1: no scenario rows");
  EXPECT_EQ(scenError(row("0\ts.map\t3\t2\t0\t0\t2"), nullptr),
            "bad.scen:2: expected 9 tab-separated fields (bucket, map, width, height, start x, start y, goal x, goal "
            "y, optimal length), got 7");
  EXPECT_EQ(scenError(row("0 s.map 3 2 0 0 2 0 2"), nullptr).substr(0, 45),
            "bad.scen:2: expected 9 tab-separated fields (");
  EXPECT_EQ(scenError(row("0\ts.map\t3\t2\ta\t0\t2\t0\t2"), nullptr), "bad.scen:2: start x is not an integer: 'a'");
  EXPECT_EQ(scenError(row("0\ts.map\t3\t2\t0\t0\t2\t0\tfar"), nullptr),
            "bad.scen:2: optimal length is not a number >= 0: 'far'");
  EXPECT_EQ(scenError(row("0\ts.map\t4\t2\t0\t0\t2\t0\t2"), &g),
            "bad.scen:2: map size 4 x 2 differs from the map's 3 x 2");
  EXPECT_EQ(scenError(row("0\ts.map\t3\t2\t0\t0\t3\t1\t4"), &g), "bad.scen:2: goal (3,1) is outside the map");
  EXPECT_EQ(scenError(row("0\ts.map\t3\t2\t1\t0\t0\t1\t1"), &g), "bad.scen:2: start (1,0) is a blocked cell");
  EXPECT_EQ(scenError("version 1\n0\ts.map\t3\t2\t0\t0\t0\t1\t1\n\n0\ts.map\t3\t2\t0\t0\t0\t1\t1\n", nullptr),
            "bad.scen:3: empty line");
  // a good row on the small map
  EXPECT_EQ(parseScen(row("0\ts.map\t3\t2\t0\t0\t2\t0\t4"), "ok.scen", &g).size(), 1u);
}

TEST(OccupancyGrid, CoarseCellsWithRadius)
{
  // 10 x 10 fine cells of 0.1 m, one occupied cell at (5,5); 0.5 m coarse cells -> 2 x 2
  std::vector<int8_t> data(100, 0);
  data[5 * 10 + 5] = 100;
  const Grid none = Grid::fromOccupancy(data, 10, 10, 0.1, 0.5, 0.0);
  EXPECT_EQ(none.width(), 2);
  EXPECT_TRUE(none.isFree(0, 0));
  EXPECT_FALSE(none.isFree(1, 1));
  EXPECT_TRUE(none.isFree(1, 0));
  // a robot of 0.1 m radius in coarse cell (1,0) (fine x 5..9, y 0..4) reaches fine row 5: blocked
  const Grid padded = Grid::fromOccupancy(data, 10, 10, 0.1, 0.5, 0.1);
  EXPECT_FALSE(padded.isFree(1, 0));
  EXPECT_FALSE(padded.isFree(0, 0));  // and its padding reaches off the map (unknown)
  data[5 * 10 + 5] = -1;              // unknown blocks like occupied
  EXPECT_FALSE(Grid::fromOccupancy(data, 10, 10, 0.1, 0.5, 0.0).isFree(1, 1));
  EXPECT_THROW(Grid::fromOccupancy(data, 10, 9, 0.1, 0.5, 0.0), std::invalid_argument);
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
