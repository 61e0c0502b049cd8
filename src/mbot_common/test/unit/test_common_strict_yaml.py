"""mbot_common.strict_yaml: every kind of mistake is a one-line ConfigError naming the file,
the key path and what was expected; correct files read into the right values."""
import pytest

from mbot_common.strict_yaml import REQUIRED, ConfigError, Reader, describe, load_yaml


def write(tmp_path, text, name="c.yaml"):
    path = tmp_path / name
    path.write_text(text)
    return str(path)


def error_of(function, *args, **kwargs):
    with pytest.raises(ConfigError) as info:
        function(*args, **kwargs)
    message = str(info.value)
    assert "\n" not in message
    return message


def test_config_error_is_a_value_error_of_one_line():
    error = ConfigError("f.yaml: a: first line\nsecond line")
    assert isinstance(error, ValueError)
    assert str(error) == "f.yaml: a: first line second line"


def test_load_yaml_names_the_file_and_the_line(tmp_path):
    assert error_of(load_yaml, str(tmp_path / "none.yaml")) == \
        "%s: cannot read the file (missing or unreadable)" % (tmp_path / "none.yaml")
    bad = write(tmp_path, "a: 1\nb: [1, 2\n")
    message = error_of(load_yaml, bad)
    assert message.startswith(bad + ": not valid YAML: line 3, column 1: ")
    assert load_yaml(write(tmp_path, "", "empty.yaml")) is None


def test_duplicate_keys_are_errors_with_their_path(tmp_path):
    path = write(tmp_path, "seed: 1\nseed: 2\n")
    assert error_of(load_yaml, path) == path + ": seed: duplicate key (line 2)"
    path = write(tmp_path, "robots:\n  - name: a\n    pose: [0, 0, 0]\n    name: b\n")
    assert error_of(load_yaml, path) == path + ": robots[0].name: duplicate key (line 4)"


def test_reader_reads_each_kind(tmp_path):
    r = Reader.from_file(write(tmp_path, "f: 1\ng: 2.5\ni: 3\nb: true\ns: text\nl: [1, 2]\nd: {k: 1}\nn: null\n"))
    assert r.required("f", float) == 1.0 and isinstance(r.required("f", float), float)
    assert r.required("g", float) == 2.5
    assert r.required("i", int) == 3
    assert r.required("b", bool) is True
    assert r.required("s", str) == "text"
    assert r.required("l", list) == [1, 2]
    assert r.required("d", dict) == {"k": 1}
    assert r.required("n", object) is None
    assert r.optional("absent", float, 0.25) == 0.25
    r.finish()


@pytest.mark.parametrize("text, kind, message", [
    ('v: "0.5"', float, 'v: expected a number, got "0.5"'),
    ("v: true", float, 'v: expected a number, got "true"'),
    ("v: .inf", float, 'v: expected a number, got "inf"'),
    ("v: 1.5", int, 'v: expected an integer, got "1.5"'),
    ("v: false", int, 'v: expected an integer, got "false"'),
    ("v: 1", bool, 'v: expected true or false, got "1"'),
    ("v: 3", str, 'v: expected a string, got "3"'),
    ("v: {a: 1}", list, "v: expected a list, got a map"),
    ("v: [1]", dict, "v: expected a map, got a list of 1"),
    ("v:", float, "v: expected a number, got nothing"),
])
def test_wrong_types_name_the_key_and_what_was_expected(tmp_path, text, kind, message):
    path = write(tmp_path, text + "\n")
    assert error_of(Reader.from_file(path).required, "v", kind) == path + ": " + message
    assert error_of(Reader.from_file(path).optional, "v", kind, None) == path + ": " + message


def test_what_and_check_give_range_errors(tmp_path):
    path = write(tmp_path, "speed: -0.5\n")
    r = Reader.from_file(path)
    assert error_of(r.required, "speed", float, what="a number > 0 [m/s]", check=lambda v: v > 0) == \
        path + ': speed: expected a number > 0 [m/s], got "-0.5"'


def test_missing_required_key(tmp_path):
    path = write(tmp_path, "a: 1\n")
    assert error_of(Reader.from_file(path).required, "b", float) == path + ": b: missing key (required)"


