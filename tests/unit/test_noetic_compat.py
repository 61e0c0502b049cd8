"""The workspace must also run on Ubuntu 20.04 + ROS Noetic, i.e. Python 3.8.

Static checks, no ROS needed:
  (a) every Python source of the repository parses with the Python 3.8 grammar
      (ast.parse(..., feature_version=(3, 8))), plus the few 3.9+ syntax forms that
      ast's feature_version does not reject (PEP 614 decorators, a[*b], a[x := 1]);
  (b) no 3.9+ standard-library API that only fails at run time (str.removeprefix,
      math.lcm, functools.cache, zoneinfo, graphlib, PEP 585 `list[int]` in annotations
      that are evaluated at run time, ...). Done on the AST, so strings and comments
      never trigger it; uses guarded by try/except ImportError, hasattr() or a
      sys.version_info test are allowed;
  (c) every package.xml is format 2 or 3 and each <*depend> key is non-empty and has
      no whitespace.
Every failure names file:line.

This file itself must stay Python 3.8 compatible (it is one of the checked files).
"""
import ast
import os
import re
import subprocess
import sys
import xml.parsers.expat

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))

PY_DIRS = ("src", "scripts", "tests", "maps")
FEATURE_VERSION = (3, 8)

# --------------------------------------------------------------------------- files


def _is_python_script(path):
    """True if the first line of `path` is a python shebang."""
    try:
        with open(path, "rb") as f:
            first = f.readline(200)
    except (IOError, OSError):
        return False
    return first.startswith(b"#!") and b"python" in first


def _wanted(rel):
    """rel: '/'-separated path relative to ROOT. Which files are Python sources."""
    parts = rel.split("/")
    if parts[0] not in PY_DIRS:
        return False
    if rel.endswith(".py"):
        return True
    base = parts[-1]
    if "." in base:
        return False
    in_script_dir = parts[0] == "scripts" or (
        parts[0] == "src" and len(parts) >= 4 and parts[2] in ("nodes", "scripts"))
    return in_script_dir and _is_python_script(os.path.join(ROOT, *parts))


def _tracked_files():
    """Paths relative to ROOT from `git ls-files`, or None if git is unavailable."""
    try:
        out = subprocess.run(["git", "ls-files", "-z", "--"] + list(PY_DIRS), cwd=ROOT,
                             stdout=subprocess.PIPE, stderr=subprocess.PIPE)
    except (IOError, OSError):
        return None
    if out.returncode != 0:
        return None
    return [p for p in out.stdout.decode("utf-8", "surrogateescape").split("\0") if p]


def _walked_files():
    skip = {".git", "__pycache__", ".pytest_cache", "node_modules"}
    result = []
    for top in PY_DIRS:
        for dirpath, dirnames, filenames in os.walk(os.path.join(ROOT, top)):
            dirnames[:] = sorted(d for d in dirnames if d not in skip)
            for name in sorted(filenames):
                result.append(os.path.relpath(os.path.join(dirpath, name), ROOT)
                              .replace(os.sep, "/"))
    return result


def python_sources():
    files = _tracked_files()
    if files is None:
        files = _walked_files()
    # a tracked file may be deleted in the work tree right now: skip it
    return sorted(rel for rel in files
                  if os.path.isfile(os.path.join(ROOT, *rel.split("/"))) and _wanted(rel))


def package_xmls():
    src = os.path.join(ROOT, "src")
    result = []
    for name in sorted(os.listdir(src)):
        path = os.path.join(src, name, "package.xml")
        if os.path.isfile(path):
            result.append("src/%s/package.xml" % name)
    return result


def _read(rel):
    with open(os.path.join(ROOT, *rel.split("/")), "rb") as f:
        return f.read()


# ------------------------------------------------------------------ (a) syntax

