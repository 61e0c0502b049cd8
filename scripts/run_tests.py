#!/usr/bin/python3
"""Run every package's gtests and rostests, JOBS at a time, from one queue for the whole workspace.

    scripts/run_tests.py [--jobs N] [--logs DIR] PACKAGE...

What `catkin build --catkin-make-args run_tests` runs, but not package by package: there each
package's last test runs alone while the other core waits, and packages with one test run alone
too. Here the catkin targets themselves (`make -C build/<pkg> run_tests_<pkg>_rostest_<file>`,
`..._gtest_<name>`) are taken from one queue, rostests first, so the results land where catkin
puts them (build/<pkg>/test_results/<pkg>/) under the same names. The packages' test programs must
be built first (`catkin build --catkin-make-args tests`) and the workspace's devel/setup.bash
sourced. Each test's output goes to DIR/<target>.log; the exit status is 1 when a target could
not be run (make failed), and the results are judged by scripts/test_summary.py.
"""
import argparse
import os
import re
import subprocess
import sys
import threading
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def targets(package):
    """The package's single-test run_tests targets: (kind, target), from its Makefile's help."""
    build = os.path.join(ROOT, "build", package)
    if not os.path.isfile(os.path.join(build, "Makefile")):
        return []
    listing = subprocess.run(["make", "-C", build, "help"], stdout=subprocess.PIPE, universal_newlines=True,
                             check=True).stdout
    return single_test_targets(package, listing)


def single_test_targets(package, make_help):
    """(kind, target) of each line `... run_tests_<pkg>_<kind>_<test>` of `make help`, rostests
    first; `run_tests_<pkg>_<kind>` (all of a kind) and the `_run_tests_...` helpers are left out."""
    found = []
    for kind in ("rostest", "gtest"):
        pattern = re.compile(r"^\.\.\. (run_tests_%s_%s_\S+)$" % (re.escape(package), kind))
        found += [(kind, m.group(1)) for m in map(pattern.match, make_help.splitlines()) if m]
    return found


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--jobs", type=int, default=2)
    parser.add_argument("--logs", default=os.path.join(ROOT, "out", "test-results", "run_tests"))
    parser.add_argument("packages", nargs="+")
    args = parser.parse_args()
    if args.jobs < 1:
        parser.error("--jobs must be at least 1, got %d" % args.jobs)
    os.makedirs(args.logs, exist_ok=True)

    queue = []
    for package in args.packages:
        queue += [(kind, package, target) for kind, target in targets(package)]
    queue.sort(key=lambda item: item[0] != "rostest")   # the long ones first; stable within a kind
    print("%d tests (%d rostests) from %d packages, %d at a time"
          % (len(queue), sum(k == "rostest" for k, _, _ in queue), len(args.packages), args.jobs))
    sys.stdout.flush()

    lock = threading.Lock()
    failed = []

    def worker():
        while True:
            with lock:
                if not queue:
                    return
                _, package, target = queue.pop(0)
            log = os.path.join(args.logs, target + ".log")
            start = time.time()
            with open(log, "w") as out:
                rc = subprocess.call(["make", "-C", os.path.join(ROOT, "build", package), target],
                                     stdout=out, stderr=subprocess.STDOUT)
            with lock:
                print("%6.1f s  %s%s" % (time.time() - start, target, "" if rc == 0 else "  (make failed: %s)" % log))
                sys.stdout.flush()
                if rc != 0:
                    failed.append(target)

    threads = [threading.Thread(target=worker) for _ in range(args.jobs)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    if failed:
        print("could not run: %s" % ", ".join(failed))
    return 1 if failed else 0


if __name__ == "__main__":
    sys.exit(main())
