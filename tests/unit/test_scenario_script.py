"""scripts/scenario: a run whose report cannot be written is a failed run (exit status 4, no
index.html left behind, an error line), not a success; a failed criterion is a failed run (exit
status 1) whose report is still written. The script runs in a copy of scripts/ whose workspace
holds a stand-in scenario runner (it writes criteria.json and exits as the real one does: 0 all
criteria passed, 1 one failed) and a stand-in scripts/report that writes a page and succeeds or
fails: only the script's own logic runs."""
import os
import shutil
import subprocess
import textwrap

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def fake_root(tmp_path, report_ok, runner_status=0):
    root = tmp_path / "ws"
    (root / "scripts").mkdir(parents=True)
    for name in ("scenario", "common.sh"):
        shutil.copy(os.path.join(ROOT, "scripts", name), str(root / "scripts" / name))
    pkg = root / "py" / "mbot_bringup"
    pkg.mkdir(parents=True)
    (pkg / "__init__.py").write_text("")
    (pkg / "scenario_runner.py").write_text(textwrap.dedent("""\
        import os, sys
        run_dir = sys.argv[sys.argv.index("--run-dir") + 1]
        os.makedirs(run_dir, exist_ok=True)
        passed = %d == 0
        open(os.path.join(run_dir, "criteria.json"), "w").write('{"passed": %%s, "criteria": []}' %% (
            "true" if passed else "false"))
        sys.exit(%d)
        """ % (runner_status, runner_status)))
    (root / "devel").mkdir()
    (root / "devel" / "setup.bash").write_text('export PYTHONPATH="%s"\n' % (root / "py"))
    report = root / "scripts" / "report"
    report.write_text("#!/bin/sh\necho '<html>half' > \"$1/index.html\"\nexit %d\n" % (0 if report_ok else 1))
    report.chmod(0o755)
    return root


def run(root, run_dir):
    return subprocess.run([str(root / "scripts" / "scenario"), "some_scenario", "--no-rviz", "--run-dir", str(run_dir)],
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=60)


def test_a_report_that_fails_fails_the_run_and_leaves_no_page(tmp_path):
    root = fake_root(tmp_path, report_ok=False)
    run_dir = tmp_path / "run"
    result = run(root, run_dir)
    assert result.returncode == 4, result.stdout
    assert "the report could not be written" in result.stdout
    assert not (run_dir / "index.html").exists()


def test_a_written_report_is_named_and_the_run_passes(tmp_path):
    root = fake_root(tmp_path, report_ok=True)
    run_dir = tmp_path / "run"
    result = run(root, run_dir)
    assert result.returncode == 0, result.stdout
    assert "report: %s/index.html" % run_dir in result.stdout


def test_a_failed_criterion_fails_the_run_and_its_report_is_still_written(tmp_path):
    root = fake_root(tmp_path, report_ok=True, runner_status=1)
    run_dir = tmp_path / "run"
    result = run(root, run_dir)
    assert result.returncode == 1, result.stdout
    assert "report: %s/index.html" % run_dir in result.stdout   # the page says which criterion failed
    assert (run_dir / "index.html").exists()
    assert '"passed": false' in (run_dir / "criteria.json").read_text()


def test_a_failed_criterion_and_a_failed_report_is_the_report_s_failure(tmp_path):
    root = fake_root(tmp_path, report_ok=False, runner_status=1)
    run_dir = tmp_path / "run"
    result = run(root, run_dir)
    assert result.returncode == 4, result.stdout
    assert not (run_dir / "index.html").exists()
