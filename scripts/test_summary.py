#!/usr/bin/python3
"""Summarise JUnit XML results from pytest, gtest and rostest into one report.

Usage: test_summary.py [--expect FILE --src DIR] [--system DIR] DIR [DIR ...]

Prints one line per result file with failures, then the end of each failure's message (so that
a CI log, which keeps the tail, shows why), then the totals as the plain closing line
`N passed, N failed, N skipped`. Exit status 1 when anything failed or no test ran.
rostest writes a `rostest-*.xml` file with one case per test node (did it run and pass) and the
node's own `rosunit-*.xml` with its test cases. The node's cases are counted; the rostest case
counts only when it failed (the node crashed or timed out before writing its results), so that
no test counts twice.

--expect FILE: the result files a complete run has (one name a line, as found under the DIRs,
e.g. `mbot_sim/gtest-test_world.xml`), each optionally followed by the least number of test
cases it must hold (`mbot_sim/gtest-test_world.xml 43`). A test that a partial build loses (a
guard in a CMakeLists, a target that failed to build) writes no result and reads as nothing at
all; with the list it is a failure naming the missing file. A file with fewer cases than its
minimum (a deleted or #if-ed TEST, a pytest file no longer collected: the pytest cases are in
pytest_bringup.xml, mbot_bringup's, and pytest.xml, the others) is a failure naming the file, the
minimum and the count. Every rostest file
under `--src`'s packages (`src/<pkg>/test/**/*.test`) and `--system` is expected too, without a
line (its cases are in the rosunit-*.xml of its test node, which a line can give a minimum). A
skipped test case is a failure, and so is a result file that nothing expects: a new gtest is
added to the list in the same commit. The cases of each kind (pytest, gtest, rostest, lint) are
printed before the totals.
"""
import os
import sys
import xml.etree.ElementTree as ET


def result_files(dirs):
    for top in dirs:
        for root, _, files in os.walk(top):
            for name in sorted(files):
                if name.endswith(".xml"):
                    yield os.path.join(root, name)


def count(path):
    """Return (passed, failed, skipped, failures) for one JUnit file.

    failures is a list of (case name, message text).
    """
    try:
        tree = ET.parse(path)
    except ET.ParseError as err:
        return 0, 1, 0, [(path, "unreadable result file (%s)" % err)]
    passed = failed = skipped = 0
    failures = []
    only_failures = os.path.basename(path).startswith("rostest-")
    for case in tree.iter("testcase"):
        name = "%s.%s" % (case.get("classname", ""), case.get("name", ""))
        bad = case.find("failure")
        if bad is None:
            bad = case.find("error")
        if bad is not None:
            failed += 1
            failures.append((name, (bad.get("message") or "") + "\n" + (bad.text or "")))
        elif only_failures:
            continue
        elif case.find("skipped") is not None:
            skipped += 1
        else:
            passed += 1
    # A suite that crashed before its cases ran reports errors on the suite only.
    for suite in tree.iter("testsuite"):
        if not list(suite.iter("testcase")) and int(suite.get("errors", 0) or 0) > 0:
            failed += 1
            failures.append(("%s (suite error)" % suite.get("name"), ""))
    return passed, failed, skipped, failures


def message_tail(text, first=2, last=6):
    """The first lines of a failure's text (rosunit puts the assertion message there) and its
    last ones (a traceback's innermost frame, or pytest's message)."""
    kept = [line.rstrip() for line in text.strip().splitlines() if line.strip()]
    if len(kept) <= first + last:
        return kept
    return kept[:first] + ["..."] + kept[-last:]


def result_name(path, dirs):
    """A result file's name in the expected list: its path below the DIR it was found in."""
    for top in dirs:
        rel = os.path.relpath(path, top)
        if not rel.startswith(".."):
            return rel.replace(os.sep, "/")
    return os.path.basename(path)


def system_results(system):
    """{expected result name: .test file} of scripts/test's system rostests (`system`/*.test,
    run as package mbot_system_tests with --results-filename system_<name>.xml)."""
    names = sorted(os.listdir(system)) if system and os.path.isdir(system) else []
    return {"mbot_system_tests/rostest-system_%s.xml" % n[:-len(".test")]: os.path.join(system, n)
            for n in names if n.endswith(".test")}


def rostest_results(src):
    """{expected result name: .test file} for every rostest file of every package under `src`:
    catkin's add_rostest names the result rostest-<path below the package, / as _>.xml."""
    out = {}
    for pkg in sorted(os.listdir(src)) if os.path.isdir(src) else []:
        test_dir = os.path.join(src, pkg, "test")
        for root, _, files in os.walk(test_dir):
            for name in sorted(files):
                if name.endswith(".test"):
                    rel = os.path.relpath(os.path.join(root, name), os.path.join(src, pkg))[:-len(".test")]
                    out["%s/rostest-%s.xml" % (pkg, rel.replace(os.sep, "_"))] = os.path.join(root, name)
    return out


