"""The report of a formation run, as a page to open from the file system:

    scripts/report RUN_DIR [--world FILE]          -> RUN_DIR/index.html (images in RUN_DIR/report/)
    scripts/report --compare RUN_A RUN_B [-o OUT]  -> OUT/index.html (default OUT: RUN_B/compare)

A run directory (the scenario runner writes it): metrics/ (the metrics collector's files, read
with mbot_follower.metrics.load_run), world.yaml (the world file; or --world), and optionally
criteria.json (the runner's verdict), screenshots/*.png, scenario.yaml, run.bag.

The page: the pass criteria (criteria.json, else the formation lab's defaults, LabCriteria), what
happened when, an animation, the paths on the map with formation snapshots, the formation error
over time with states and events, every number of the summary, time per state, switches,
losses, per robot numbers, latency and speed plots, the screenshots.

Every input is checked before anything is written: a missing or broken one is one line naming
the file (ReportError), exit status 1, and no page.

write_report() is the goal-tour demo's report (report_demo.py), kept for scripts/demo.
"""
import argparse
import html
import json
import os
import sys

from mbot_bringup.colors import robot_colors
from mbot_bringup.report_data import METRIC_BY_KEY, METRICS, STATES, LabCriteria, ReportError, arrival_time, \
    assignments, compare_rows, evaluate, format_value, parse_criteria, pause_spans, run_numbers, sorted_events, \
    switch_settling, target_time
from mbot_follower.metrics.settle import SWITCH_HOLD, SWITCH_TOLERANCE, switch_done_times
from mbot_bringup.report_scans import read_scans
from mbot_bringup.scenario import LAB_THRESHOLDS, criteria_reasons
from mbot_bringup.report_demo import write_report  # noqa: F401  (the demo's report: scripts/demo, fleet_office)

IMAGES = "report"   # the images' folder, beside index.html
PLOTS = ("trajectories.png", "errors.png", "latency.png", "speeds.png")
ANIMATION = "animation.gif"
MOMENTS = ("forming", "mid_route", "switch", "arrival")   # the order of screenshots taken in the same second


class RunInputs(object):
    """Everything a report reads from one run directory, checked."""

    def __init__(self, run_dir, world=None):
        from mbot_common.paths import resolve_world
        from mbot_common.strict_yaml import ConfigError
        from mbot_common.world import load_world
        from mbot_follower.metrics import RunFileError, load_run, summarize

        self.run_dir = run_dir
        if not os.path.isdir(run_dir):
            raise ReportError("%s: no such run directory" % run_dir)
        metrics = os.path.join(run_dir, "metrics")
        if not os.path.isdir(metrics):
            raise ReportError("%s: missing (the metrics collector's folder: metrics.csv, events.csv, "
                              "controller.csv, metrics.json)" % metrics)
        if not os.path.isfile(os.path.join(metrics, "metrics.json")):
            raise ReportError("%s: missing (the metrics collector writes it with the CSV files)"
                              % os.path.join(metrics, "metrics.json"))
        try:
            self.run = load_run(metrics)
        except RunFileError as error:
            raise ReportError(str(error))
        except (IOError, OSError) as error:
            raise ReportError("%s: cannot read: %s" % (error.filename, error.strerror))
        if not self.run.samples:
            raise ReportError("%s: no samples (the run recorded nothing)" % os.path.join(metrics, "metrics.csv"))
        self.summary = summarize(self.run)
        self.assignments = assignments(self.run, os.path.join(metrics, "events.csv"))

        try:
            self.world_path = resolve_world(world) if world else os.path.join(run_dir, "world.yaml")
        except ConfigError as error:
            raise ReportError(str(error))
        if not os.path.isfile(self.world_path):
            raise ReportError("%s: missing (the run's world file; or give one with --world FILE)" % self.world_path)
        try:
            self.world = load_world(self.world_path)
        except ConfigError as error:
            raise ReportError(str(error))
        if self.world.map_data.origin[2] != 0.0:
            raise ReportError("%s: origin: the report draws maps without rotation, got yaw %g"
                              % (self.world.map_path, self.world.map_data.origin[2]))

        self.numbers = run_numbers(self.run, self.summary)
        self.criteria_path = os.path.join(run_dir, "criteria.json")
        if os.path.isfile(self.criteria_path):
            try:
                with open(self.criteria_path) as f:
                    data = json.load(f)
            except ValueError as error:
                raise ReportError("%s: not valid JSON: %s" % (self.criteria_path, error))
            except (IOError, OSError) as error:
                raise ReportError("%s: cannot read: %s" % (self.criteria_path, error.strerror))
            self.scenario, self.passed, self.criteria, self.facts = parse_criteria(data, self.criteria_path)
            self.criteria_source = "criteria.json"
        else:
            self.scenario, self.facts = "", {}
            self.criteria = evaluate(self.numbers, LabCriteria().criteria())
            self.passed = all(c.passed for c in self.criteria)
            self.criteria_source = "the formation lab's defaults (no criteria.json)"

        # Screenshots in the order they were taken (file time); files of the same second (a copy,
        # a checkout) in the order of a run's moments, then by name.
        shots = os.path.join(run_dir, "screenshots")
        names = [n for n in os.listdir(shots) if n.lower().endswith(".png")] if os.path.isdir(shots) else []
        order = dict((m, i) for i, m in enumerate(MOMENTS))
        self.screenshots = sorted(names, key=lambda n: (int(os.path.getmtime(os.path.join(shots, n))),
                                                        order.get(os.path.splitext(n)[0], len(order)), n))
        self.scenario_file = os.path.join(run_dir, "scenario.yaml")

    def title(self):
        return self.scenario or os.path.basename(os.path.abspath(self.run_dir))

    def limit(self, name, default):
        """The threshold of criterion `name` (default when no criterion names it)."""
        for c in self.criteria:
            if c.name == name and not isinstance(c.threshold, bool):
                return c.threshold
        return default