def check_syntax(source, filename="<string>"):
    """Problems ('file:line: message') that keep `source` from running on Python 3.8.

    Returns (problems, tree); tree is None if the source does not parse.
    """
    try:
        tree = ast.parse(source, filename, feature_version=FEATURE_VERSION)
    except SyntaxError as e:
        return ["%s:%s: does not parse as Python 3.8: %s" % (filename, e.lineno, e.msg)], None
    except ValueError as e:  # e.g. NUL bytes
        return ["%s:1: cannot be parsed: %s" % (filename, e)], None
    problems = []
    for node in ast.walk(tree):
        for deco in getattr(node, "decorator_list", ()):
            if not _is_38_decorator(deco):
                problems.append("%s:%d: decorator expression needs Python 3.9 (PEP 614)"
                                % (filename, deco.lineno))
        if isinstance(node, ast.Subscript):
            sl = node.slice
            if sys.version_info < (3, 9) and isinstance(sl, ast.Index):  # 3.8 AST
                sl = sl.value
            elts = sl.elts if isinstance(sl, ast.Tuple) else [sl]
            if any(isinstance(e, ast.Starred) for e in elts):
                problems.append("%s:%d: a[*b] needs Python 3.11" % (filename, node.lineno))
            if isinstance(sl, ast.NamedExpr):
                problems.append("%s:%d: unparenthesized a[x := 1] needs Python 3.10"
                                % (filename, node.lineno))
    return problems, tree


def _is_dotted_name(node):
    while isinstance(node, ast.Attribute):
        node = node.value
    return isinstance(node, ast.Name)


def _is_38_decorator(node):
    """Python 3.8 grammar: decorator: '@' dotted_name [ '(' [arglist] ')' ]."""
    if isinstance(node, ast.Call):
        node = node.func
    return _is_dotted_name(node)


# ------------------------------------------------------------ (b) 3.9+ library APIs

# modules that do not exist in Python 3.8
NEW_MODULES = {"zoneinfo": "3.9", "graphlib": "3.9", "tomllib": "3.11"}

# module-level names added after 3.8 (module.attribute)
NEW_MODULE_ATTRS = {
    "math.lcm": "3.9", "math.nextafter": "3.9", "math.ulp": "3.9",
    "functools.cache": "3.9",
    "ast.unparse": "3.9",
    "random.randbytes": "3.9",
    "asyncio.to_thread": "3.9",
    "os.waitstatus_to_exitcode": "3.9",
    "importlib.resources.files": "3.9",
    "typing.Annotated": "3.9",
    "itertools.pairwise": "3.10",
    "typing.TypeAlias": "3.10", "typing.ParamSpec": "3.10", "typing.TypeGuard": "3.10",
    "typing.Concatenate": "3.10",
    "contextlib.aclosing": "3.10",
    "sys.stdlib_module_names": "3.10",
    "typing.Self": "3.11", "typing.Never": "3.11", "typing.LiteralString": "3.11",
    "typing.assert_never": "3.11", "typing.reveal_type": "3.11",
    "contextlib.chdir": "3.11",
    "enum.StrEnum": "3.11",
    "datetime.UTC": "3.11",
    "itertools.batched": "3.12",
}

# methods of builtin / stdlib types, matched by attribute name on any object
NEW_METHODS = {
    "removeprefix": "3.9 (str/bytes.removeprefix)",
    "removesuffix": "3.9 (str/bytes.removesuffix)",
    "is_relative_to": "3.9 (pathlib.PurePath.is_relative_to)",
    "with_stem": "3.9 (pathlib.PurePath.with_stem)",
    "bit_count": "3.10 (int.bit_count)",
}

# builtins that became generic in 3.9 (PEP 585): list[int] fails at run time on 3.8
PEP585_BUILTINS = ("list", "dict", "tuple", "set", "frozenset", "type")

IMPORT_ERRORS = {"ImportError", "ModuleNotFoundError", "AttributeError", "NameError",
                 "Exception", "BaseException"}


def _handler_names(handler):
    t = handler.type
    if t is None:
        return {"BaseException"}
    elts = t.elts if isinstance(t, ast.Tuple) else [t]
    names = set()
    for e in elts:
        if isinstance(e, ast.Name):
            names.add(e.id)
        elif isinstance(e, ast.Attribute):
            names.add(e.attr)
    return names


def _is_version_guard(test):
    """if sys.version_info >= (3, 9): / if hasattr(str, 'removeprefix'): / PY39 flags."""
    for n in ast.walk(test):
        if isinstance(n, ast.Attribute) and n.attr in ("version_info", "hexversion"):
            return True
        if isinstance(n, ast.Name) and n.id in ("version_info", "hexversion"):
            return True
        if isinstance(n, ast.Call) and isinstance(n.func, ast.Name) and n.func.id == "hasattr":
            return True
    return False


