"""The scripts answer --help at once: nothing is installed, built or run (a user asking how to call
scripts/bench or scripts/test must not start a half-hour build), and scripts/test refuses
arguments it does not take."""
import os
import subprocess

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def run(script, *args):
    return subprocess.run([os.path.join(ROOT, "scripts", script)] + list(args), stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)


@pytest.mark.parametrize("script, words", [
    ("test", "run every test"),
    ("bench", "usage: scripts/bench"),
    ("demo", "scripts/demo"),
    ("scenario", "scripts/scenario"),
    ("fleet-hosts", "scripts/fleet-hosts run"),
])
def test_help_prints_usage_without_building(script, words):
    result = run(script, "--help")
    assert result.returncode == 0, result.stdout
    assert words in result.stdout
    assert "[mbot]" not in result.stdout, "the script started its setup: " + result.stdout


def test_scripts_test_refuses_an_unknown_argument():
    result = run("test", "--fast")
    assert result.returncode != 0
    assert "unknown argument '--fast'" in result.stdout