# --- HTML -------------------------------------------------------------------------------------

STYLE_CSS = """body{font-family:sans-serif;max-width:72em;margin:1.5em auto;padding:0 1em;color:#222}
table{border-collapse:collapse;margin:0.5em 0}td,th{border:1px solid #bbb;padding:0.2em 0.6em;text-align:right}
th{background:#f0f0f0}td.l,th.l{text-align:left}img{max-width:100%}.pass{background:#d9f2d9}
.fail{background:#f7c6c6}.pause{background:#ffe3c7}.verdict{font-size:1.3em;padding:0.4em 0.8em;display:inline-block}
figure{display:inline-block;margin:0.5em;vertical-align:top}figcaption{text-align:center;font-size:0.9em}
.chip{display:inline-block;width:0.9em;height:0.9em;border-radius:50%;vertical-align:middle;margin-right:0.2em}
.side{display:flex;gap:1em}.side>div{flex:1}pre{background:#f6f6f6;padding:0.5em;overflow:auto}"""


def esc(text):
    return html.escape(str(text))


def table(header, rows, left=1):
    """An HTML table; header: [text]; rows: [[cell html]]; the first `left` columns align left.
    A row may be (cells, css class)."""
    def cells(tag, items):
        return "".join("<%s%s>%s</%s>" % (tag, ' class="l"' if i < left else "", c, tag) for i, c in enumerate(items))
    out = ["<table><tr>%s</tr>" % cells("th", [esc(h) for h in header])]
    for row in rows:
        css = ""
        if isinstance(row, tuple):
            row, css = row
        out.append("<tr%s>%s</tr>" % (' class="%s"' % css if css else "", cells("td", row)))
    return "".join(out) + "</table>"


def _threshold_text(name, c):
    if isinstance(c.threshold, bool):
        return "yes" if c.threshold else "no"
    return format_value(name, c.threshold)


def _looser(c, lab):
    return lab is not None and not isinstance(lab, bool) and not isinstance(c.threshold, bool) and \
        (c.threshold < lab if c.op == ">=" else c.op == "<=" and c.threshold > lab)


def criteria_table(inputs):
    """The criteria with the lab's threshold beside the run's and, for a looser one, the
    scenario file's reason (scenario.yaml's `why:`)."""
    why = criteria_reasons(inputs.scenario_file) if os.path.isfile(inputs.scenario_file) else {}
    rows = []
    for c in inputs.criteria:
        metric = METRIC_BY_KEY.get(c.name)   # None: a criterion of the runner's own
        label, unit = (metric.label, metric.unit) if metric else (c.name, "")
        lab = LAB_THRESHOLDS.get(c.name)
        lab_text = "" if lab is None else _threshold_text(c.name, c._replace(threshold=lab))
        reason = why.get(c.name, "(no reason given)") if _looser(c, lab) else ""
        rows.append(([esc(label), "<code>%s</code>" % esc(c.name), esc(format_value(c.name, c.value)), esc(c.op),
                      esc(_threshold_text(c.name, c)), esc(lab_text), esc(unit), "PASS" if c.passed else "FAIL",
                      esc(reason)],
                     "pass" if c.passed else "fail"))
    out = table(["criterion", "key", "value", "", "threshold", "lab's", "unit", "result", "why looser than the lab"],
                rows, left=2)
    if inputs.facts:
        out += "<p>What the scenario runner saw: %s.</p>" % esc(", ".join(
            "%s = %s" % (k, _fact(v)) for k, v in sorted(inputs.facts.items())))
    return out


