#include "mbot_navigation/map_server.h"

#include <filesystem>
#include <stdexcept>

namespace mbot_navigation
{
namespace map_server
{
namespace fs = std::filesystem;

std::string findMapsDirectory(const std::string& package_dir)
{
  std::error_code ec;
  fs::path dir = fs::absolute(package_dir, ec);
  if (ec) return "";
  for (; !dir.empty(); dir = dir.parent_path())
  {
    if (fs::is_directory(dir / "maps", ec)) return (dir / "maps").string();
    if (dir == dir.parent_path()) break;  // reached the root
  }
  return "";
}

std::string resolveMapPath(const std::string& name, const std::string& maps_dir)
{
  const bool bare = name.find('/') == std::string::npos && !fs::path(name).has_extension();
  if (!bare) return name;
  if (maps_dir.empty())
    throw std::runtime_error("map '" + name + "': a bare map name needs the workspace's maps/ "
                             "folder, which was not found; give the path to the .yaml instead");
  return (fs::path(maps_dir) / (name + ".yaml")).string();
}

}  // namespace map_server
}  // namespace mbot_navigation
