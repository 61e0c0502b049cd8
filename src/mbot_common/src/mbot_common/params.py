"""Strict ROS parameters: a parameter of the wrong type is an error that names it, not a value
used anyway. rospy is imported inside get_param(), so this module imports without ROS.

    rate = get_param("~rate", 10.0, float)                 # [Hz]
    robots = get_param("~robots", REQUIRED, list)
    config = read_params(rospy.get_param("~"), {"gain": (float, 1.0), "leader": (str, REQUIRED)},
                         rospy.get_name())              # also rejects unknown private parameters
"""
from mbot_common.strict_yaml import KIND_NAMES, REQUIRED, ConfigError, Reader, convert, describe

__all__ = ["REQUIRED", "check_param", "get_param", "read_params"]


def check_param(full_name, value, kind, what=None, check=None):
    """`value` of the parameter `full_name` as `kind` (float, int, bool, str, list, dict); ConfigError
    "parameter <name>: expected <what>, got <value>" otherwise."""
    result = convert(value, kind)
    if result is None or (check is not None and not check(result)):
        raise ConfigError("parameter %s: expected %s, got %s" % (full_name, what or KIND_NAMES[kind], describe(value)))
    return result


def get_param(name, default, kind, what=None, check=None):
    """rospy.get_param(name) checked to be a `kind` (float accepts an int, never a bool or a
    string). default: returned when the parameter is not set (REQUIRED: then it is an error).
    what / check: as Reader.required()."""
    import rospy  # here, so that the module imports without ROS
    full_name = rospy.resolve_name(name)
    if not rospy.has_param(name):
        if default is REQUIRED:
            raise ConfigError("parameter %s: missing (required)" % full_name)
        return default
    return check_param(full_name, rospy.get_param(name), kind, what, check)


def read_params(params, spec, where="parameters"):
    """Check a dict of parameters (e.g. rospy.get_param("~")) against `spec`, {name: (kind,
    default)} (default REQUIRED: must be set). Returns {name: value}; ConfigError
    "<where>: <name>: <problem>" for a wrong type, a missing one or one not in spec (a typo)."""
    r = Reader({} if params is None else params, where)
    values = {}
    for name, (kind, default) in spec.items():
        if default is REQUIRED:
            values[name] = r.required(name, kind)
        else:
            values[name] = r.optional(name, kind, default)
    r.finish()
    return values
