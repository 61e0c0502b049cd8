"""scripts/test_summary.py counts JUnit results from pytest, gtest and rostest correctly."""
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SUMMARY = os.path.join(ROOT, "scripts", "test_summary.py")

GTEST_XML = """<?xml version="1.0"?>
<testsuites tests="3" failures="1">
  <testsuite name="Raycast" tests="3">
    <testcase name="a" classname="Raycast"/>
    <testcase name="b" classname="Raycast"><failure message="x"/></testcase>
    <testcase name="c" classname="Raycast"><skipped/></testcase>
  </testsuite>
</testsuites>"""

ROSTEST_XML = """<?xml version="1.0"?>
<testsuite name="sim" tests="2" errors="0" failures="0">
  <testcase name="test_odom" classname="sim.Sim"/>
  <testcase name="test_scan" classname="sim.Sim"/>
</testsuite>"""

CRASHED_XML = """<?xml version="1.0"?>
<testsuite name="crashed" tests="1" errors="1" failures="0"></testsuite>"""


def run(tmp_path, files):
    for name, text in files.items():
        (tmp_path / name).write_text(text)
    proc = subprocess.run([sys.executable, SUMMARY, str(tmp_path)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    return proc.returncode, proc.stdout.strip().splitlines()[-1]


def test_counts_pass_fail_skip(tmp_path):
    code, last = run(tmp_path, {"gtest-raycast.xml": GTEST_XML})
    assert last == "1 passed, 1 failed, 1 skipped"
    assert code == 1


ROSTEST_NODE_RAN = """<?xml version="1.0"?>
<testsuite name="s" tests="1"><testcase classname="rostest.runner.RosTest" name="testsim"/></testsuite>"""

ROSTEST_NODE_DIED = """<?xml version="1.0"?>
<testsuite name="s" tests="1"><testcase classname="rostest.runner.RosTest" name="testsim">
<failure message="test [sim] did not generate test results"/></testcase></testsuite>"""


def test_rostest_counts_the_node_cases_not_the_wrapper(tmp_path):
    code, last = run(tmp_path, {"rostest-sim.xml": ROSTEST_NODE_RAN, "rosunit-sim.xml": ROSTEST_XML})
    assert last == "2 passed, 0 failed, 0 skipped"
    assert code == 0


def test_rostest_wrapper_failure_counts_when_the_node_died(tmp_path):
    code, last = run(tmp_path, {"rostest-sim.xml": ROSTEST_NODE_DIED})
    assert last == "0 passed, 1 failed, 0 skipped"
    assert code == 1


def test_suite_error_without_cases_is_a_failure(tmp_path):
    code, last = run(tmp_path, {"rostest-crashed.xml": CRASHED_XML})
    assert last == "0 passed, 1 failed, 0 skipped"
    assert code == 1


def test_no_results_is_an_error(tmp_path):
    proc = subprocess.run([sys.executable, SUMMARY, str(tmp_path)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    assert proc.returncode == 1
    assert "no test ran" in proc.stderr


FAILED_WITH_TRACE = """<?xml version="1.0"?>
<testsuite name="s" tests="1"><testcase classname="corridor.Checks" name="test_check">
<failure message="AssertionError">Traceback (most recent call last):
  File "corridor.py", line 40, in test_check
AssertionError: follower_2 slot RMS 0.93 m over the 0.5 m bound</failure></testcase></testsuite>"""


def test_failure_message_is_printed_before_the_totals(tmp_path):
    (tmp_path / "rosunit-corridor.xml").write_text(FAILED_WITH_TRACE)
    proc = subprocess.run([sys.executable, SUMMARY, str(tmp_path)],
                          stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    lines = proc.stdout.strip().splitlines()
    assert lines[-1] == "0 passed, 1 failed, 0 skipped"
    reason = [i for i, line in enumerate(lines) if "slot RMS 0.93 m over the 0.5 m bound" in line]
    assert reason and reason[0] > [i for i, line in enumerate(lines) if "FAILED corridor" in line][0]
