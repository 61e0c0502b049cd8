"""mbot_common.params: a ROS parameter of the wrong type is an error naming it. rospy is
replaced by a stand-in that holds a parameter dict, so no master is needed."""
import sys
import types

import pytest

from mbot_common.params import REQUIRED, get_param, read_params
from mbot_common.strict_yaml import ConfigError


@pytest.fixture
def fake_rospy(monkeypatch):
    server = {"/follower/gain": 2, "/follower/name": "leader", "/follower/rate": "fast", "/follower/on": True}
    rospy = types.ModuleType("rospy")
    rospy.resolve_name = lambda name: "/follower/" + name[1:] if name.startswith("~") else name
    rospy.has_param = lambda name: rospy.resolve_name(name) in server
    rospy.get_param = lambda name: server[rospy.resolve_name(name)]
    monkeypatch.setitem(sys.modules, "rospy", rospy)
    return server


def test_get_param_checks_the_kind(fake_rospy):
    assert get_param("~gain", 1.0, float) == 2.0 and isinstance(get_param("~gain", 1.0, float), float)
    assert get_param("~name", REQUIRED, str) == "leader"
    assert get_param("~absent", 0.5, float) == 0.5
    with pytest.raises(ConfigError) as info:
        get_param("~rate", 10.0, float)
    assert str(info.value) == 'parameter /follower/rate: expected a number, got "fast"'
    with pytest.raises(ConfigError, match='parameter /follower/on: expected a number, got "true"'):
        get_param("~on", 1.0, float)
    with pytest.raises(ConfigError, match="parameter /follower/absent: missing"):
        get_param("~absent", REQUIRED, float)
    with pytest.raises(ConfigError, match=r'expected a number > 0 \[1/s\], got "2"'):
        get_param("~gain", 1.0, float, what="a number > 0 [1/s]", check=lambda v: v > 2)


def test_read_params_rejects_wrong_types_missing_and_unknown():
    spec = {"gain": (float, 1.0), "leader": (str, REQUIRED)}
    assert read_params({"leader": "robot_0"}, spec, "/follower") == {"gain": 1.0, "leader": "robot_0"}
    with pytest.raises(ConfigError) as info:
        read_params({"leader": "robot_0", "gian": 2.0}, spec, "/follower")
    assert str(info.value) == "/follower: gian: unknown key (expected one of gain, leader)"
    with pytest.raises(ConfigError, match="/follower: leader: missing key"):
        read_params({}, spec, "/follower")
    with pytest.raises(ConfigError, match='/follower: gain: expected a number, got "x"'):
        read_params({"leader": "a", "gain": "x"}, spec, "/follower")


def test_module_imports_without_rospy():
    assert "mbot_common.params" in sys.modules
