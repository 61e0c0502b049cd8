"""Strict reading of YAML config files (the C++ twin is strict_yaml.h).

Every mistake in a config file is an error of one line that names the file, the key and what was
expected, e.g.

    office.world.yaml: robots[1].pose: expected a list of 3 numbers [x, y, yaw], got "1.0"

Nothing is guessed: an unknown key (a typo), a duplicate key, a missing required key, a quoted
number ("0.5" is a string), a boolean where a number belongs: each is a ConfigError.

    r = Reader.from_file(path)                       # or Reader(load_yaml(path), path)
    rate = r.optional("rate", float, 10.0)           # [Hz]; int accepted, bool and str not
    pose = r.number_list("pose", 3, what="a list of 3 numbers [x, y, yaw]")
    for robot in r.children("robots"):              # where = "file: robots[1]"
        name = robot.required("name", str)
    r.finish()                                       # unknown keys here and in every child

`where` of a Reader is the file for the top-level map, or "file: key.path" for a nested one;
a key is appended after ": " to a bare file and after "." to a key path.
"""
import math

import yaml


class ConfigError(ValueError):
    """A config file or parameter that cannot be used. str(error) is one line,
    "<file>: <key path>: <problem>"."""

    def __init__(self, message):
        super(ConfigError, self).__init__(" ".join(str(message).splitlines()))


class _Required(object):
    def __repr__(self):
        return "REQUIRED"


#: Default of Reader.number_list() (and of params.get_param()): the key must be there.
REQUIRED = _Required()

_BAD = object()

#: What each kind is called in messages ("expected a number, got ...").
KIND_NAMES = {float: "a number", int: "an integer", bool: "true or false", str: "a string",
              list: "a list", dict: "a map", object: "a value"}


def describe(value):
    """How a value looks in a message: "1.0" (a scalar), a list of 2, a map, nothing."""
    if value is None:
        return "nothing"
    if isinstance(value, dict):
        return "a map"
    if isinstance(value, (list, tuple)):
        return "a list of %d" % len(value)
    if isinstance(value, bool):
        return '"true"' if value else '"false"'
    return '"%s"' % (value,)


def convert(value, kind):
    """`value` as `kind` (float, int, bool, str, list, dict, or object = anything), or None
    when it is not one. float accepts an int but never a bool, a string or inf/NaN; int never
    accepts a bool."""
    result = _convert(value, kind)
    return None if result is _BAD else result


def _convert(value, kind):
    if kind not in KIND_NAMES:  # a programming error, not a config error
        raise TypeError("kind: expected one of float, int, bool, str, list, dict, object, got %r" % (kind,))
    if kind is object:
        return value
    if kind is float:
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
            return _BAD
        return float(value)
    if kind is int:
        return value if isinstance(value, int) and not isinstance(value, bool) else _BAD
    return value if isinstance(value, kind) else _BAD


def _join(path, key):
    return "%s" % (key,) if not path else "%s.%s" % (path, key)


def _check_duplicates(node, file_name, path, seen_nodes):
    """Raise a ConfigError for the first duplicate key under the composed YAML `node`
    (PyYAML would silently keep the last one)."""
    if id(node) in seen_nodes:  # an alias of a node checked already
        return
    seen_nodes.add(id(node))
    if isinstance(node, yaml.MappingNode):
        keys = set()
        for key_node, value_node in node.value:
            key = key_node.value if isinstance(key_node, yaml.ScalarNode) else None
            if key is not None and key != "<<":
                if key in keys:
                    raise ConfigError("%s: %s: duplicate key (line %d)"
                                      % (file_name, _join(path, key), key_node.start_mark.line + 1))
                keys.add(key)
            _check_duplicates(value_node, file_name, _join(path, key), seen_nodes)
    elif isinstance(node, yaml.SequenceNode):
        for i, item in enumerate(node.value):
            _check_duplicates(item, file_name, "%s[%d]" % (path, i), seen_nodes)


def load_yaml(path):
    """The data of the YAML file `path` (None for an empty file).

    A missing or unreadable file, invalid YAML (with its line and column) or a duplicate key
    is a ConfigError naming the file.
    """
    try:
        with open(path, "rb") as f:
            raw = f.read()
    except (IOError, OSError):
        raise ConfigError("%s: cannot read the file (missing or unreadable)" % path)
    try:
        text = raw.decode("utf-8")
    except UnicodeDecodeError as error:
        raise ConfigError("%s: not valid YAML: not UTF-8 text (byte %d)" % (path, error.start))
    loader = yaml.SafeLoader(text)
    try:
        node = loader.get_single_node()
        if node is None:
            return None
        _check_duplicates(node, path, "", set())
        return loader.construct_document(node)
    except yaml.MarkedYAMLError as error:
        mark = error.problem_mark or error.context_mark
        where = "line %d, column %d: " % (mark.line + 1, mark.column + 1) if mark else ""
        raise ConfigError("%s: not valid YAML: %s%s" % (path, where, error.problem or error.context))
    except yaml.YAMLError as error:
        raise ConfigError("%s: not valid YAML: %s" % (path, error))
    finally:
        loader.dispose()


