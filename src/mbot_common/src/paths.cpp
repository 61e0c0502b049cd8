/**
 * @file paths.cpp
 * @brief The maps/worlds lookup (the search stage_node's resolveWorldPath and the map server's
 *        resolveMapPath do today, in one place).
 */
#include "mbot_common/paths.h"

#include <filesystem>

namespace mbot_common
{
namespace fs = std::filesystem;

namespace
{
std::string resolve(const std::string& name, const std::string& what, const std::string& suffix, bool is_path,
                    const std::vector<std::string>& maps_dirs)
{
  if (name.empty()) throw ConfigError(what + " \"\": expected a " + what + " name (maps/NAME" + suffix + ") or a path");
  if (is_path) return name;  // the reader reports a missing file with its name
  std::vector<std::string> candidates;
  for (const auto& dir : maps_dirs)
    if (!dir.empty()) candidates.push_back(dir + "/" + name + suffix);
  std::error_code ec;
  for (const auto& candidate : candidates)
    if (fs::is_regular_file(candidate, ec)) return candidate;
  std::string searched;
  for (const auto& candidate : candidates) searched += (searched.empty() ? "" : ", ") + candidate;
  if (searched.empty()) searched = "no maps/ folder was found";
  throw ConfigError(what + " \"" + name + "\": no " + what + " file of that name (searched " + searched + ")");
}
}  // namespace

std::string findMapsDirectory(const std::string& start)
{
  std::error_code ec;
  fs::path dir = fs::absolute(start, ec);
  if (ec) return "";
  for (; !dir.empty(); dir = dir.parent_path())
  {
    if (fs::is_directory(dir / "maps", ec)) return (dir / "maps").lexically_normal().string();
    if (dir == dir.parent_path()) break;  // reached the root
  }
  return "";
}

std::string workspaceMapsDirectory() { return findMapsDirectory(MBOT_COMMON_SOURCE_DIR); }

bool isWorldPath(const std::string& world)
{
  const std::string ext = ".yaml";
  return world.find('/') != std::string::npos ||
         (world.size() >= ext.size() && world.compare(world.size() - ext.size(), ext.size(), ext) == 0);
}

bool isMapPath(const std::string& map) { return map.find('/') != std::string::npos || fs::path(map).has_extension(); }

std::string resolveWorldPath(const std::string& world, const std::vector<std::string>& maps_dirs)
{
  return resolve(world, "world", ".world.yaml", isWorldPath(world), maps_dirs);
}

std::string resolveWorldPath(const std::string& world, const std::string& maps_dir)
{
  return resolveWorldPath(world, std::vector<std::string>{maps_dir, workspaceMapsDirectory()});
}

std::string resolveMapPath(const std::string& map, const std::vector<std::string>& maps_dirs)
{
  return resolve(map, "map", ".yaml", isMapPath(map), maps_dirs);
}

std::string resolveMapPath(const std::string& map, const std::string& maps_dir)
{
  return resolveMapPath(map, std::vector<std::string>{maps_dir, workspaceMapsDirectory()});
}

}  // namespace mbot_common
