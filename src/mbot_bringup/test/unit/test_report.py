"""The formation run report (scripts/report, mbot_bringup.report) on the recorded run
test/fixtures/run_trio (triangle, a switch to line, a 0.1 s loss of follower_2, ARRIVED): the page
has the criteria table, the timeline, every plot, the animation and the screenshots; compare
shows every metric with B - A; every missing or broken input is one line naming the file, exit
status 1 and no page."""
import json
import os
import re
import shutil
import subprocess

import pytest

from mbot_bringup.report import ANIMATION, IMAGES, PLOTS, RunInputs, main, write_compare_report, write_run_report
from mbot_common.world import load_world
from mbot_follower.metrics import RunWriter, load_run, summarize

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURE = os.path.join(HERE, "..", "fixtures", "run_trio")
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", "..", ".."))
SCRIPT = os.path.join(ROOT, "scripts", "report")
PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


def copy_run(where, name="run"):
    """A copy of the fixture run; its world.yaml names the map by its absolute path (the
    fixture's path is relative to the fixture's folder)."""
    dst = os.path.join(str(where), name)
    shutil.copytree(FIXTURE, dst)
    map_path = os.path.abspath(load_world(os.path.join(FIXTURE, "world.yaml")).map_path)
    with open(os.path.join(dst, "world.yaml")) as f:
        text = f.read()
    with open(os.path.join(dst, "world.yaml"), "w") as f:
        f.write(re.sub(r"(?m)^map: .*$", "map: " + map_path, text))
    return dst