def test_number_list(tmp_path):
    path = write(tmp_path, 'pose: [1, 2.5, -3]\nbad: "1.0"\nshort: [1, 2]\nword: [1, x, 2]\n')
    r = Reader.from_file(path)
    assert r.number_list("pose", 3) == [1.0, 2.5, -3.0]
    assert r.number_list("absent", 2, default=(0, 1)) == [0.0, 1.0]
    what = "a list of 3 numbers [x, y, yaw]"
    assert error_of(r.number_list, "bad", 3, what=what) == path + ': bad: ' + \
        'expected a list of 3 numbers [x, y, yaw], got "1.0"'
    assert error_of(r.number_list, "short", 3) == path + ": short: expected a list of 3 numbers, got a list of 2"
    assert error_of(r.number_list, "word", 3) == path + ': word: expected a list of 3 numbers, got "x"'
    assert error_of(r.number_list, "none", 3, default=REQUIRED) == path + ": none: missing key (required)"


def test_children_and_child_carry_the_key_path(tmp_path):
    path = write(tmp_path, "robots:\n  - name: a\n    pose: [0, 0, 0]\n  - name: b\n    pose: \"1.0\"\n"
                           "noise:\n  laser: {sigma: x}\n")
    r = Reader.from_file(path)
    robots = r.children("robots")
    assert [robot.where for robot in robots] == [path + ": robots[0]", path + ": robots[1]"]
    assert robots[0].required("name", str) == "a"
    assert error_of(robots[1].number_list, "pose", 3, what="a list of 3 numbers [x, y, yaw]") == \
        path + ': robots[1].pose: expected a list of 3 numbers [x, y, yaw], got "1.0"'
    laser = r.child("noise").child("laser")
    assert laser.where == path + ": noise.laser"
    assert error_of(laser.required, "sigma", float) == path + ': noise.laser.sigma: expected a number, got "x"'


def test_children_errors_and_optional_sections(tmp_path):
    path = write(tmp_path, "robots: {name: a}\nlist: [1]\nempty:\n")
    r = Reader.from_file(path)
    assert error_of(r.children, "robots") == path + ": robots: expected a list, got a map"
    assert error_of(r.children, "list") == path + ': list[0]: expected a map, got "1"'
    assert error_of(r.children, "absent") == path + ": absent: missing key (required)"
    assert r.children("absent", required=False) == []
    assert r.children("empty", required=False) == []
    assert error_of(r.child, "absent") == path + ": absent: missing key (required)"
    assert r.child("absent", required=False).optional("x", float, 1.5) == 1.5
    assert error_of(r.child, "empty") == path + ": empty: expected a map, got nothing"


def test_finish_names_unknown_keys_here_and_in_children(tmp_path):
    path = write(tmp_path, "rate: 10\nrat: 5\n")
    r = Reader.from_file(path)
    r.required("rate", float)
    r.optional("gain", float, 1.0)
    assert error_of(r.finish) == path + ": rat: unknown key (expected one of rate, gain)"

    path = write(tmp_path, "robots:\n  - name: a\n    colour: red\n    size: 2\n")
    r = Reader.from_file(path)
    for robot in r.children("robots"):
        robot.required("name", str)
    assert error_of(r.finish) == path + ": robots[0]: unknown keys colour, size (expected one of name)"


def test_check_keys_checks_before_reading(tmp_path):
    path = write(tmp_path, "map: m.yaml\ngravity: 9.81\n")
    r = Reader.from_file(path)
    assert error_of(r.check_keys, ["map", "seed"]) == path + ": gravity: unknown key (expected one of map, seed)"
    r = Reader.from_file(write(tmp_path, "seed: 1\n", "b.yaml"))
    assert error_of(r.check_keys, ["map", "seed"], required=["map"]).endswith("b.yaml: map: missing key (required)")


def test_top_level_must_be_a_map(tmp_path):
    path = write(tmp_path, "- 1\n- 2\n")
    assert error_of(Reader.from_file, path) == path + ": (top level): expected a map of keys, got a list of 2"
    path = write(tmp_path, "", "empty.yaml")
    assert error_of(Reader.from_file, path) == path + ": (top level): expected a map of keys, got nothing"


def test_describe():
    assert describe(None) == "nothing"
    assert describe({}) == "a map"
    assert describe([1, 2]) == "a list of 2"
    assert describe("1.0") == '"1.0"'
    assert describe(False) == '"false"'