def _guarded_nodes(tree):
    """ids of nodes whose 3.9+ use is protected by a fallback."""
    guarded = set()

    def mark(stmts):
        for s in stmts:
            for n in ast.walk(s):
                guarded.add(id(n))

    for node in ast.walk(tree):
        if isinstance(node, ast.Try):
            if any(_handler_names(h) & IMPORT_ERRORS for h in node.handlers):
                mark(node.body)
        elif isinstance(node, (ast.If, ast.IfExp)) and _is_version_guard(node.test):
            body = node.body if isinstance(node.body, list) else [node.body]
            orelse = node.orelse if isinstance(node.orelse, list) else [node.orelse]
            mark(body)
            mark(orelse)
    return guarded


def _has_future_annotations(tree):
    for node in tree.body:
        if (isinstance(node, ast.ImportFrom) and node.module == "__future__"
                and any(a.name == "annotations" for a in node.names)):
            return True
    return False


def _runtime_annotations(tree):
    """Annotation expressions Python evaluates at run time (def time / class or module body).

    Local variable annotations inside a function body are never evaluated, and with
    `from __future__ import annotations` none are.
    """
    if _has_future_annotations(tree):
        return []
    result = []

    def visit(node, in_function):
        for child in ast.iter_child_nodes(node):
            if isinstance(child, (ast.FunctionDef, ast.AsyncFunctionDef)):
                args = child.args
                all_args = list(getattr(args, "posonlyargs", [])) + list(args.args) + \
                    list(args.kwonlyargs) + [a for a in (args.vararg, args.kwarg) if a]
                result.extend(a.annotation for a in all_args if a.annotation is not None)
                if child.returns is not None:
                    result.append(child.returns)
                visit(child, True)
            elif isinstance(child, ast.Lambda):
                visit(child, True)
            elif isinstance(child, ast.ClassDef):
                visit(child, False)
            else:
                if isinstance(child, ast.AnnAssign) and not in_function:
                    result.append(child.annotation)
                visit(child, in_function)

    visit(tree, False)
    return result


def _rebound_names(tree):
    """Names assigned somewhere in the file (e.g. `list = ...` shadows the builtin)."""
    names = set()
    for node in ast.walk(tree):
        if isinstance(node, ast.Name) and isinstance(node.ctx, (ast.Store, ast.Del)):
            names.add(node.id)
        elif isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef)):
            names.add(node.name)
        elif isinstance(node, ast.arg):
            names.add(node.arg)
        elif isinstance(node, (ast.Import, ast.ImportFrom)):
            for a in node.names:
                names.add((a.asname or a.name).split(".")[0])
    return names


def _import_aliases(tree):
    """local name -> dotted module/object it refers to."""
    aliases = {}
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                if a.asname:
                    aliases[a.asname] = a.name
                else:
                    top = a.name.split(".")[0]
                    aliases[top] = top
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            for a in node.names:
                aliases[a.asname or a.name] = "%s.%s" % (node.module, a.name)
    return aliases


def _dotted(node, aliases):
    parts = []
    while isinstance(node, ast.Attribute):
        parts.append(node.attr)
        node = node.value
    if not isinstance(node, ast.Name) or node.id not in aliases:
        return None
    parts.append(aliases[node.id])
    return ".".join(reversed(parts))


