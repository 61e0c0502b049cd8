"""scripts/test_summary.py counts JUnit results from pytest, gtest and rostest correctly."""
import os
import re
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


# --- --expect: a run that lost a test is a failed run ----------------------------------------------

def run_expecting(tmp_path, results, expected, test_files=()):
    """results: {relative path under the results dir: XML}; expected: the list's lines;
    test_files: rostest files of a package tree under tmp_path/src."""
    out = tmp_path / "results"
    for name, text in results.items():
        (out / name).parent.mkdir(parents=True, exist_ok=True)
        (out / name).write_text(text)
    for name in test_files:
        (tmp_path / "src" / name).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / "src" / name).write_text("<launch/>")
    (tmp_path / "src").mkdir(exist_ok=True)
    listing = tmp_path / "expected.txt"
    listing.write_text("# comment\n" + "\n".join(expected) + "\n")
    proc = subprocess.run([sys.executable, SUMMARY, "--expect", str(listing), "--src", str(tmp_path / "src"),
                           str(out)], stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
    return proc.returncode, proc.stdout


def test_a_complete_run_passes(tmp_path):
    results = {"pkg/rostest-test_sim.xml": ROSTEST_NODE_RAN, "pkg/rosunit-sim.xml": ROSTEST_XML,
               "pkg/gtest-test_a.xml": ROSTEST_XML}
    code, out = run_expecting(tmp_path, results,
                              ["pkg/rostest-test_sim.xml", "pkg/gtest-test_a.xml"], ["pkg/test/sim.test"])
    assert code == 0, out
    assert out.strip().splitlines()[-1] == "4 passed, 0 failed, 0 skipped"


def test_an_expected_result_that_is_missing_fails_the_run(tmp_path):
    code, out = run_expecting(tmp_path, {"pkg/gtest-test_a.xml": ROSTEST_XML},
                              ["pkg/gtest-test_a.xml", "pkg/gtest-test_raycast.xml"])
    assert code == 1
    assert "pkg/gtest-test_raycast.xml" in out and "expected result missing" in out
    assert out.strip().splitlines()[-1] == "2 passed, 1 failed, 0 skipped"


def test_a_skipped_case_fails_the_run(tmp_path):
    code, out = run_expecting(tmp_path, {"pytest.xml": GTEST_XML.replace('<failure message="x"/>', "")},
                              ["pytest.xml"])
    assert code == 1 and "a skipped test is a test that did not run" in out


def test_a_rostest_file_without_a_result_or_a_result_nothing_expects_fails_the_run(tmp_path):
    code, out = run_expecting(tmp_path, {"pkg/gtest-test_a.xml": ROSTEST_XML, "pkg/gtest-test_new.xml": ROSTEST_XML},
                              ["pkg/gtest-test_a.xml"], ["pkg/test/rostest/new_check.test"])
    assert code == 1
    assert "pkg/rostest-test_rostest_new_check.xml" in out and "is not registered (add_rostest)" in out
    assert "pkg/gtest-test_new.xml" in out and "does not list" in out


# --- minimum case counts: a result file that lost cases is a failed run ------------------------------

def cases_xml(n):
    return ('<?xml version="1.0"?>\n<testsuite name="s" tests="%d">%s</testsuite>'
            % (n, "".join('<testcase classname="S" name="t%d"/>' % k for k in range(n))))


def test_a_file_with_fewer_cases_than_its_minimum_fails_the_run_naming_it_the_minimum_and_the_count(tmp_path):
    code, out = run_expecting(tmp_path, {"pytest.xml": cases_xml(940), "pkg/gtest-test_a.xml": cases_xml(5)},
                              ["pytest.xml 945", "pkg/gtest-test_a.xml 5"])
    assert code == 1, out
    assert "FAILED: pytest.xml" in out
    assert "940 test cases, fewer than the 945 that" in out and "expected.txt expects" in out
    assert "FAILED: pkg/gtest-test_a.xml" not in out   # 5 of 5: enough
    assert out.strip().splitlines()[-1] == "945 passed, 1 failed, 0 skipped"


def test_as_many_or_more_cases_than_the_minimum_and_a_line_without_one_pass(tmp_path):
    code, out = run_expecting(tmp_path, {"pytest.xml": cases_xml(950), "pkg/gtest-test_a.xml": cases_xml(5),
                                         "pkg/gtest-test_b.xml": cases_xml(1)},
                              ["pytest.xml 945", "pkg/gtest-test_a.xml 5", "pkg/gtest-test_b.xml"])
    assert code == 0, out
    assert out.strip().splitlines()[-1] == "956 passed, 0 failed, 0 skipped"


def test_a_rostests_cases_are_checked_through_its_nodes_rosunit_file(tmp_path):
    results = {"pkg/rostest-test_sim.xml": ROSTEST_NODE_RAN, "pkg/rosunit-sim.xml": ROSTEST_XML}
    code, out = run_expecting(tmp_path, results, ["pkg/rosunit-sim.xml 3"], ["pkg/test/sim.test"])
    assert code == 1 and "2 test cases, fewer than the 3 that" in out
    code, out = run_expecting(tmp_path, results, ["pkg/rosunit-sim.xml 2"], ["pkg/test/sim.test"])
    assert code == 0, out


def test_the_cases_of_each_kind_are_printed_before_the_totals(tmp_path):
    results = {"pytest.xml": cases_xml(7), "fleet_hosts.xml": cases_xml(1), "lint.xml": cases_xml(3),
               "pkg/gtest-test_a.xml": cases_xml(4), "pkg/gtest-test_b.xml": cases_xml(2),
               "pkg/rostest-test_sim.xml": ROSTEST_NODE_RAN, "pkg/rosunit-sim.xml": ROSTEST_XML}
    code, out = run_expecting(tmp_path, results, ["pytest.xml", "fleet_hosts.xml", "lint.xml", "pkg/gtest-test_a.xml",
                                                  "pkg/gtest-test_b.xml"], ["pkg/test/sim.test"])
    assert code == 0, out
    lines = out.strip().splitlines()
    assert lines[-2] == "test cases by kind: pytest 8, gtest 6, rostest 2, lint 3"
    assert lines[-1] == "19 passed, 0 failed, 0 skipped"


def test_a_bad_line_in_the_expected_list_is_an_error_naming_it(tmp_path):
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "pytest.xml").write_text(cases_xml(1))
    for line in ("pytest.xml many", "pytest.xml 3 4", "pytest.xml -1"):
        listing = tmp_path / "expected.txt"
        listing.write_text("# comment\nlint.xml\n%s\n" % line)
        proc = subprocess.run([sys.executable, SUMMARY, "--expect", str(listing), str(tmp_path / "results")],
                              stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        assert proc.returncode == 2, line
        assert proc.stderr.strip() == "%s:3: expected 'RESULT_FILE [MIN_CASES]' (MIN_CASES a whole number), got %r" % (
            listing, line)


def test_the_projects_list_reads_and_each_rostest_line_names_a_test_node_of_a_test_file():
    sys.path.insert(0, os.path.join(ROOT, "scripts"))
    try:
        from test_summary import read_expected
    finally:
        sys.path.pop(0)
    expected = read_expected(os.path.join(ROOT, "tests", "expected_results.txt"))
    assert expected["pytest.xml"] + expected["pytest_bringup.xml"] >= 1000   # scripts/test writes both
    nodes = set()
    for top in [os.path.join(ROOT, "src"), os.path.join(ROOT, "tests", "rostest")]:
        for root, _, files in os.walk(top):
            for name in files:
                if name.endswith(".test"):
                    with open(os.path.join(root, name)) as f:
                        nodes.update(re.findall(r'test-name="([^"]+)"', f.read()))
    rosunit = [name for name in expected if "/rosunit-" in name]
    assert len(rosunit) >= 60
    for name in rosunit:
        assert name.split("/rosunit-")[1][:-len(".xml")] in nodes, name
