"""scripts/scenario: a run whose report cannot be written is a failed run (exit status 4, no
index.html left behind, an error line), not a success. The script runs in a copy of scripts/
whose workspace holds a stand-in scenario runner (it writes criteria.json, all passed) and a
stand-in scripts/report that fails after writing half a page: only the script's own logic runs."""
import os
import shutil
import subprocess
import textwrap

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def fake_root(tmp_path, report_ok):
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
        open(os.path.join(run_dir, "criteria.json"), "w").write('{"passed": true, "criteria": []}')
        """))
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