def check_new_apis(tree, filename="<string>"):
    """Problems ('file:line: message') from Python 3.9+ library APIs used in `tree`."""
    problems = []
    guarded = _guarded_nodes(tree)
    aliases = _import_aliases(tree)

    def add(node, msg):
        if id(node) not in guarded:
            problems.append("%s:%d: %s" % (filename, node.lineno, msg))

    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for a in node.names:
                top = a.name.split(".")[0]
                if top in NEW_MODULES:
                    add(node, "module %s needs Python %s" % (top, NEW_MODULES[top]))
        elif isinstance(node, ast.ImportFrom) and node.module and not node.level:
            top = node.module.split(".")[0]
            if top in NEW_MODULES:
                add(node, "module %s needs Python %s" % (top, NEW_MODULES[top]))
            for a in node.names:
                full = "%s.%s" % (node.module, a.name)
                if full in NEW_MODULE_ATTRS:
                    add(node, "%s needs Python %s" % (full, NEW_MODULE_ATTRS[full]))
        elif isinstance(node, ast.Attribute) and isinstance(node.ctx, ast.Load):
            full = _dotted(node, aliases)
            if full in NEW_MODULE_ATTRS:
                add(node, "%s needs Python %s" % (full, NEW_MODULE_ATTRS[full]))
            elif node.attr in NEW_METHODS:
                add(node, ".%s() needs Python %s" % (node.attr, NEW_METHODS[node.attr]))
        elif isinstance(node, ast.Call) and isinstance(node.func, ast.Name) \
                and node.func.id == "zip" and any(k.arg == "strict" for k in node.keywords):
            add(node, "zip(strict=...) needs Python 3.10")

    # PEP 585 / PEP 604 in annotations evaluated at run time
    shadowed = _rebound_names(tree)
    for ann in _runtime_annotations(tree):
        for n in ast.walk(ann):
            if isinstance(n, ast.Subscript) and isinstance(n.value, ast.Name) \
                    and n.value.id in PEP585_BUILTINS and n.value.id not in shadowed:
                add(n, "annotation %s[...] is evaluated at run time and needs Python 3.9 "
                       "(use typing.%s or `from __future__ import annotations`)"
                    % (n.value.id, n.value.id.capitalize()))
            elif isinstance(n, ast.BinOp) and isinstance(n.op, ast.BitOr):
                add(n, "annotation X | Y is evaluated at run time and needs Python 3.10 "
                       "(use typing.Union/Optional or `from __future__ import annotations`)")
    return problems


def check_python_source(source, filename="<string>"):
    problems, tree = check_syntax(source, filename)
    if tree is not None:
        problems.extend(check_new_apis(tree, filename))
    return problems


# ------------------------------------------------------------- (c) package.xml

DEPEND_TAGS = {"depend", "build_depend", "build_export_depend", "buildtool_depend",
               "buildtool_export_depend", "exec_depend", "test_depend", "doc_depend"}
FORMAT1_TAGS = {"run_depend"}


def check_package_xml(data, filename="<string>"):
    """Problems ('file:line: message') in a package.xml given as bytes or str."""
    if isinstance(data, str):
        data = data.encode("utf-8")
    problems = []
    stack = []  # [tag, line, text parts]
    root = {}
    parser = xml.parsers.expat.ParserCreate()

    def start(tag, attrs):
        if not stack and not root:
            root.update(tag=tag, attrs=attrs, line=parser.CurrentLineNumber)
        stack.append([tag, parser.CurrentLineNumber, []])

    def chars(text):
        if stack:
            stack[-1][2].append(text)

    def end(tag):
        tag_, line, parts = stack.pop()
        if len(stack) != 1 or stack[0][0] != "package":
            return  # only direct children of <package> are dependencies
        if tag_ in FORMAT1_TAGS:
            problems.append("%s:%d: <%s> is package format 1 only; use <exec_depend>"
                            % (filename, line, tag_))
        elif tag_ in DEPEND_TAGS:
            key = "".join(parts)
            if not key.strip():
                problems.append("%s:%d: empty <%s>" % (filename, line, tag_))
            elif any(c.isspace() for c in key):
                problems.append("%s:%d: <%s> key %r contains whitespace"
                                % (filename, line, tag_, key))

    parser.StartElementHandler = start
    parser.EndElementHandler = end
    parser.CharacterDataHandler = chars
    try:
        parser.Parse(data, True)
    except xml.parsers.expat.ExpatError as e:
        return ["%s:%d: not well-formed XML: %s" % (filename, e.lineno, e)]
    if root.get("tag") != "package":
        problems.append("%s:%d: root element is <%s>, not <package>"
                        % (filename, root.get("line", 1), root.get("tag")))
    elif root["attrs"].get("format") not in ("2", "3"):
        problems.append("%s:%d: package format %r; Noetic needs format=\"2\" or \"3\""
                        % (filename, root["line"], root["attrs"].get("format", "1 (default)")))
    return problems


# ======================================================================= tests

