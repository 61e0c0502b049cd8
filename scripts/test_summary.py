#!/usr/bin/python3
"""Summarise JUnit XML results from pytest, gtest and rostest into one report.

Usage: test_summary.py DIR [DIR ...]

Prints one line per result file with failures, then the end of each failure's message (so that
a CI log, which keeps the tail, shows why), then the totals as the plain closing line
`N passed, N failed, N skipped`. Exit status 1 when anything failed or no test ran.
rostest writes a `rostest-*.xml` file with one case per test node (did it run and pass) and the
node's own `rosunit-*.xml` with its test cases. The node's cases are counted; the rostest case
counts only when it failed (the node crashed or timed out before writing its results), so that
no test counts twice.
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


def main(dirs):
    totals = [0, 0, 0]
    details = []
    for path in result_files(dirs):
        p, f, s, failures = count(path)
        totals[0] += p
        totals[1] += f
        totals[2] += s
        rel = os.path.relpath(path)
        print("  %-70s %4d passed %3d failed %3d skipped" % (rel[-70:], p, f, s))
        for name, message in failures:
            print("      FAILED: %s" % name)
            details.append((name, message))
    for name, message in details:
        print()
        print("FAILED %s:" % name)
        for line in message_tail(message):
            print("    " + line[:200])
    print()
    print("%d passed, %d failed, %d skipped" % tuple(totals))
    if totals[0] + totals[1] == 0:
        print("no test ran", file=sys.stderr)
        return 1
    return 1 if totals[1] else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
