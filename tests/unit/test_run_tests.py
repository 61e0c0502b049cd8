"""scripts/run_tests.py: which catkin targets it runs (one per test, never a package's aggregate)."""
import os
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(ROOT, "scripts"))
from run_tests import single_test_targets  # noqa: E402

MAKE_HELP = """The following are some of the valid targets for this Makefile:
... all (the default if no target is provided)
... run_tests
... run_tests_mbot_sim
... _run_tests_mbot_sim_gtest_test_world
... run_tests_mbot_sim_gtest
... run_tests_mbot_sim_gtest_test_world
... run_tests_mbot_sim_rostest
... run_tests_mbot_sim_rostest_test_sim_basics.test
... _run_tests_mbot_sim_rostest_test_sim_basics.test
... run_tests_mbot_simx_rostest_test_other.test
... test_world
"""


def test_each_test_once_rostests_first_no_aggregates_no_other_package():
    assert single_test_targets("mbot_sim", MAKE_HELP) == [
        ("rostest", "run_tests_mbot_sim_rostest_test_sim_basics.test"),
        ("gtest", "run_tests_mbot_sim_gtest_test_world")]


def test_a_package_without_tests_has_none():
    assert single_test_targets("mbot_msgs", MAKE_HELP) == []