def _fail_if(problems, what):
    if problems:
        pytest.fail("%d %s:\n%s" % (len(problems), what, "\n".join(problems)), pytrace=False)


def test_finds_the_python_sources():
    files = python_sources()
    assert "tests/unit/test_test_summary.py" in files, files
    assert any(f.startswith("src/") and f.endswith(".py") for f in files), files
    # extension-less ROS nodes with a python shebang are included, shell scripts are not
    assert any(f.startswith("src/") and "/nodes/" in f and "." not in f.split("/")[-1]
               for f in files), files
    assert not any(f.endswith(".sh") for f in files), files


def test_this_file_is_python38_compatible():
    # checked here too, since python_sources() only lists files git already tracks
    with open(os.path.abspath(__file__), "rb") as f:
        assert check_python_source(f.read(), "tests/unit/test_noetic_compat.py") == []


def test_python_sources_parse_as_python38():
    problems = []
    for rel in python_sources():
        problems.extend(check_syntax(_read(rel), rel)[0])
    _fail_if(problems, "Python 3.8 syntax problem(s)")


def test_python_sources_use_no_39_plus_library_api():
    problems = []
    for rel in python_sources():
        try:
            tree = ast.parse(_read(rel), rel, feature_version=FEATURE_VERSION)
        except (SyntaxError, ValueError):
            continue  # reported by test_python_sources_parse_as_python38
        problems.extend(check_new_apis(tree, rel))
    _fail_if(problems, "Python 3.9+ API use(s)")


def test_package_xmls_are_format2_with_clean_keys():
    files = package_xmls()
    assert files, "no src/*/package.xml found"
    problems = []
    for rel in files:
        problems.extend(check_package_xml(_read(rel), rel))
    _fail_if(problems, "package.xml problem(s)")


# ------------------------------------------- the checkers do fail when they should

@pytest.mark.parametrize("source, expected", [
    ('x = "a".removeprefix("b")\n', "removeprefix"),
    ('y = b"ab".removesuffix(b"b")\n', "removesuffix"),
    ("match x:\n    case 1:\n        pass\n", "does not parse as Python 3.8"),
    ("with (open('a') as f, open('b') as g):\n    pass\n", "does not parse as Python 3.8"),
    ("import math\nprint(math.lcm(4, 6))\n", "math.lcm"),
    ("import math as m\nm.lcm(4, 6)\n", "math.lcm"),
    ("from math import lcm\n", "math.lcm"),
    ("import functools\n@functools.cache\ndef f():\n    pass\n", "functools.cache"),
    ("from functools import cache\n", "functools.cache"),
    ("import zoneinfo\n", "zoneinfo"),
    ("from zoneinfo import ZoneInfo\n", "zoneinfo"),
    ("import graphlib\n", "graphlib"),
    ("from graphlib import TopologicalSorter\n", "graphlib"),
    ("def f(a: list[int]) -> None:\n    pass\n", "list[...]"),
    ("def f() -> dict[str, int]:\n    pass\n", "dict[...]"),
    ("from typing import Optional\ndef f(a: Optional[tuple[int, int]] = None):\n    pass\n",
     "tuple[...]"),
    ("def f(*a: set[int]):\n    pass\n", "set[...]"),
    ("class C:\n    x: list[int] = []\n", "list[...]"),
    ("def f(a: int | None):\n    pass\n", "X | Y"),
    # a 3.8 interpreter rejects this already in the parser, newer ones need the extra check
    ("@buttons[0].clicked.connect\ndef f():\n    pass\n", "PEP 614|does not parse"),
    ("zip(a, b, strict=True)\n", "zip(strict"),
])
def test_checker_flags_python39_plus(source, expected):
    problems = check_python_source(source, "neg.py")
    assert problems, "not flagged: %r" % source
    assert any(e in p for p in problems for e in expected.split("|")), problems
    assert all(p.startswith("neg.py:") for p in problems), problems


def test_checker_reports_the_line():
    problems = check_python_source('import os\n\nx = "a".removeprefix("b")\n', "neg.py")
    assert problems == ["neg.py:3: .removeprefix() needs Python 3.9 (str/bytes.removeprefix)"]
    problems = check_python_source("x = 1\nmatch x:\n    case 1:\n        pass\n", "neg.py")
    # CPython reports this feature_version error at a line inside the match block
    assert len(problems) == 1 and re.match(r"neg\.py:[234]: .*Pattern matching", problems[0]), \
        problems


