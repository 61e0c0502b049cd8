/**
 * @file map_server.h
 * @brief Where the map server finds a map, free of ROS types. The map itself is read by
 *        mbot_sim::loadMap (mbot_sim/map_io.h), the reader the simulator uses too.
 */
#pragma once

#include <string>

namespace mbot_navigation
{
namespace map_server
{
/// @brief The workspace's `maps` folder: the first `maps` directory found next to one of
///        `package_dir`'s ancestors (for src/mbot_navigation that is the folder next to src/).
/// @return the directory, or "" when there is none
std::string findMapsDirectory(const std::string& package_dir);

/// @brief The map file that `name` means. A bare name without '/' and without an extension
///        ("office") is `<maps_dir>/office.yaml`; anything else is a path, used as given.
/// @throws std::runtime_error for a bare name when maps_dir is ""
std::string resolveMapPath(const std::string& name, const std::string& maps_dir);

}  // namespace map_server
}  // namespace mbot_navigation