def _fact(value):
    """A value of criteria.json's facts, numbers to 4 digits."""
    if isinstance(value, float):
        return "%.4g" % value
    if isinstance(value, list):
        return "[%s]" % ", ".join(_fact(v) for v in value)
    return json.dumps(value)


def timeline_table(inputs):
    """What happened, from the target on: state changes with their reason, switches, losses,
    rejoins, contacts, leader pauses (start with the reason, end with the length)."""
    t0 = target_time(inputs.run)
    run = inputs.run
    pauses = pause_spans(run, run.samples[-1].t if run.samples else t0)
    rows = []
    for e in sorted_events(run):
        if e.kind == "assignment":
            continue
        what = {"state": "state %s" % e.name, "switch": "switch %s &rarr; %s" % (esc(e.detail), esc(e.name)),
                "loss": "lost %s" % e.name, "rejoin": "%s rejoined" % e.name,
                "contact": "contact %s &harr; %s at (%.2f, %.2f) m" % (esc(e.name), esc(e.detail), e.x, e.y),
                "pause": "leader paused" if e.name == "start" else "pause ends"}
        text = what.get(e.kind, "%s %s" % (e.kind, e.name))
        detail = esc(e.detail) if e.kind == "state" else ""
        if e.kind == "pause":
            if e.name == "start":
                detail = esc(next((p.reason for p in pauses if abs(p.start - e.t) < 1e-9), e.detail))
            else:
                length = [e.t - p.start for p in pauses if abs(p.end - e.t) < 1e-9]
                detail = esc("; ".join(d for d in ["after %.2f s" % length[0] if length else "", e.detail] if d))
        css = "fail" if e.kind in ("loss", "contact") or (e.kind == "state" and e.name in ("DEGRADED", "ABORTED")) \
            else "pause" if e.kind == "pause" else ""
        rows.append(([text if e.kind in ("switch", "contact") else esc(text), detail, "%.2f" % (e.t - t0)], css))
    return table(["what", "why (the coordinator's reason)", "time from target [s]"], rows, left=2)


def metrics_table(numbers):
    rows = [[esc(m.label), esc(m.unit or "-"), esc(format_value(m.key, numbers.get(m.key)))]
            for m in METRICS if not m.key.startswith("time_in_state_s.")]
    return table(["metric", "unit", "value"], rows, left=2)


def state_table(summary):
    spent = summary["fleet"]["time_in_state_s"]
    total = sum(spent.values()) or 1.0
    ordered = [s for s in STATES if s in spent] + sorted(s for s in spent if s not in STATES)
    return table(["state", "time [s]", "share [%]"],
                 [[esc(s), "%.1f" % spent[s], "%.0f" % (100.0 * spent[s] / total)] for s in ordered])


def switch_table(inputs):
    t0 = target_time(inputs.run)

    def seconds(value):
        return "never" if value is None else "%.2f" % value

    rows = [[esc(s["previous"]), esc(s["formation"]), "%.2f" % (s["t_s"] - t0), seconds(d["switch_time_s"]),
             "-" if d["coordinator_done_s"] is None else "%.2f" % d["coordinator_done_s"],
             seconds(s["settle_s"]), "-" if s["peak_rms_m"] is None else "%.3f" % s["peak_rms_m"]]
            for s, d in zip(switch_settling(inputs.run), switch_done_times(inputs.run))]
    if not rows:
        return "<p>No formation switch.</p>"
    config = inputs.run.config
    rule = ("<p>Switch time: until every follower was within %.2f m of its new slot, held %.1f s (the one rule "
            "of mbot_follower.metrics.settle, which the coordinator, the scenario judge and the benchmark use); "
            "the coordinator's done: when the coordinator saw that hold complete. Settled, a later figure: the "
            "slot RMS is below %.2f m and stays there for %.1f s (the same rule as a recovery after a loss).</p>"
            % (SWITCH_TOLERANCE, SWITCH_HOLD, config.recovered_rms, config.recovered_hold))
    return table(["from", "to", "at [s from target]", "switch time [s]", "coordinator's done [s]",
                  "time to settle [s]", "largest slot RMS meanwhile [m]"], rows, left=2) + rule


