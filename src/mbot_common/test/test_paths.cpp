/**
 * @file test_paths.cpp
 * @brief paths.h: names are looked up in the given maps directory, then in the workspace's
 *        maps/; paths are used as given; a name that is nowhere names every place searched.
 */
#include "mbot_common/paths.h"

#include <gtest/gtest.h>

#include <filesystem>
#include <string>

using namespace mbot_common;
namespace fs = std::filesystem;

namespace
{
const std::string kFixtures = MBOT_COMMON_FIXTURES;
// <workspace>/src/mbot_common -> <workspace>/maps
const std::string kWorkspaceMaps =
    (fs::path(MBOT_COMMON_SOURCE_DIR).parent_path().parent_path() / "maps").lexically_normal().string();
}  // namespace

TEST(Paths, FindsTheWorkspaceMaps)
{
  ASSERT_TRUE(fs::is_regular_file(kWorkspaceMaps + "/office.world.yaml")) << kWorkspaceMaps;
  EXPECT_EQ(workspaceMapsDirectory(), kWorkspaceMaps);
  EXPECT_EQ(findMapsDirectory(kFixtures + "/worlds"), kFixtures + "/maps");  // the fixtures' own maps/
  EXPECT_EQ(findMapsDirectory("/"), "");
}

TEST(Paths, NamesAndPaths)
{
  EXPECT_TRUE(isWorldPath("office.world.yaml"));
  EXPECT_TRUE(isWorldPath("worlds/office"));
  EXPECT_FALSE(isWorldPath("office"));
  EXPECT_TRUE(isMapPath("office.yaml"));
  EXPECT_FALSE(isMapPath("office"));
  EXPECT_EQ(resolveWorldPath("office"), kWorkspaceMaps + "/office.world.yaml");
  EXPECT_EQ(resolveMapPath("office"), kWorkspaceMaps + "/office.yaml");
  // the given directory first
  EXPECT_EQ(resolveWorldPath("valid_minimal", kFixtures + "/worlds"), kFixtures + "/worlds/valid_minimal.world.yaml");
  EXPECT_EQ(resolveMapPath("tiny", kFixtures + "/maps"), kFixtures + "/maps/tiny.yaml");
  EXPECT_EQ(resolveWorldPath("office", kFixtures + "/worlds"), kWorkspaceMaps + "/office.world.yaml");
  // a path as given, even when it does not exist (the reader names it)
  EXPECT_EQ(resolveWorldPath("some/where.world.yaml"), "some/where.world.yaml");
}

TEST(Paths, AnUnknownNameNamesWhatWasSearched)
{
  std::string message;
  try
  {
    resolveWorldPath("atlantis", kFixtures + "/worlds");
  }
  catch (const ConfigError& e)
  {
    message = e.what();
  }
  EXPECT_EQ(message, "world \"atlantis\": no world file of that name (searched " + kFixtures +
                         "/worlds/atlantis.world.yaml, " + kWorkspaceMaps + "/atlantis.world.yaml)");
  message.clear();
  try
  {
    resolveMapPath("atlantis", std::vector<std::string>{});
  }
  catch (const ConfigError& e)
  {
    message = e.what();
  }
  EXPECT_EQ(message, "map \"atlantis\": no map file of that name (searched no maps/ folder was found)");
}
