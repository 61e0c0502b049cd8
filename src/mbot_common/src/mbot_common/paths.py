"""Where maps and worlds are: a bare name means a file in the workspace's maps/ folder, anything
else is a path (the C++ twin is paths.h; stage_node, the map server and the launch helpers look
names up the same way).

    resolve_world("office")                   -> <workspace>/maps/office.world.yaml
    resolve_world("test/worlds/x.world.yaml") -> its absolute path
    resolve_map("office")                     -> <workspace>/maps/office.yaml
"""
import os

from mbot_common.strict_yaml import ConfigError


def find_maps_directory(start=None):
    """The first folder named `maps` in `start` or one of its parents (start: default this
    file's directory, i.e. the workspace's maps/ from the source tree), or None."""
    d = os.path.abspath(start if start is not None else os.path.dirname(__file__))
    while True:
        candidate = os.path.join(d, "maps")
        if os.path.isdir(candidate):
            return candidate
        parent = os.path.dirname(d)
        if parent == d:
            return None
        d = parent


def is_world_path(world):
    """True if `world` is a path (has a / or ends in .yaml), False if it is a name."""
    return "/" in world or world.endswith(".yaml")


def is_map_path(map_name):
    """True if `map_name` is a path (has a / or an extension), False if it is a name."""
    return "/" in map_name or os.path.splitext(map_name)[1] != ""


def _resolve(name, what, suffix, is_path, maps_dir):
    if not isinstance(name, str) or not name:
        raise ConfigError("%s %r: expected a %s name (maps/NAME%s) or a path" % (what, name, what, suffix))
    if is_path(name):
        return os.path.abspath(name)  # the reader reports a missing file with its name
    directories = [d for d in (maps_dir, find_maps_directory()) if d]
    candidates = [os.path.join(d, name + suffix) for d in directories]
    for candidate in candidates:
        if os.path.isfile(candidate):
            return os.path.abspath(candidate)
    searched = ", ".join(candidates) if candidates else "no maps/ folder was found"
    raise ConfigError('%s "%s": no %s file of that name (searched %s)' % (what, name, what, searched))


def resolve_world(name_or_path, maps_dir=None):
    """The absolute path of a world file. A name (no / and not ending in .yaml) is
    NAME.world.yaml in `maps_dir` (if given), else in the workspace's maps/, as stage_node looks
    it up; a path is made absolute. ConfigError naming every place searched for a name."""
    return _resolve(name_or_path, "world", ".world.yaml", is_world_path, maps_dir)


def resolve_map(name_or_path, maps_dir=None):
    """The absolute path of a map yaml. A name (no / and no extension) is NAME.yaml in
    `maps_dir` (if given), else in the workspace's maps/; a path is made absolute."""
    return _resolve(name_or_path, "map", ".yaml", is_map_path, maps_dir)
