"""scripts/demo end to end, as a user runs it from a plain shell: `scripts/demo triangle_trio
--no-rviz` installs what is missing, builds, runs the scenario on its own master and leaves a
complete run dir (here in a temporary folder: out/demo may hold the user's own demo). Not a unit
test: it takes a minute or two (the build is already done when scripts/test runs it, and the run
is about 50 s of sim time in lockstep).
"""
import json
import os
import subprocess

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))


def test_demo_triangle_trio_passes_and_leaves_a_complete_run_dir(tmp_path):
    run_dir = str(tmp_path / "demo")
    # a plain shell: no ROS environment of the caller, whatever python3 comes first on PATH
    env = {k: v for k, v in os.environ.items()
           if not k.startswith("ROS") and k not in ("PYTHONPATH", "CMAKE_PREFIX_PATH")}
    result = subprocess.run([os.path.join(ROOT, "scripts", "demo"), "triangle_trio", "--no-rviz", "--run-dir", run_dir],
                            env=env,
                            stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=900)
    output = result.stdout[-4000:]
    assert result.returncode == 0, output
    assert "PASSED" in output and "run dir: %s" % run_dir in output

    for name in ("scenario.yaml", "world.yaml", "run.bag", "criteria.json", "timeline.json",
                 "metrics/metrics.csv", "metrics/events.csv", "metrics/controller.csv", "metrics/metrics.json"):
        path = os.path.join(run_dir, name)
        assert os.path.isfile(path) and os.path.getsize(path) > 0, "%s is missing or empty\n%s" % (path, output)
    with open(os.path.join(run_dir, "criteria.json")) as f:
        criteria = json.load(f)
    assert criteria["scenario"] == "triangle_trio" and criteria["passed"] is True
    assert {c["name"] for c in criteria["criteria"]} >= {"arrived", "contacts", "steady_navigating_slot_rms_m"}
    assert all(c["passed"] for c in criteria["criteria"])
    with open(os.path.join(run_dir, "metrics", "metrics.json")) as f:
        assert json.load(f)["state"] == "ARRIVED"
    if os.access(os.path.join(ROOT, "scripts", "report"), os.X_OK):
        assert os.path.isfile(os.path.join(run_dir, "index.html")), output