@pytest.mark.parametrize("source", [
    '# x = "a".removeprefix("b")\n',
    's = "call .removeprefix( or math.lcm( or functools.cache( or list[int]"\n',
    '"""import zoneinfo\ndef f(a: list[int]) -> dict[str, int]: pass\n"""\n',
    "import functools\n@functools.lru_cache(maxsize=None)\ndef f():\n    pass\n",
    "from __future__ import annotations\ndef f(a: list[int]) -> dict[str, int]:\n    pass\n",
    "def f():\n    x: list[int] = []\n    return x\n",
    "def f(a: 'list[int]') -> 'int | None':\n    pass\n",
    "from typing import Dict, List\ndef f(a: List[int]) -> Dict[str, int]:\n    pass\n",
    "try:\n    import zoneinfo\nexcept ImportError:\n    zoneinfo = None\n",
    "try:\n    from functools import cache\nexcept ImportError:\n    cache = None\n",
    "import sys\nif sys.version_info >= (3, 9):\n    y = 'ab'.removeprefix('a')\n"
    "else:\n    y = 'ab'[1:]\n",
    "s = 'ab'\nt = s.removeprefix('a') if hasattr(s, 'removeprefix') else s[1:]\n",
    "if (n := len('abc')) > 2:\n    pass\n",
    "def f(a, /, b):\n    pass\n",
    "import math\nmath.gcd(4, 6)\nmath.prod([1, 2])\n",
    "list = [1, 2]\ndef f(a: list[0]):\n    pass\n",
    "@app.route('/x')\n@property\ndef f():\n    pass\n",
    "x = a[1:2, ::3]\ny = d['k']\n",
])
def test_checker_accepts_python38(source):
    assert check_python_source(source, "ok.py") == []


def test_checker_on_a_file_outside_the_repository(tmp_path):
    bad = tmp_path / "bad.py"
    bad.write_text('x = "a".removeprefix("b")\n')
    assert check_python_source(bad.read_bytes(), str(bad)) == [
        "%s:1: .removeprefix() needs Python 3.9 (str/bytes.removeprefix)" % bad]


PKG = """<?xml version="1.0"?>
<package format="{fmt}">
  <name>demo</name>
  <version>0.0.0</version>
  <description>d</description>
  <maintainer email="a@b.c">a</maintainer>
  <license>BSD</license>
  <buildtool_depend>catkin</buildtool_depend>
  {extra}
</package>
"""


@pytest.mark.parametrize("fmt, extra, expected", [
    ("1", "<run_depend>rospy</run_depend>", ":2: package format '1'"),
    ("2", "<run_depend>rospy</run_depend>", ":9: <run_depend> is package format 1 only"),
    ("2", "<exec_depend></exec_depend>", ":9: empty <exec_depend>"),
    ("2", "<depend/>", ":9: empty <depend>"),
    ("3", "<test_depend>python3 pytest</test_depend>", "contains whitespace"),
    ("2", "<build_depend> roscpp</build_depend>", "contains whitespace"),
    ("2", "<exec_depend>rospy", "not well-formed"),
])
def test_package_xml_checker_flags(fmt, extra, expected):
    problems = check_package_xml(PKG.format(fmt=fmt, extra=extra), "p.xml")
    assert any(expected in p for p in problems), problems


def test_package_xml_checker_default_format_is_1():
    problems = check_package_xml(PKG.replace(' format="{fmt}"', "").format(extra=""), "p.xml")
    assert problems == ["p.xml:2: package format '1 (default)'; Noetic needs "
                        "format=\"2\" or \"3\""]


def test_package_xml_checker_accepts_good():
    extra = ('<depend>roscpp</depend>\n  <exec_depend condition="$ROS_PYTHON_VERSION == 3">'
             'python3-yaml</exec_depend>\n  <export><build_type>catkin</build_type></export>')
    assert check_package_xml(PKG.format(fmt="2", extra=extra), "p.xml") == []
    assert check_package_xml(PKG.format(fmt="3", extra=extra), "p.xml") == []