class Reader(object):
    """A YAML map read key by key; every read checks the type, finish() rejects the keys that
    were never read."""

    def __init__(self, data, where):
        """data: the map (a dict); where: the file, or "file: key.path" for a nested map."""
        self.data = data
        self.where = where
        self._asked = []     # keys read (or declared by check_keys), in order: the allowed keys
        self._children = []  # Readers made by child() and children(), finished with this one
        if not isinstance(data, dict):
            if self._top_level():
                raise ConfigError("%s: (top level): expected a map of keys, got %s" % (where, describe(data)))
            raise ConfigError("%s: expected a map, got %s" % (where, describe(data)))

    @classmethod
    def from_file(cls, path):
        """Reader(load_yaml(path), path)."""
        return cls(load_yaml(path), path)

    def _top_level(self):
        return ": " not in self.where

    def key_path(self, key):
        """How `key` of this map is named in messages: "file: key" or "file: path.key"."""
        return "%s: %s" % (self.where, key) if self._top_level() else "%s.%s" % (self.where, key)

    def fail(self, key, problem):
        """Raise ConfigError("<where>.<key>: <problem>"); key None: the map itself."""
        raise ConfigError("%s: %s" % (self.where if key is None else self.key_path(key), problem))

    def expected(self, key, what, got):
        """Raise ConfigError("<where>.<key>: expected <what>, got <got>")."""
        self.fail(key, "expected %s, got %s" % (what, describe(got)))

    def _ask(self, key):
        if key not in self._asked:
            self._asked.append(key)

    def __contains__(self, key):
        return key in self.data

    def keys(self):
        """The keys of the map, in file order (for maps whose keys are names, e.g. formations)."""
        return list(self.data.keys())

    def _get(self, key, kind, default, what, check):
        self._ask(key)
        if key not in self.data:
            if default is REQUIRED:
                self.fail(key, "missing key (required)")
            return default
        value = self.data[key]
        result = _convert(value, kind)
        if result is _BAD or (check is not None and not check(result)):
            self.expected(key, what or KIND_NAMES[kind], value)
        return result

    def required(self, key, kind, what=None, check=None):
        """The value of `key` as `kind` (float, int, bool, str, list, dict, object).

        what: how the expected value is named in the error ("a number > 0 [m/s]");
        check: a function of the value that must return True (e.g. lambda v: v > 0).
        """
        return self._get(key, kind, REQUIRED, what, check)

    def optional(self, key, kind, default, what=None, check=None):
        """As required(), but `default` when the key is absent (a key with no value is an error)."""
        return self._get(key, kind, default, what, check)

    def number_list(self, key, n, default=REQUIRED, what=None):
        """A list of exactly n numbers as floats, e.g. a pose [x, y, yaw]."""
        what = what or "a list of %d numbers" % n
        self._ask(key)
        if key not in self.data:
            if default is REQUIRED:
                self.fail(key, "missing key (required)")
            return default if default is None else [float(v) for v in default]
        value = self.data[key]
        if not isinstance(value, list) or len(value) != n:
            self.expected(key, what, value)
        numbers = []
        for item in value:
            number = _convert(item, float)
            if number is _BAD:
                self.expected(key, what, item)
            numbers.append(number)
        return numbers

    def child(self, key, required=True):
        """A Reader for the map at `key` (where = "file: key"). required=False: an absent key or
        one with no value is an empty map."""
        self._ask(key)
        if key not in self.data or (self.data[key] is None and not required):
            if required:
                self.fail(key, "missing key (required)")
            reader = Reader({}, self.key_path(key))
        else:
            reader = Reader(self.data[key], self.key_path(key))
        self._children.append(reader)
        return reader

    def children(self, key, required=True):
        """Readers for the list of maps at `key` (where = "file: robots[1]"). required=False: an
        absent key or one with no value is an empty list."""
        self._ask(key)
        if key not in self.data or (self.data[key] is None and not required):
            if required:
                self.fail(key, "missing key (required)")
            return []
        value = self.data[key]
        if not isinstance(value, list):
            self.expected(key, "a list", value)
        readers = [Reader(item, "%s[%d]" % (self.key_path(key), i)) for i, item in enumerate(value)]
        self._children.extend(readers)
        return readers

    def check_keys(self, allowed, required=()):
        """Check the keys now, before reading values (as the C++ checkKeys()): every key must be
        in `allowed`, every key of `required` present. The allowed keys count as read."""
        for key in self.data:
            if key not in allowed:
                self.fail(key, "unknown key (expected one of %s)" % ", ".join(str(k) for k in allowed))
        for key in required:
            if key not in self.data:
                self.fail(key, "missing key (required)")
        for key in allowed:
            self._ask(key)

    def finish(self):
        """ConfigError naming every key of this map (and of its child Readers) that was never
        read: unknown keys are typos, not options."""
        unknown = [key for key in self.data if key not in self._asked]
        if self._asked:
            hint = "(expected one of %s)" % ", ".join(str(k) for k in self._asked)
        else:
            hint = "(this map takes no keys)"
        if len(unknown) == 1:
            self.fail(unknown[0], "unknown key %s" % hint)
        if unknown:
            self.fail(None, "unknown keys %s %s" % (", ".join(str(k) for k in unknown), hint))
        for reader in self._children:
            reader.finish()