def recovery_table(inputs):
    t0 = target_time(inputs.run)

    def sec(v):
        return "never" if v is None else "%.2f" % v
    rows = [[esc(r["robot"]), "%.2f" % (r["t_s"] - t0), sec(r["time_to_degraded_s"]), sec(r["recovery_time_s"])]
            for r in inputs.summary["recoveries"]]
    if not rows:
        return "<p>No robot was lost.</p>"
    return table(["robot", "lost at [s from target]", "to DEGRADED [s]", "recovered after [s]"], rows)


def robot_table(inputs, colors):
    rows = []
    for r, e in inputs.summary["robots"].items():
        def v(key, scale=1.0, digits=3):
            return "-" if e.get(key) is None else "%.*f" % (digits, e[key] * scale)
        chip = '<span class="chip" style="background:%s"></span>' % _hex(colors[r])
        rows.append([chip + esc(r), v("distance_m", digits=2), v("energy_j", digits=1), v("slot_rms_m"),
                     v("slot_p95_m"), v("slot_max_m"), v("latency_p95_s", 1000.0, 0),
                     v("tf_success_rate", 100.0, 2), v("cycle_time_p99_ms", digits=1)])
    return table(["robot", "distance [m]", "energy [J]", "slot RMS [m]", "slot p95 [m]", "slot max [m]",
                  "latency p95 [ms]", "tf success [%]", "cycle p99 [ms wall]"], rows)


def _hex(rgb):
    return "#%02x%02x%02x" % tuple(int(round(255 * c)) for c in rgb)


def _link(page_dir, path, text=None):
    return '<a href="%s">%s</a>' % (esc(os.path.relpath(path, page_dir)), esc(text or os.path.basename(path)))


def verdict_html(inputs):
    failed = [c for c in inputs.criteria if not c.passed]
    if inputs.passed:
        return '<p class="verdict pass">PASS: all %d criteria met</p>' % len(inputs.criteria)
    return '<p class="verdict fail">FAIL: %d of %d criteria not met (%s)</p>' % (
        len(failed), len(inputs.criteria), esc(", ".join(c.name for c in failed)) or "see criteria.json")


def files_html(inputs, page_dir):
    """Links to the metrics files, the world and every other file of the run directory; the
    scenario's text."""
    items = []
    metrics = os.path.join(inputs.run_dir, "metrics")
    for name in ("metrics.csv", "events.csv", "controller.csv", "metrics.json"):
        items.append(_link(page_dir, os.path.join(metrics, name), "metrics/" + name))
    if os.path.dirname(os.path.abspath(inputs.world_path)) != os.path.abspath(inputs.run_dir):
        items.append(_link(page_dir, inputs.world_path, "world: " + inputs.world_path))
    for name in sorted(os.listdir(inputs.run_dir)):
        path = os.path.join(inputs.run_dir, name)
        if os.path.isfile(path) and name != "index.html":
            items.append(_link(page_dir, path) + " (%.1f kB)" % (os.path.getsize(path) / 1e3))
    out = "<ul>%s</ul>" % "".join("<li>%s</li>" % i for i in items)
    if os.path.isfile(inputs.scenario_file):
        with open(inputs.scenario_file) as f:
            out += "<h3>scenario.yaml</h3><pre>%s</pre>" % esc(f.read())
    return out


def _page(title, body):
    return ('<!DOCTYPE html>\n<html><head><meta charset="utf-8"><title>%s</title><style>%s</style></head>\n'
            '<body>%s</body></html>\n' % (esc(title), STYLE_CSS, body))


def _write_atomic(path, text):
    tmp = path + ".tmp"
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, path)
    return path


