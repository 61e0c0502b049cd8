/**
 * @file paths.h
 * @brief Where maps and worlds are: a bare name means a file in the workspace's maps/ folder
 *        (`office` -> maps/office.world.yaml or maps/office.yaml), anything else is a path used as
 *        given. The search order is stage_node's: an explicit maps directory first, then the
 *        workspace's maps/. Free of ROS types (the Python twin is mbot_common.paths).
 */
#pragma once

#include <string>
#include <vector>

#include "mbot_common/strict_yaml.h"

namespace mbot_common
{
/// @brief The first folder named `maps` in `start` or one of its parents; "" if there is none.
std::string findMapsDirectory(const std::string& start);

/// @brief The workspace's maps/ folder found from mbot_common's source directory (where it was
///        built from); "" if there is none (an install without the source tree).
std::string workspaceMapsDirectory();

/// @brief True if `world` is a path (has a '/' or ends in ".yaml"), false if it is a name.
bool isWorldPath(const std::string& world);

/// @brief True if `map` is a path (has a '/' or an extension), false if it is a name.
bool isMapPath(const std::string& map);

/// @brief The world file that `world` means: a path as given; a name NAME.world.yaml in the first
///        of `maps_dirs` (empty entries skipped) that has it.
/// @throws ConfigError `world "NAME": no world file of that name (searched A, B)`
std::string resolveWorldPath(const std::string& world, const std::vector<std::string>& maps_dirs);

/// @brief resolveWorldPath() in `maps_dir` (if not empty), then in workspaceMapsDirectory().
std::string resolveWorldPath(const std::string& world, const std::string& maps_dir = "");

/// @brief The map yaml that `map` means: a path as given; a name NAME.yaml in the first of
///        `maps_dirs` that has it. @throws ConfigError naming every place searched
std::string resolveMapPath(const std::string& map, const std::vector<std::string>& maps_dirs);

/// @brief resolveMapPath() in `maps_dir` (if not empty), then in workspaceMapsDirectory().
std::string resolveMapPath(const std::string& map, const std::string& maps_dir = "");

}  // namespace mbot_common
