"""The HTML report of the goal-tour demo (recording.py's JSON): summary table, plots of what
happened, rviz screenshot. scripts/demo and the fleet_office rostest use it; the report of a
formation run is report.py.

    report_demo.write_report(recording_json, world_yaml, out_dir, screenshot=None) -> path of index.html

Uses matplotlib's Agg backend (no display needed).
"""
import html
import json
import math
import os
import shutil

import numpy as np

from mbot_common.world import load_world
from mbot_bringup.report_plots import map_image


def load_map_for_plot(world_yaml):
    """(image, extent) of the world's map for matplotlib's imshow(origin="lower")."""
    return map_image(load_world(world_yaml).map_data)


def new_figure(width, height):
    """A matplotlib figure and axes drawn off-screen (no display needed)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt.subplots(figsize=(width, height))


def save_figure(fig, ax, path, title, xlabel, ylabel):
    """Label the axes, add the legend, write the PNG and free the figure."""
    import matplotlib.pyplot as plt
    ax.set_xlabel(xlabel)
    ax.set_ylabel(ylabel)
    ax.set_title(title)
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    fig.savefig(path, dpi=90)
    plt.close(fig)


def plot_trajectories(rec, world_yaml, path):
    fig, ax = new_figure(7, 7)
    image, extent = load_map_for_plot(world_yaml)
    ax.imshow(image, cmap="gray", extent=extent, origin="lower", vmin=0.0, vmax=1.0)
    for name in sorted(rec["robots"]):
        r = rec["robots"][name]
        if not r["x"]:
            continue
        line, = ax.plot(r["x"], r["y"], lw=1.5, label=name)
        ax.plot(r["x"][0], r["y"][0], "o", color=line.get_color())
        ax.annotate("", xy=(r["x"][-1] + 0.3 * math.cos(r["yaw"][-1]), r["y"][-1] + 0.3 * math.sin(r["yaw"][-1])),
                    xytext=(r["x"][-1], r["y"][-1]), arrowprops=dict(arrowstyle="->", color=line.get_color()))
    for g in rec.get("goals", []):
        ax.plot(g["x"], g["y"], "k*", ms=10)
    for c in rec["contacts"]:
        ax.plot(c["x"], c["y"], "rx", ms=9)
    save_figure(fig, ax, path, "Ground-truth trajectories (o start, arrow end, * goal, x contact)", "x [m]", "y [m]")


def plot_speeds(rec, path):
    fig, ax = new_figure(7, 3)
    for name in sorted(rec["robots"]):
        r = rec["robots"][name]
        t, x, y = np.array(r["t"]), np.array(r["x"]), np.array(r["y"])
        if len(t) < 2:
            continue
        speed = np.hypot(np.diff(x), np.diff(y)) / np.maximum(np.diff(t), 1e-9)
        ax.plot(t[1:] - t[0], speed, lw=1, label=name)
    save_figure(fig, ax, path, "Ground-truth speed", "sim time [s]", "speed [m/s]")


def summary_table(rec):
    rows = []
    for name in sorted(rec["robots"]):
        r = rec["robots"][name]
        rates = r.get("rates", {})
        rows.append("<tr><td>%s</td><td>%.1f</td><td>%.1f</td><td>%.1f</td><td>%.2f</td><td>%s</td></tr>" % (
            html.escape(name), rates.get("odom", 0.0), rates.get("scan", 0.0), rates.get("ground_truth", 0.0),
            r["distance"], "%.2f" % r["min_range"] if r["min_range"] is not None else "-"))
    return ("<table><tr><th>robot</th><th>odom [Hz]</th><th>scan [Hz]</th><th>ground truth [Hz]</th>"
            "<th>moved [m]</th><th>nearest laser return [m]</th></tr>%s</table>" % "".join(rows))


def nav_table(rec):
    rows = "".join("<tr><td>%s</td><td>%.1f</td><td>%s</td><td style='text-align:left'>%s</td></tr>" % (
        html.escape(r["robot"]), r["t"], r["status"], html.escape(r["text"])) for r in rec.get("nav_results", []))
    if not rows:
        return "<p>No move_base goal finished during the run.</p>"
    return ("<table><tr><th>robot</th><th>sim time [s]</th><th>result</th><th>status text</th></tr>%s</table>" % rows)


def write_report(recording_json, world_yaml, out_dir, screenshot=None):
    """Write out_dir/index.html (plus its images); return the path of index.html."""
    with open(recording_json) as f:
        rec = json.load(f)
    if not os.path.isdir(out_dir):
        os.makedirs(out_dir)
    plot_trajectories(rec, world_yaml, os.path.join(out_dir, "trajectories.png"))
    plot_speeds(rec, os.path.join(out_dir, "speeds.png"))
    shot = ""
    if screenshot and os.path.exists(screenshot):
        if os.path.abspath(os.path.dirname(screenshot)) != os.path.abspath(out_dir):
            shutil.copy(screenshot, os.path.join(out_dir, "rviz.png"))
            screenshot = os.path.join(out_dir, "rviz.png")
        shot = '<h2>rviz</h2><img src="%s" alt="rviz screenshot">' % os.path.basename(screenshot)
    contacts = "".join("<li>t = %.2f s: %s &harr; %s at (%.2f, %.2f)</li>" % (
        c["t"], html.escape(c["a"]), html.escape(c["b"]), c["x"], c["y"]) for c in rec["contacts"])
    speedup = rec["sim_seconds"] / rec["wall_seconds"] if rec.get("wall_seconds") else 0.0
    page = """<!DOCTYPE html>
<html><head><meta charset="utf-8"><title>mbot fleet demo report</title>
<style>body{font-family:sans-serif;max-width:60em;margin:2em auto}table{border-collapse:collapse}
td,th{border:1px solid #999;padding:0.2em 0.6em;text-align:right}img{max-width:100%%}</style></head>
<body><h1>mbot fleet demo</h1>
<p>World <code>%s</code>: %d robots, %.1f s of sim time in %.1f s of wall time (%.1fx real time).</p>
<h2>What each robot did</h2>%s
<h2>Navigation goals</h2>%s
<h2>Contacts (%d)</h2><ul>%s</ul>
<h2>Trajectories</h2><img src="trajectories.png" alt="trajectories">
<h2>Speeds</h2><img src="speeds.png" alt="speeds">
%s
</body></html>
""" % (html.escape(rec.get("world", "")), len(rec["robots"]), rec["sim_seconds"], rec.get("wall_seconds", 0.0),
       speedup, summary_table(rec), nav_table(rec), len(rec["contacts"]), contacts or "<li>none</li>", shot)
    index = os.path.join(out_dir, "index.html")
    with open(index, "w") as f:
        f.write(page)
    return index