def render_images(inputs, image_dir, animation=True):
    """Write the plots (and the animation) into image_dir; {name: path}, colours {robot: rgb}."""
    from mbot_bringup import report_plots as plots
    if not os.path.isdir(image_dir):
        os.makedirs(image_dir)
    run, radius = inputs.run, inputs.run.config.robot_radius
    colors = robot_colors(run.robots, [r.name for r in inputs.world.robots])
    out = {}
    out["trajectories.png"] = plots.plot_trajectories(run, inputs.world, colors,
                                                      os.path.join(image_dir, "trajectories.png"), radius)
    out["errors.png"] = plots.plot_errors(run, colors, os.path.join(image_dir, "errors.png"),
                                          inputs.limit("steady_navigating_slot_rms_m", None),
                                          inputs.limit("leader_lateral_rms_m", None))
    out["latency.png"] = plots.plot_latency(run, colors, os.path.join(image_dir, "latency.png"),
                                            inputs.limit("latency_p95_s", None))
    out["speeds.png"] = plots.plot_speeds(run, colors, os.path.join(image_dir, "speeds.png"))
    if animation:
        path = os.path.join(image_dir, ANIMATION)
        bag = os.path.join(inputs.run_dir, "run.bag")
        scans = read_scans(bag, run.robots) if os.path.isfile(bag) else None
        plots.write_animation(run, inputs.world, colors, path, radius, scans)
        out[ANIMATION] = path
    return out, colors


def write_run_report(run_dir, world=None, animation=True):
    """Check the inputs of run_dir, write run_dir/report/* and run_dir/index.html; its path."""
    inputs = RunInputs(run_dir, world)
    image_dir = os.path.join(run_dir, IMAGES)
    images, colors = render_images(inputs, image_dir, animation)
    run, summary = inputs.run, inputs.summary
    t0 = target_time(run)
    arrived = arrival_time(run)

    def img(name, alt):
        return '<img src="%s/%s" alt="%s">' % (IMAGES, name, esc(alt)) if name in images else ""
    robots = " ".join('<span class="chip" style="background:%s"></span>%s' % (_hex(colors[r]), esc(r))
                      for r in run.robots)
    formations = []
    for a in inputs.assignments:
        if not formations or formations[-1] != a.formation:
            formations.append(a.formation)
    shots = "".join('<figure><img src="%s" alt="%s"><figcaption>%s</figcaption></figure>' % (
        esc("screenshots/" + n), esc(n), esc(os.path.splitext(n)[0])) for n in inputs.screenshots)
    body = [
        "<h1>Formation run: %s</h1>" % esc(inputs.title()),
        verdict_html(inputs),
        "<p>World <code>%s</code> (map <code>%s</code>); robots %s; leader <b>%s</b>; formation %s. %.1f s of "
        "sim time; the target came %.1f s after the start; %s. Times below count from the target.</p>" % (
            esc(os.path.basename(inputs.world_path)), esc(os.path.basename(inputs.world.map)), robots,
            esc(run.samples[0].leader), " &rarr; ".join(esc(f) for f in formations) if formations else "-",
            summary["duration_s"], t0 - summary["start_s"],
            "ARRIVED %.1f s after the target" % (arrived - t0) if arrived is not None
            else "<b>never arrived</b> (final state %s)" % esc(summary["state"] or "none")),
        "<h2>Pass criteria</h2><p>From %s.</p>%s" % (esc(inputs.criteria_source), criteria_table(inputs)),
        "<h2>What happened</h2>%s" % timeline_table(inputs),
    ]
    if ANIMATION in images:
        body.append("<h2>Animation</h2><p>Discs: robots (heading tick); dashed rings: the slots they should be "
                    "in; grey lines: to the leader; caption: time from target, state, formation, slot RMS and "
                    "how much faster than sim time it plays.</p>" + img(ANIMATION, "animation of the run"))
    body += [
        "<h2>Paths and formation snapshots</h2>" + img("trajectories.png", "trajectories"),
        "<h2>Formation error over time</h2>" + img("errors.png", "formation error over time"),
        "<h2>Metrics</h2>" + metrics_table(inputs.numbers),
        "<h2>Time per state</h2>" + state_table(summary),
        "<h2>Formation switches</h2>" + switch_table(inputs),
        "<h2>Losses and recoveries</h2>" + recovery_table(inputs),
        "<h2>Per robot</h2>" + robot_table(inputs, colors),
        "<h2>Control latency</h2>" + img("latency.png", "latency histogram"),
        "<h2>Speeds</h2>" + img("speeds.png", "speed profiles"),
        "<h2>Screenshots</h2>" + (shots or "<p>No screenshots in this run.</p>"),
        "<h2>Files</h2>" + files_html(inputs, run_dir),
    ]
    return _write_atomic(os.path.join(run_dir, "index.html"), _page("run " + inputs.title(), "\n".join(body)))


