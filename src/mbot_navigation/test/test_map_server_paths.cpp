/**
 * @file test_map_server_paths.cpp
 * @brief gtest (no master): how the map server turns its argument into a map file.
 */
#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <stdexcept>

#include <unistd.h>  // getpid

#include "mbot_navigation/map_server.h"

using namespace mbot_navigation::map_server;
namespace fs = std::filesystem;

class MapPaths : public ::testing::Test
{
protected:
  void SetUp() override
  {
    // a workspace: <root>/maps and <root>/src/mbot_navigation
    root_ = fs::temp_directory_path() / ("mbot_map_paths_" + std::to_string(::getpid()));
    fs::create_directories(root_ / "maps");
    fs::create_directories(root_ / "src" / "mbot_navigation");
  }
  void TearDown() override { fs::remove_all(root_); }
  fs::path root_;
};

TEST_F(MapPaths, FindsTheMapsFolderNextToSrc)
{
  EXPECT_EQ(findMapsDirectory((root_ / "src" / "mbot_navigation").string()), (root_ / "maps").string());
  fs::remove_all(root_ / "maps");
  // without a maps folder on the way up (the temp dir has none) there is nothing to find
  const std::string found = findMapsDirectory((root_ / "src" / "mbot_navigation").string());
  EXPECT_TRUE(found.empty() || found.find(root_.string()) == std::string::npos) << found;
}

TEST_F(MapPaths, BareNamesResolveToTheMapsFolderAndPathsStay)
{
  const std::string maps = (root_ / "maps").string();
  EXPECT_EQ(resolveMapPath("office", maps), (root_ / "maps" / "office.yaml").string());
  EXPECT_EQ(resolveMapPath("office.yaml", maps), "office.yaml");  // a file name: used as given
  EXPECT_EQ(resolveMapPath("/tmp/x/office.yaml", maps), "/tmp/x/office.yaml");
  EXPECT_EQ(resolveMapPath("test/maps/fixture", maps), "test/maps/fixture");
  try
  {
    resolveMapPath("office", "");
    FAIL() << "a bare name without a maps folder must throw";
  }
  catch (const std::runtime_error& e)
  {
    EXPECT_NE(std::string(e.what()).find("office"), std::string::npos) << e.what();
  }
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
