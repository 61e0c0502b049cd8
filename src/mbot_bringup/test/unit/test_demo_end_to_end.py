"""The demo as a newcomer meets it: a `git clone` of the committed HEAD into a temporary folder,
then the demo's default scenario (DEMO_SCENARIO of scripts/demo, office_route) the way
scripts/demo runs it (scripts/scenario with rviz screenshots under Xvfb), and every section of
the report that README.md and src/mbot_bringup/README.md promise, with content.

What is not rebuilt: scripts/demo first runs scripts/setup, which installs and builds the whole
workspace (C++ simulator and navigation: many minutes). The clone builds only mbot_bringup (Python:
its scenarios, runner, report, launch files; about 4 s) in a devel space that extends this
checkout's built devel space (`catkin config --extend`), so the other packages are this
checkout's build. What the test catches: a file of mbot_bringup or scripts/ that works here but
is not committed, a default scenario that fails, a report section missing or empty. That a
report that cannot be written fails the run (exit status 4) is tests/unit/test_scenario_script.py.
Not a unit test: about two minutes (clone, build, ~60 s of the run, the report).
"""
import json
import os
import re
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def run(cmd, cwd, env, timeout):
    out = subprocess.run(["bash", "-c", cmd], cwd=cwd, env=env, stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                         universal_newlines=True, timeout=timeout)
    assert out.returncode == 0, "%s: exit status %d\n%s" % (cmd, out.returncode, out.stdout[-4000:])
    return out.stdout


def demo_scenario(clone):
    with open(os.path.join(clone, "scripts", "demo")) as f:
        return re.search(r"(?m)^DEMO_SCENARIO=(\w+)", f.read()).group(1)


def section(page, title):
    """The HTML between <h2>title</h2> and the next <h2> (AssertionError when there is none)."""
    match = re.search(r"<h2>%s</h2>(.*?)(?=<h2>|</body>)" % re.escape(title), page, re.S)
    assert match, "the report has no section %r" % title
    return match.group(1)


def assert_png(path, min_bytes=5000):
    with open(path, "rb") as f:
        data = f.read()
    assert data.startswith(PNG_MAGIC) and len(data) >= min_bytes, "%s: not a PNG of %d bytes or more" % (
        path, min_bytes)


def test_a_clone_of_head_runs_the_demo_scenario_and_writes_every_promised_report_section(tmp_path):
    assert os.path.isfile(os.path.join(ROOT, "devel", "setup.bash")), "build this checkout first (scripts/setup)"
    clone = str(tmp_path / "mbot")
    # a plain shell: no ROS environment of the caller
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("ROS") and k not in ("PYTHONPATH", "CMAKE_PREFIX_PATH")}
    run("git clone -q %s %s" % (ROOT, clone), str(tmp_path), env, 120)
    run(". scripts/common.sh && ros_env && catkin config --extend %s/devel >/dev/null && "
        "catkin build --no-status --no-deps mbot_bringup" % ROOT, clone, env, 300)
    name = demo_scenario(clone)
    run_dir = str(tmp_path / "demo")
    output = run("scripts/scenario %s --run-dir %s" % (name, run_dir), clone, env, 900)
    assert "PASSED" in output and "report: %s/index.html" % run_dir in output, output[-4000:]
    with open(os.path.join(run_dir, "criteria.json")) as f:
        criteria = json.load(f)
    assert criteria["scenario"] == name and criteria["passed"] is True
    with open(os.path.join(run_dir, "index.html")) as f:
        page = f.read()

    # the verdict and the criteria table: one PASS row per criterion of criteria.json
    assert '<p class="verdict pass">PASS: all %d criteria met</p>' % len(criteria["criteria"]) in page
    table = section(page, "Pass criteria")
    assert table.count('<tr class="pass">') == len(criteria["criteria"]) >= 8
    assert 'class="fail"' not in table
    for c in criteria["criteria"]:
        assert "<code>%s</code>" % c["name"] in table
    # what happened: the target, the switches and ARRIVED, with times
    events = section(page, "What happened")
    assert events.count("<tr") >= 4 and "ARRIVED" in events and "switch" in events
    # the animation: a GIF of many frames; the plots: PNGs with something in them
    from PIL import Image
    gif = Image.open(os.path.join(run_dir, "report", "animation.gif"))
    assert gif.n_frames >= 100
    assert 'src="report/animation.gif"' in section(page, "Animation")
    for title, png in (("Paths and formation snapshots", "trajectories.png"),
                       ("Formation error over time", "errors.png"), ("Control latency", "latency.png"),
                       ("Speeds", "speeds.png")):
        assert 'src="report/%s"' % png in section(page, title)
        assert_png(os.path.join(run_dir, "report", png))
    # the numbers: every metric row, switches with their settling time, per robot
    assert section(page, "Metrics").count("<tr") >= 10
    assert section(page, "Formation switches").count("<tr") >= 3       # header and the two switches
    assert section(page, "Per robot").count("<tr") >= 4                # header and three robots
    # the rviz screenshots taken headless, each shown
    shots = sorted(os.listdir(os.path.join(run_dir, "screenshots")))
    assert shots, "no screenshot in %s/screenshots" % run_dir
    for shot in shots:
        assert_png(os.path.join(run_dir, "screenshots", shot))
        assert 'src="screenshots/%s"' % shot in section(page, "Screenshots")
    # the run's files
    for name in ("scenario.yaml", "world.yaml", "run.bag", "timeline.json", "metrics/metrics.csv",
                 "metrics/events.csv", "metrics/metrics.json"):
        path = os.path.join(run_dir, name)
        assert os.path.isfile(path) and os.path.getsize(path) > 0, "%s is missing or empty" % path