def completeness(found, expected, src, system=None):
    """Failures (name, message) of a run that is not complete: an expected result missing (the
    list's, and one per rostest file on disk), or a result that nothing expects."""
    failures = []
    files = dict(rostest_results(src)) if src else {}
    files.update(system_results(system))
    expected = set(expected) | set(files)
    for name in sorted(expected - set(found)):
        why = ("%s wrote no result: it is not registered (add_rostest) or did not run" % files[name]) \
            if name in files else "the test did not build, was not registered or did not run"
        failures.append((name, "expected result missing: " + why))
    for name in sorted(set(found) - expected):
        if not os.path.basename(name).startswith("rosunit-"):   # a rostest's own cases; its rostest- file is listed
            failures.append((name, "a result that tests/expected_results.txt does not list: add it"))
    return failures


def read_expected(path):
    """{result name: least number of test cases, or None} of an expected list: one result a line,
    optionally its minimum after a space; lines starting with # are comments. ValueError naming
    the file and the line for anything else."""
    expected = {}
    with open(path) as f:
        for number, line in enumerate(f, start=1):
            fields = line.split()
            if not fields or fields[0].startswith("#"):
                continue
            if len(fields) > 2 or (len(fields) == 2 and not fields[1].isdigit()):
                raise ValueError("%s:%d: expected 'RESULT_FILE [MIN_CASES]' (MIN_CASES a whole number), got %r"
                                 % (path, number, line.strip()))
            expected[fields[0]] = int(fields[1]) if len(fields) == 2 else None
    return expected


def kind(name):
    """The kind of test a result file holds: gtest, rostest (its rostest-*.xml and the rosunit-*.xml
    of its node), lint, or pytest (pytest*.xml, fleet_hosts.xml)."""
    base = os.path.basename(name)
    if base.startswith("gtest-"):
        return "gtest"
    if base.startswith(("rostest-", "rosunit-")):
        return "rostest"
    return "lint" if base == "lint.xml" else "pytest"


def too_few(cases, minimums, listing):
    """Failures (name, message) of the result files with fewer test cases than their minimum.
    cases: {result name: number of cases}; minimums: {result name: least number or None};
    listing: the expected list's file, for the message."""
    return [(name, "%d test cases, fewer than the %d that %s expects: a test was lost (deleted, #if-ed out, "
                   "renamed or not collected); if that was meant, lower the minimum there"
             % (cases[name], least, listing))
            for name, least in sorted(minimums.items()) if least is not None and name in cases and cases[name] < least]


def main(argv):
    expected, src = None, None
    if argv[:1] == ["--expect"]:
        listing = os.path.relpath(argv[1])
        try:
            expected = read_expected(argv[1])
        except ValueError as error:
            print(error, file=sys.stderr)
            return 2
        argv = argv[2:]
        if argv[:1] == ["--src"]:
            src, argv = argv[1], argv[2:]
    system = None
    if argv[:1] == ["--system"]:
        system, argv = argv[1], argv[2:]
    dirs = argv
    totals = [0, 0, 0]
    details = []
    found = []
    cases = {}                                               # result name: test cases in it
    by_kind = dict((k, 0) for k in ("pytest", "gtest", "rostest", "lint"))
    for path in result_files(dirs):
        found.append(result_name(path, dirs))
        p, f, s, failures = count(path)
        cases[found[-1]] = cases.get(found[-1], 0) + p + f + s
        by_kind[kind(found[-1])] += p + f + s
        if expected is not None and s:
            failures.append(("%s (%d skipped)" % (found[-1], s), "a skipped test is a test that did not run"))
            f += 1
        totals[0] += p
        totals[1] += f
        totals[2] += s
        rel = os.path.relpath(path)
        print("  %-70s %4d passed %3d failed %3d skipped" % (rel[-70:], p, f, s))
        for name, message in failures:
            print("      FAILED: %s" % name)
            details.append((name, message))
    if expected is not None:
        for name, message in completeness(found, expected, src, system) + too_few(cases, expected, listing):
            totals[1] += 1
            print("      FAILED: %s" % name)
            details.append((name, message))
    for name, message in details:
        print()
        print("FAILED %s:" % name)
        for line in message_tail(message):
            print("    " + line[:200])
    print()
    print("test cases by kind: " + ", ".join("%s %d" % item for item in by_kind.items()))
    print("%d passed, %d failed, %d skipped" % tuple(totals))
    if totals[0] + totals[1] == 0:
        print("no test ran", file=sys.stderr)
        return 1
    return 1 if totals[1] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