def write_compare_report(run_a, run_b, out_dir=None):
    """Check both runs, write out_dir/report/* and out_dir/index.html (default out_dir:
    run_b/compare): both runs side by side, every metric with B - A and which is better, and the
    formation errors of both on one axis. Returns the path of index.html."""
    from mbot_bringup import report_plots as plots
    a, b = RunInputs(run_a), RunInputs(run_b)
    out_dir = out_dir or os.path.join(run_b, "compare")
    image_dir = os.path.join(out_dir, IMAGES)
    if not os.path.isdir(image_dir):
        os.makedirs(image_dir)
    names = ["A", "B"]
    for name, inputs in zip(names, (a, b)):
        colors = robot_colors(inputs.run.robots, [r.name for r in inputs.world.robots])
        plots.plot_trajectories(inputs.run, inputs.world, colors, os.path.join(image_dir, "trajectories_%s.png" % name),
                                inputs.run.config.robot_radius)
    plots.plot_compare_errors([a.run, b.run], names, os.path.join(image_dir, "errors_compare.png"),
                              b.limit("steady_navigating_slot_rms_m", a.limit("steady_navigating_slot_rms_m", None)))
    rows = []
    for key, va, vb, diff, better in compare_rows(a.numbers, b.numbers):
        metric = [m for m in METRICS if m.key == key][0]
        shown_diff = "-" if diff is None else ("%+.*f" % (metric.digits, diff * metric.scale))
        css = {"A": "fail", "B": "pass"}.get(better, "")
        rows.append(([esc(metric.label), esc(metric.unit or "-"), esc(format_value(key, va)),
                      esc(format_value(key, vb)), esc(shown_diff), esc(better or "-")], css))

    def run_cell(name, inputs):
        index = os.path.join(inputs.run_dir, "index.html")
        link = _link(out_dir, index, "its report") if os.path.isfile(index) else "no report yet"
        return "<div><h3>%s: %s</h3>%s<p>%s; %s</p>%s</div>" % (
            name, esc(inputs.title()), verdict_html(inputs), esc(os.path.abspath(inputs.run_dir)), link,
            '<img src="%s/trajectories_%s.png" alt="paths of %s">' % (IMAGES, name, name))
    body = [
        "<h1>Compare: A = %s, B = %s</h1>" % (esc(a.title()), esc(b.title())),
        '<div class="side">%s%s</div>' % (run_cell("A", a), run_cell("B", b)),
        "<h2>Formation error of both runs</h2><img src=\"%s/errors_compare.png\" alt=\"errors of both runs\">" % IMAGES,
        "<h2>Every metric</h2><p>Green: B is better, red: A is better (lower is better for errors, latency, "
        "times and energy; higher for tf success, clearance and arriving).</p>",
        table(["metric", "unit", "A", "B", "B - A", "better"], rows, left=2),
    ]
    return _write_atomic(os.path.join(out_dir, "index.html"),
                         _page("compare %s %s" % (a.title(), b.title()), "\n".join(body)))


def main(argv=None):
    parser = argparse.ArgumentParser(
        prog="scripts/report", description="HTML report of a formation run directory, or of two runs compared.")
    parser.add_argument("run_dir", nargs="?", help="the run directory (metrics/, world.yaml, ...)")
    parser.add_argument("--world", help="world file or name, if not RUN_DIR/world.yaml")
    parser.add_argument("--compare", nargs=2, metavar=("RUN_A", "RUN_B"), help="compare two run directories")
    parser.add_argument("-o", "--output", help="with --compare: the folder of the page (default RUN_B/compare)")
    args = parser.parse_args(argv)
    if (args.run_dir is None) == (args.compare is None):
        parser.error("give either RUN_DIR or --compare RUN_A RUN_B")
    if args.compare and args.world:
        parser.error("--world is for one run; compared runs use their own world.yaml")
    if args.output and not args.compare:
        parser.error("-o is for --compare; a run's report is RUN_DIR/index.html")
    try:
        if args.compare:
            path = write_compare_report(args.compare[0], args.compare[1], args.output)
        else:
            path = write_run_report(args.run_dir, args.world)
    except ReportError as error:
        print("report: error: %s" % error, file=sys.stderr)
        return 1
    print(path)
    return 0


if __name__ == "__main__":
    sys.exit(main())