def row_cells(page, first_cell):
    """The cells (tags removed) of the table row whose first cell is first_cell."""
    for row in re.findall(r"<tr[^>]*>(.*?)</tr>", page, re.S):
        cells = [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<t[dh][^>]*>(.*?)</t[dh]>", row, re.S)]
        if cells and cells[0] == first_cell:
            return cells
    raise AssertionError("no row %r in the page" % first_cell)


@pytest.fixture(scope="module")
def report(tmp_path_factory):
    """(run dir, page text, stdout) of `scripts/report RUN_DIR` on a copy of the fixture."""
    run = copy_run(tmp_path_factory.mktemp("report"))
    for name in ("switch.png", "arrival.png"):     # taken in the same second, as after a checkout
        os.utime(os.path.join(run, "screenshots", name), (1e9, 1e9))
    out = subprocess.run([SCRIPT, run], stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                         timeout=300)
    assert out.returncode == 0, out.stderr
    with open(os.path.join(run, "index.html")) as f:
        return run, f.read(), out.stdout


def test_the_script_writes_index_html_and_prints_its_path(report):
    run, page, stdout = report
    assert stdout.strip() == os.path.join(run, "index.html")
    assert page.startswith("<!DOCTYPE html>") and page.rstrip().endswith("</html>")


def test_criteria_table_shows_criteria_json_with_units(report):
    _, page, _ = report
    with open(os.path.join(FIXTURE, "criteria.json")) as f:
        criteria = json.load(f)["criteria"]
    summary = summarize(load_run(os.path.join(FIXTURE, "metrics")))
    fleet = summary["fleet"]
    # criteria.json holds what the metrics files give (the runner judged the same run)
    values = dict((c["name"], c["value"]) for c in criteria)
    assert values["steady_navigating_slot_rms_m"] == pytest.approx(fleet["steady_navigating_slot_rms_m"])
    assert values["latency_p95_s"] == pytest.approx(fleet["latency_p95_s"])
    assert row_cells(page, "formation error, RMS while moving (slots free)") == [
        "formation error, RMS while moving (slots free)", "steady_navigating_slot_rms_m",
        "%.3f" % fleet["steady_navigating_slot_rms_m"], "&lt;=", "0.150", "0.150", "m", "FAIL", ""]
    assert fleet["steady_navigating_slot_rms_m"] > 0.15
    # the fixture's latency limit is 0.2 s, not the lab's 0.12 s: the page uses criteria.json and
    # shows the lab's beside it; the fixture has no scenario.yaml to say why
    assert row_cells(page, "control latency, 95th percentile")[2:] == [
        "%.0f" % (1000 * fleet["latency_p95_s"]), "&lt;=", "200", "120", "ms", "PASS", "(no reason given)"]
    assert row_cells(page, "tf lookup success")[2:] == [
        "%.3f" % (100 * fleet["tf_success_rate"]), "&gt;=", "99.990", "99.990", "%", "FAIL", ""]
    assert row_cells(page, "arrived at the target")[2:] == ["yes", "==", "yes", "yes", "", "PASS", ""]
    assert "FAIL: 3 of 6 criteria not met" in page
    for header in ("threshold", "lab&#x27;s", "why looser than the lab", "unit",
                   "time from target [s]", "time [s]", "distance [m]", "energy [J]",
                   "latency p95 [ms]", "time to settle [s]"):
        assert "<th" in page and ">%s</th>" % header in page


def test_tables_give_the_measured_arrival_switch_and_loss(report):
    _, page, _ = report
    # events.csv: FORMING at 6152.45 s (the target), the switch at 6171.45, the loss at 6200.25, ARRIVED at 6204.05
    assert row_cells(page, "arrival: target to ARRIVED")[2] == "51.60"
    assert row_cells(page, "switch triangle &rarr; line")[2] == "19.00"
    switch = row_cells(page, "triangle")
    assert switch[:3] == ["triangle", "line", "19.00"]
    assert 2.0 < float(switch[3]) < 10.0            # the followers need some seconds to move out 2.5 m
    assert switch[4] == "-"                         # recorded before the coordinator's switch_done events
    # settled (RMS < 0.15 m for 1 s: with two followers each < 0.21 m) comes after the switch time
    assert float(switch[3]) <= float(switch[5]) < 10.0
    assert float(switch[6]) > 2.0                   # the line's slots are ~2.5 m from the triangle's
    assert row_cells(page, "follower_2")[1:3] == ["47.80", "0.00"]
    spent = summarize(load_run(os.path.join(FIXTURE, "metrics")))["fleet"]["time_in_state_s"]
    assert row_cells(page, "NAVIGATING")[1] == "%.1f" % spent["NAVIGATING"]


def test_overruns_and_late_starts_stand_beside_the_cycle_time(tmp_path):
    """The follower's overrun and late-start counters (controller.csv, newest per robot, summed)
    are rows right below the cycle time p99 in the metrics table."""
    from mbot_bringup.report import metrics_table
    run = copy_run(tmp_path)
    path = os.path.join(run, "metrics", "controller.csv")
    with open(path) as f:
        lines = f.read().splitlines()
    # the fixture predates the counters (7 columns): give them counters that grow as a follower's do
    seen, newest = {}, {}
    out = [lines[0] + ",overruns,late_starts"]
    for line in lines[1:]:
        robot = line.split(",")[1]
        seen[robot] = seen.get(robot, 0) + 1
        counters = (0, 0) if robot == "leader" else (seen[robot] // 100, seen[robot] // 250)
        newest[robot] = counters
        out.append(line + ",%d,%d" % counters)
    with open(path, "w") as f:
        f.write("\n".join(out) + "\n")
    overruns, late = sum(c[0] for c in newest.values()), sum(c[1] for c in newest.values())
    assert (overruns, late) == (12, 4)   # follower_1: 620 rows, follower_2: 617
    page = metrics_table(RunInputs(run).numbers)
    names = [re.sub(r"<[^>]+>", "", c) for c in re.findall(r"<tr><td class=\"l\">(.*?)</td>", page)]
    at = names.index("controller cycle time, 99th percentile (wall)")
    assert names[at + 1:at + 3] == ["controller cycles longer than the period (overruns, all robots)",
                                    "controller cycles started a period or more late (all robots)"]
    assert row_cells(page, names[at + 1])[1:] == ["-", "12"]
    assert row_cells(page, names[at + 2])[1:] == ["-", "4"]


def test_every_plot_is_a_png_that_shows_something(report):
    from PIL import Image
    run, page, _ = report
    for name in PLOTS:
        path = os.path.join(run, IMAGES, name)
        with open(path, "rb") as f:
            assert f.read(8) == PNG_MAGIC, name
        assert os.path.getsize(path) > 10000, name
        image = Image.open(path).convert("RGB")
        assert image.size[0] >= 600, name
        assert len(image.getcolors(1 << 20)) > 50, name   # lines, colours, text: not a blank canvas
        assert 'src="%s/%s"' % (IMAGES, name) in page


def test_the_animation_has_frames_at_10_fps_and_moves(report):
    from PIL import Image, ImageChops
    run, page, _ = report
    path = os.path.join(run, IMAGES, ANIMATION)
    assert 'src="%s/%s"' % (IMAGES, ANIMATION) in page
    assert os.path.getsize(path) < 5e6
    gif = Image.open(path)
    assert gif.format == "GIF"
    samples = len(load_run(os.path.join(FIXTURE, "metrics")).samples)
    assert 10 < gif.n_frames <= min(samples, 240)
    assert gif.info["duration"] == 100                # [ms] 10 frames per second
    gif.seek(0)
    first = gif.convert("RGB")
    gif.seek(gif.n_frames // 2)
    middle = gif.convert("RGB")
    assert ImageChops.difference(first, middle).getbbox() is not None   # the robots moved


def test_screenshots_appear_with_their_names_in_run_order(report):
    _, page, _ = report
    switch = page.index('<img src="screenshots/switch.png" alt="switch.png"><figcaption>switch</figcaption>')
    arrival = page.index('<img src="screenshots/arrival.png" alt="arrival.png"><figcaption>arrival</figcaption>')
    assert switch < arrival          # same file time: the moments in the order of a run, not by name


def test_screenshots_are_in_the_order_they_were_taken(tmp_path):
    run = copy_run(tmp_path)
    shots = os.path.join(run, "screenshots")
    shutil.copy(os.path.join(shots, "switch.png"), os.path.join(shots, "loss.png"))
    for name, t in (("switch.png", 1000.0), ("loss.png", 1030.0), ("arrival.png", 1050.0)):
        os.utime(os.path.join(shots, name), (t, t))
    assert RunInputs(run).screenshots == ["switch.png", "loss.png", "arrival.png"]
    os.utime(os.path.join(shots, "loss.png"), (1050.0, 1050.0))   # the same second as arrival: moments first
    assert RunInputs(run).screenshots == ["switch.png", "arrival.png", "loss.png"]


def test_every_image_and_link_of_the_page_exists(report):
    run, page, _ = report
    targets = re.findall(r'(?:src|href)="([^"]+)"', page)
    assert len(targets) >= 12
    for target in targets:
        assert os.path.exists(os.path.join(run, target)), target


def test_without_criteria_json_the_lab_defaults_judge(tmp_path):
    run = copy_run(tmp_path)
    os.remove(os.path.join(run, "criteria.json"))
    with open(write_run_report(run, animation=False)) as f:
        page = f.read()
    assert "the formation lab&#x27;s defaults (no criteria.json)" in page
    fleet = summarize(load_run(os.path.join(run, "metrics")))["fleet"]
    assert 0.12 < fleet["latency_p95_s"] <= 0.2
    assert row_cells(page, "control latency, 95th percentile")[4:] == ["120", "120", "ms", "FAIL", ""]
    assert row_cells(page, "leader lateral path error, RMS")[4:] == ["0.080", "0.080", "m", "FAIL", ""]
    assert row_cells(page, "contacts")[2:] == ["0", "&lt;=", "0", "0", "", "PASS", ""]
    assert "FAIL: 4 of 6 criteria not met" in page
    assert not os.path.exists(os.path.join(run, IMAGES, ANIMATION))


def test_a_widened_threshold_shows_the_lab_s_and_the_scenario_s_reason(tmp_path):
    run = copy_run(tmp_path)
    with open(os.path.join(run, "scenario.yaml"), "w") as f:
        f.write("criteria:\n  latency_p95_s: {value: 0.2, why: \"a slow <test> machine\"}\n")
    with open(write_run_report(run, animation=False)) as f:
        page = f.read()
    assert row_cells(page, "control latency, 95th percentile")[4:] == [
        "200", "120", "ms", "PASS", "a slow &lt;test&gt; machine"]
    assert row_cells(page, "contacts")[4:] == ["0", "0", "", "PASS", ""]


def test_scenario_yaml_is_shown(tmp_path):
    run = copy_run(tmp_path)
    with open(os.path.join(run, "scenario.yaml"), "w") as f:
        f.write("name: trio_line_switch  # <a test>\n")
    with open(write_run_report(run, animation=False)) as f:
        page = f.read()
    assert "<h3>scenario.yaml</h3><pre>name: trio_line_switch  # &lt;a test&gt;\n</pre>" in page


def better_copy(where):
    """The fixture run with every slot error halved (a better controller, as far as the
    formation error goes), written by the metrics collector's writer."""
    run = load_run(os.path.join(FIXTURE, "metrics"))
    for i, s in enumerate(run.samples):
        robots = dict((r, p._replace(slot_error=p.slot_error / 2)) for r, p in s.robots.items())
        run.samples[i] = s._replace(slot_rms=s.slot_rms / 2, slot_max=s.slot_max / 2, robots=robots)
    dst = copy_run(where, "better")
    shutil.rmtree(os.path.join(dst, "metrics"))
    RunWriter(os.path.join(dst, "metrics")).write(run, summarize(run))
    return dst


def test_compare_gives_every_metric_with_b_minus_a(tmp_path):
    a, b = copy_run(tmp_path, "a"), better_copy(tmp_path)
    out = str(tmp_path / "cmp")
    with open(write_compare_report(a, b, out)) as f:
        page = f.read()
    fa = summarize(load_run(os.path.join(a, "metrics")))["fleet"]
    fb = summarize(load_run(os.path.join(b, "metrics")))["fleet"]
    assert fb["slot_rms_m"] == pytest.approx(fa["slot_rms_m"] / 2)
    assert row_cells(page, "formation error, RMS over the whole run")[1:] == [
        "m", "%.3f" % fa["slot_rms_m"], "%.3f" % fb["slot_rms_m"], "%+.3f" % (fb["slot_rms_m"] - fa["slot_rms_m"]), "B"]
    assert row_cells(page, "control latency, 95th percentile")[1:] == ["ms", "130", "130", "+0", "same"]
    assert row_cells(page, "arrived at the target")[1:] == ["-", "yes", "yes", "-", "same"]
    for name in ("errors_compare.png", "trajectories_A.png", "trajectories_B.png"):
        path = os.path.join(out, IMAGES, name)
        with open(path, "rb") as f:
            assert f.read(8) == PNG_MAGIC
        assert os.path.getsize(path) > 10000
        assert 'src="%s/%s"' % (IMAGES, name) in page


def test_compare_by_the_script_defaults_to_run_b_compare(tmp_path):
    a, b = copy_run(tmp_path, "a"), copy_run(tmp_path, "b")
    out = subprocess.run([SCRIPT, "--compare", a, b], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                         universal_newlines=True, timeout=300)
    assert out.returncode == 0, out.stderr
    assert out.stdout.strip() == os.path.join(b, "compare", "index.html")
    with open(out.stdout.strip()) as f:
        page = f.read()
    assert row_cells(page, "formation error, RMS while moving (slots free)")[4:] == ["+0.000", "same"]


# --- inputs that are missing or broken ---------------------------------------------------------

def _remove(path):
    if os.path.isdir(path):
        shutil.rmtree(path)
    else:
        os.remove(path)


def _write(path, text):
    with open(path, "w") as f:
        f.write(text)


BROKEN = [
    # (what to do to the run, file the message names, words of the message)
    ("no metrics dir", lambda run: _remove(os.path.join(run, "metrics")), "metrics", "missing"),
    ("no metrics.json", lambda run: _remove(os.path.join(run, "metrics", "metrics.json")), "metrics.json", "missing"),
    ("metrics.json not JSON", lambda run: _write(os.path.join(run, "metrics", "metrics.json"), "{not json"),
     "metrics.json", "Expecting property name"),
    ("metrics.csv header", lambda run: _write(os.path.join(run, "metrics", "metrics.csv"), "t,x\n1,2\n"),
     "metrics.csv", "line 1: expected the columns"),
    ("no world.yaml", lambda run: _remove(os.path.join(run, "world.yaml")), "world.yaml", "missing"),
    ("missing map", lambda run: _write(os.path.join(run, "world.yaml"), "map: nowhere.yaml\nrobots: []\n"),
     "nowhere.yaml", "cannot read"),
    ("criteria.json type", lambda run: _write(os.path.join(run, "criteria.json"),
                                              '{"scenario": "x", "passed": "yes", "criteria": []}'),
     "criteria.json", "passed: expected true or false"),
    ("criteria.json op", lambda run: _write(os.path.join(run, "criteria.json"), json.dumps(
        {"scenario": "x", "passed": True, "criteria": [
            {"name": "contacts", "value": 0, "threshold": 0, "op": "=<", "passed": True}]})),
     "criteria.json", "criteria[0].op: expected one of"),
]


@pytest.mark.parametrize("case", BROKEN, ids=[c[0] for c in BROKEN])
def test_a_broken_input_is_one_line_naming_the_file_and_no_page(tmp_path, capsys, case):
    _, spoil, name, words = case
    run = copy_run(tmp_path)
    spoil(run)
    assert main([run]) == 1
    captured = capsys.readouterr()
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith("report: error: ")
    assert re.search(r"%s\b" % re.escape(name), lines[0]) and words in lines[0], lines[0]
    assert captured.out == ""
    assert not os.path.exists(os.path.join(run, "index.html"))
    assert not os.path.exists(os.path.join(run, IMAGES))


def test_the_script_fails_with_one_line_and_status_1(tmp_path):
    run = copy_run(tmp_path)
    _remove(os.path.join(run, "metrics"))
    out = subprocess.run([SCRIPT, run], stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True,
                         timeout=120)
    assert out.returncode == 1
    assert out.stderr.splitlines() == ["report: error: %s: missing (the metrics collector's folder: metrics.csv, "
                                       "events.csv, controller.csv, metrics.json)" % os.path.join(run, "metrics")]
    assert out.stdout == ""


def test_world_option_takes_a_world_name(tmp_path, capsys):
    run = copy_run(tmp_path)
    _remove(os.path.join(run, "world.yaml"))
    assert RunInputs(run, "trio").world_path == os.path.join(ROOT, "maps", "trio.world.yaml")
    assert main([run, "--world", "no_such_world"]) == 1
    assert capsys.readouterr().err.startswith('report: error: world "no_such_world": no world file of that name')


def test_a_missing_run_dir_of_compare_is_named(tmp_path, capsys):
    a = copy_run(tmp_path, "a")
    missing = str(tmp_path / "nothing")
    assert main(["--compare", a, missing]) == 1
    assert capsys.readouterr().err.splitlines() == ["report: error: %s: no such run directory" % missing]
