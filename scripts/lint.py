#!/usr/bin/python3
"""The habits the tools enforce, as one test tier of scripts/test:

  flake8        every Python file (*.py, and scripts and nodes that start with a python shebang),
                settings in .flake8
  catkin_lint   every package under src/
  clang-format  every C++ file under src/ formatted as .clang-format says (a dry run: nothing is
                rewritten; `scripts/lint.py --fix` formats the files)

Usage: scripts/lint.py [--junit FILE] [--fix]
One JUnit test case per tool (its findings are the failure text), so a finding is a failed test
in the summary. Exit status 1 when a tool found something or is missing.
"""
import argparse
import os
import shutil
import subprocess
import sys
from xml.sax.saxutils import escape, quoteattr

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), ".."))
SKIP_DIRS = {".git", ".venv", "build", "devel", "install", "logs", "out", "docker", "__pycache__"}
CPP_EXTENSIONS = (".cpp", ".h", ".hpp", ".cc")


def walk(top):
    for root, dirs, files in os.walk(top):
        dirs[:] = sorted(d for d in dirs if d not in SKIP_DIRS)
        for name in sorted(files):
            yield os.path.join(root, name)


def is_python(path):
    if path.endswith(".py"):
        return True
    if os.path.splitext(path)[1] or not os.access(path, os.X_OK):
        return False
    try:
        with open(path, "rb") as f:
            first = f.readline(200)
    except OSError:
        return False
    return first.startswith(b"#!") and b"python" in first


def python_files():
    return [p for p in walk(ROOT) if not os.path.islink(p) and is_python(p)]


def cpp_files():
    return [p for p in walk(os.path.join(ROOT, "src")) if p.endswith(CPP_EXTENSIONS)]


def packages():
    src = os.path.join(ROOT, "src")
    return sorted(os.path.join(src, d) for d in os.listdir(src) if os.path.isfile(os.path.join(src, d, "package.xml")))


def run(command):
    """(exit status, output) of a command run from the workspace root."""
    result = subprocess.run(command, cwd=ROOT, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True)
    return result.returncode, result.stdout


def check_flake8():
    files = [os.path.relpath(p, ROOT) for p in python_files()]
    return run(["flake8", "--config", os.path.join(ROOT, ".flake8")] + files)


def check_catkin_lint():
    # errors and warnings (-W1, catkin_lint's default level); --strict: a warning fails too
    return run(["catkin_lint", "-W1", "--strict", "--quiet"] + packages())


def check_clang_format(fix):
    files = cpp_files()
    if fix:
        return run(["clang-format", "-i", "--style=file"] + files)
    return run(["clang-format", "--dry-run", "-Werror", "--style=file"] + files)


TOOLS = [("flake8", "flake8", check_flake8), ("catkin_lint", "catkin_lint", check_catkin_lint),
         ("clang-format", "clang-format", None)]


def junit(results, path):
    failures = sum(1 for _, status, _ in results if status != 0)
    cases = []
    for name, status, output in results:
        body = "" if status == 0 else "<failure message=%s>%s</failure>" % (
            quoteattr("%s found problems" % name), escape(output))
        cases.append('  <testcase classname="lint" name=%s>%s</testcase>' % (quoteattr(name), body))
    with open(path, "w") as f:
        f.write('<?xml version="1.0" encoding="utf-8"?>\n<testsuite name="lint" tests="%d" failures="%d">\n%s\n'
                "</testsuite>\n" % (len(results), failures, "\n".join(cases)))


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--junit", help="write the results as JUnit XML here")
    parser.add_argument("--fix", action="store_true", help="format the C++ files with clang-format")
    args = parser.parse_args(argv)
    results = []
    for name, program, check in TOOLS:
        if shutil.which(program) is None:
            results.append((name, 1, "%s is not installed (scripts/setup installs it)" % program))
            continue
        status, output = check_clang_format(args.fix) if name == "clang-format" else check()
        results.append((name, status, output.strip()))
    for name, status, output in results:
        print("%s %s" % ("PASS" if status == 0 else "FAIL", name))
        if status != 0:
            print("\n".join("    " + line for line in output.splitlines()[:200]))
    if args.junit:
        junit(results, args.junit)
    return 0 if all(status == 0 for _, status, _ in results) else 1


if __name__ == "__main__":
    sys.exit(main())
