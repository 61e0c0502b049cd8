"""The plots of a formation run report (matplotlib, Agg: no display needed): trajectories on the
map with formation snapshots, formation error over time with states and events, latency
histogram, speed profiles, the animation (GIF), and the error plot of two runs.

Each robot has one colour in every plot: the colour the simulator gives its marker in rviz
(/stage/markers: hue = world index / 6), a little darker so that lines read on white.
"""
import math

import numpy as np

from mbot_bringup.report_data import Series, arrival_time, assignment_at, assignments, event_marks, pause_spans, \
    fleet_path_length, leader_trail, slot_positions, speeds, state_spans


class PlotStyle(object):
    """Sizes and colours shared by the plots."""

    def __init__(self):
        self.dpi = 90                     # PNG resolution [dots per inch]
        self.margin = 1.0                 # map shown around everything that moved [m]
        self.snapshots = 10               # formation snapshots on the trajectory plot (+ one per switch)
        self.snapshot_dt = 1.0            # snapshots at least this far apart in time [s]
        self.label_near = 0.6             # snapshots whose leaders stood this close share a time label [m]
        self.error_view = 4.0             # error axes go up to this many times the threshold ...
        self.error_median = 1.5           # ... or this many times the median error while moving
        self.speed_window = 1.0           # speeds are averaged over this long [s]
        self.map_width = 7.0              # width of the map in the trajectory plot [in]
        self.gif_fps = 10                 # animation frames per second of playback [1/s]
        self.gif_max_frames = 240         # at most this many frames (the run is sped up to fit) [1]
        self.gif_width = 640              # animation width [pixels]
        self.trail = 6.0                  # the animation draws each robot's last this many seconds [s]
        self.news = 4.0                   # ... and names each event this long after it [s]
        self.state_colors = {"IDLE": "#e6e6e6", "FORMING": "#fff2b3", "NAVIGATING": "#dcebfa",
                             "DEGRADED": "#ffd9b3", "ARRIVED": "#d9f2d9", "ABORTED": "#f7c6c6"}
        self.mark_colors = {"switch": "#7b2fbe", "loss": "#d62728", "rejoin": "#2ca02c", "pause": "#ff7f0e",
                            "contact": "#000000"}


STYLE = PlotStyle()


def pyplot():
    """matplotlib.pyplot drawing off-screen (Agg)."""
    import matplotlib
    matplotlib.use("Agg")
    import matplotlib.pyplot as plt
    return plt


def map_image(map_data):
    """(grey image, extent) of an occupancy map for imshow(origin="lower"): free white,
    occupied dark, unknown light grey."""
    occ = map_data.occupancy
    image = np.where(occ == 0, 1.0, np.where(occ < 0, 0.85, 0.2))
    ox, oy, _ = map_data.origin
    res = map_data.resolution
    return image, (ox, ox + map_data.width * res, oy, oy + map_data.height * res)


def draw_map(ax, world, box):
    """The map and the world's static and moving obstacles, limited to box (x0, x1, y0, y1)."""
    from matplotlib.patches import Circle, Rectangle
    from matplotlib.transforms import Affine2D
    image, extent = map_image(world.map_data)
    ax.imshow(image, cmap="gray", vmin=0.0, vmax=1.0, extent=extent, origin="lower", interpolation="nearest")
    for o in world.obstacles:
        if o.shape.type == "cylinder":
            ax.add_patch(Circle((o.pose.x, o.pose.y), o.shape.radius, color="#8c6d4f"))
        else:
            box_patch = Rectangle((-o.shape.length / 2, -o.shape.width / 2), o.shape.length, o.shape.width,
                                  color="#8c6d4f")
            box_patch.set_transform(Affine2D().rotate(o.pose.theta).translate(o.pose.x, o.pose.y) + ax.transData)
            ax.add_patch(box_patch)
    for m in world.moving_obstacles:
        xs, ys = zip(*(m.waypoints + ([m.waypoints[0]] if m.mode == "loop" else [])))
        ax.plot(xs, ys, ":", color="#d98c1a", lw=1.5)
    ax.set_xlim(box[0], box[1])
    ax.set_ylim(box[2], box[3])
    ax.set_aspect("equal")


def view_box(series, margin):
    """(x0, x1, y0, y1) around every pose of the run, margin [m] added."""
    xs = np.concatenate([series.x[r] for r in series.robots]) if series.robots else np.array([])
    ys = np.concatenate([series.y[r] for r in series.robots]) if series.robots else np.array([])
    xs, ys = xs[np.isfinite(xs)], ys[np.isfinite(ys)]
    if len(xs) == 0:
        return (-5.0, 5.0, -5.0, 5.0)
    return (xs.min() - margin, xs.max() + margin, ys.min() - margin, ys.max() + margin)


def figure(width, height):
    return pyplot().subplots(figsize=(width, height))


def map_figure(box, map_width, right=0.0):
    """A figure whose axes show box (x0, x1, y0, y1) at equal scale map_width [in] wide, with
    right [in] more for a legend."""
    height = map_width * (box[3] - box[2]) / max(box[1] - box[0], 1e-9)
    fig, ax = figure(map_width + right + 0.9, min(max(height, 2.0), 1.5 * map_width) + 0.9)
    fig.subplots_adjust(left=0.7 / fig.get_figwidth(), right=1.0 - (right + 0.2) / fig.get_figwidth(),
                        bottom=0.55 / fig.get_figheight(), top=1.0 - 0.35 / fig.get_figheight())
    return fig, ax


def save(fig, path, dpi=None):
    fig.savefig(path, dpi=dpi or STYLE.dpi)
    pyplot().close(fig)
    return path


def _index_at(series, t):
    """Index of the last sample at or before t [s from the target] (0 if none)."""
    return max(0, int(np.searchsorted(series.t, t + 1e-9)) - 1)


def _draw_robot(ax, pose, radius, color, filled, zorder=5):
    from matplotlib.patches import Circle
    x, y, theta = pose
    ax.add_patch(Circle((x, y), radius, facecolor=color if filled else "white", edgecolor=color, lw=1.5,
                        zorder=zorder))
    ax.plot([x, x + 2.0 * radius * math.cos(theta)], [y, y + 2.0 * radius * math.sin(theta)], "-",
            color=color if not filled else "black", lw=1.5, zorder=zorder + 0.1)


def snapshot_indices(series, run):
    """Sample indices of the formation snapshots: the target, each switch, the last arrival (or
    the end), and between them evenly along the distance the fleet drove (so that they fall where
    robots move, not while they wait), none closer to another than half that spacing or than
    snapshot_dt in time (two labels of the same second say nothing)."""
    n = len(series.t)
    path = fleet_path_length(series)
    first = min(int(np.searchsorted(series.t, 0.0)), n - 1)
    arrived = arrival_time(run, last=True)
    last = n - 1 if arrived is None else min(n - 1, int(np.searchsorted(series.t, arrived - series.t0)))
    first = min(first, last)
    apart = 0.5 * (path[last] - path[first]) / max(1, STYLE.snapshots - 1)
    fixed = [first, last] + [min(n - 1, int(np.searchsorted(series.t, m.t - series.t0)))
                             for m in event_marks(run) if m.kind == "switch"]
    chosen = sorted(set(fixed))
    for d in np.linspace(path[first], path[last], STYLE.snapshots):
        i = min(last, int(np.searchsorted(path, d)))
        if i not in chosen and all(abs(path[i] - path[j]) >= apart
                                   and abs(series.t[i] - series.t[j]) >= STYLE.snapshot_dt for j in chosen):
            chosen.append(i)
    return sorted(chosen)


def snapshot_labels(positions, times, near):
    """One time label per place: [((x, y), "14, 16, 22 s")] for the snapshots whose leader stood
    within `near` [m] of the first one there (the fleet waiting while it forms or switches)."""
    groups = []   # [(x, y), [t, ...]]
    for (x, y), t in zip(positions, times):
        for place, ts in groups:
            if math.hypot(x - place[0], y - place[1]) < near:
                ts.append(t)
                break
        else:
            groups.append(((x, y), [t]))
    return [(place, ", ".join("%.0f" % t for t in sorted(set(round(t) + 0.0 for t in ts))) + " s")
            for place, ts in groups]


def plot_trajectories(run, world, colors, path, radius):
    """Every robot's ground-truth path on the map, with formation snapshots (robot outlines, a
    line from the leader to each follower, the time), start (o) and end (square), switches (star),
    losses (x), contacts (red X)."""
    series = Series(run)
    box = view_box(series, STYLE.margin)
    fig, ax = map_figure(box, STYLE.map_width, right=2.6)
    draw_map(ax, world, box)
    for r in series.robots:
        ax.plot(series.x[r], series.y[r], "-", color=colors[r], lw=1.5, alpha=0.8, label=r, zorder=3)
        finite = np.flatnonzero(np.isfinite(series.x[r]))
        if len(finite):
            first, last = finite[0], finite[-1]
            ax.plot(series.x[r][first], series.y[r][first], "o", ms=11, mfc="none", mec=colors[r], mew=2, zorder=6)
            ax.plot(series.x[r][last], series.y[r][last], "s", ms=9, color=colors[r], mec="black", zorder=6)
    labelled, label_times = [], []   # leader position and time of each snapshot
    for i in snapshot_indices(series, run):
        leader = series.pose(series.leader[i], i)
        for r in series.robots:
            pose = series.pose(r, i)
            if pose is None:
                continue
            lost = r in series.lost[i]   # not in the formation: no link, a grey outline
            if leader is not None and r != series.leader[i] and not lost:
                ax.plot([leader[0], pose[0]], [leader[1], pose[1]], "-", color="#555555", lw=0.8, zorder=4)
            _draw_robot(ax, pose, radius, "#999999" if lost else colors[r], filled=False)
        if leader is not None:
            labelled.append(leader[:2])
            label_times.append(series.t[i])
    for (x, y), text in snapshot_labels(labelled, label_times, STYLE.label_near):
        ax.annotate(text, (x, y), xytext=(0, 9), textcoords="offset points", ha="center", fontsize=8, zorder=7,
                    bbox=dict(boxstyle="round,pad=0.15", fc="white", ec="none", alpha=0.8))
    for m in event_marks(run):
        i = _index_at(series, m.t - series.t0)
        if m.kind == "switch":
            leader = series.pose(series.leader[i], i)
            if leader is not None:
                ax.plot(leader[0], leader[1], "*", ms=18, color=STYLE.mark_colors["switch"], mec="white", zorder=8)
                ax.annotate(m.label, (leader[0], leader[1]), xytext=(0, -18), textcoords="offset points",
                            ha="center", fontsize=9, color=STYLE.mark_colors["switch"], zorder=8,
                            bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.85))
        elif m.kind == "loss":
            pose = series.pose(m.name, i)
            if pose is not None:
                ax.plot(pose[0], pose[1], "x", ms=14, mew=3, color=STYLE.mark_colors["loss"], zorder=8)
    for e in run.events:
        if e.kind == "contact" and math.isfinite(e.x) and math.isfinite(e.y):
            ax.plot(e.x, e.y, "X", ms=14, color="red", mec="black", zorder=9)
    from matplotlib.lines import Line2D
    handles, labels = ax.get_legend_handles_labels()
    labels = ["%s (leads)" % r if r == series.leader[0] else r for r in labels]
    handles += [Line2D([], [], ls="none", marker="o", mfc="none", mec="black", ms=9),
                Line2D([], [], ls="none", marker="s", color="grey", mec="black", ms=8),
                Line2D([], [], ls="none", marker="o", mfc="white", mec="black", ms=8)]
    labels += ["start", "end", "snapshot (time from target)"]
    kinds = set(m.kind for m in event_marks(run))
    for kind, handle, label in [
            ("switch", Line2D([], [], ls="none", marker="*", color=STYLE.mark_colors["switch"], ms=13),
             "formation switch"),
            ("loss", Line2D([], [], ls="none", marker="x", color=STYLE.mark_colors["loss"], mew=2, ms=9),
             "robot lost"),
            ("contact", Line2D([], [], ls="none", marker="X", color="red", mec="black", ms=9), "contact")]:
        if kind in kinds:   # only what happened in this run
            handles.append(handle)
            labels.append(label)
    ax.legend(handles, labels, loc="upper left", bbox_to_anchor=(1.02, 1.0), fontsize=9, framealpha=0.9)
    ax.set_xlabel("x [m]")
    ax.set_ylabel("y [m]")
    ax.set_title("Ground-truth paths; formation snapshots with their time from the target")
    return save(fig, path)


def shade_states(ax, run, series, label=True):
    """Colour the background by coordinator state; write the names of the longer ones at the top."""
    import matplotlib.transforms as mtransforms
    trans = mtransforms.blended_transform_factory(ax.transData, ax.transAxes)
    t0, end = series.t0, series.t[-1]
    span = max(end - series.t[0], 1e-9)
    for state, a, b in state_spans(run, end + t0):
        a, b = a - t0, min(b - t0, end)
        ax.axvspan(a, b, color=STYLE.state_colors.get(state, "#f0f0f0"), zorder=0, lw=0)
        if label and (b - a) > 0.06 * span:
            ax.text((a + b) / 2.0, 0.98, state, transform=trans, ha="center", va="top", fontsize=8, color="#444444")


def mark_events(ax, run, t0, label=True):
    """A vertical line per event (switch, loss, rejoin, pause, contact ...), labelled; each leader
    pause shaded from its start to its end."""
    import matplotlib.transforms as mtransforms
    trans = mtransforms.blended_transform_factory(ax.transData, ax.transAxes)
    for p in pause_spans(run, run.samples[-1].t if run.samples else t0):
        ax.axvspan(p.start - t0, p.end - t0, color=STYLE.mark_colors["pause"], alpha=0.25, lw=0, zorder=1)
    shown = []
    for m in event_marks(run):
        t = m.t - t0
        color = STYLE.mark_colors.get(m.kind, "#555555")
        ax.axvline(t, color=color, lw=1.5, ls="--", zorder=4)
        if label:
            # Events at the same moment stack their labels instead of writing over each other.
            level = sum(1 for s in shown if abs(s - t) < 0.02 * max(1.0, ax.get_xlim()[1] - ax.get_xlim()[0]))
            shown.append(t)
            text, ha = _label_beside(ax, t, m.label)
            ax.text(t, 0.88 - 0.12 * level, text, transform=trans, color=color, fontsize=8, va="top", ha=ha,
                    zorder=6, bbox=dict(boxstyle="square,pad=0.1", fc="white", ec="none", alpha=0.75))


def _label_beside(ax, t, text):
    """(text, ha) for a label at x = t: right of the line, or left of it in the last quarter of
    the axis, so that it does not run out of the plot into the legend."""
    lo, hi = ax.get_xlim()
    if t > lo + 0.75 * (hi - lo):
        return text + " ", "right"
    return " " + text, "left"


def error_limit(values, threshold):
    """Upper y limit of an error axis: error_view x the threshold, or error_median x the median
    of values if that is more, so that both the limit and the typical error are readable; a
    transient (forming, a switch) may go off the top."""
    finite = values[np.isfinite(values)]
    median = float(np.median(finite)) if len(finite) else 0.0
    top = max(STYLE.error_view * (threshold or 0.0), STYLE.error_median * median)
    if top <= 0.0:
        top = float(finite.max()) * 1.1 if len(finite) and finite.max() > 0 else 1.0
    return top


def _cut_note(values, top, unit="m"):
    """' (cut at X; up to Y)' when values go above top."""
    finite = values[np.isfinite(values)]
    if len(finite) and finite.max() > top:
        return " (axis cut at %.2f %s; up to %.2f %s)" % (top, unit, finite.max(), unit)
    return ""


def plot_errors(run, colors, path, formation_limit, lateral_limit):
    """Formation error (slot RMS of the fleet, each follower's slot error, the shape error after a
    rigid fit) and the leader's lateral error over time, with the state bands and the events."""
    series = Series(run)
    plt = pyplot()
    fig, (ax, ax2) = plt.subplots(2, 1, figsize=(12.5, 7.0), sharex=True, gridspec_kw={"height_ratios": [2, 1]})
    fig.subplots_adjust(left=0.07, right=0.74, top=0.94, bottom=0.08, hspace=0.12)
    end = series.t[-1]
    ax.set_xlim(series.t[0], end)
    for a in (ax, ax2):
        shade_states(a, run, series, label=a is ax)
    for r in series.followers():
        ax.plot(series.t, series.slot_error[r], "-", color=colors[r], lw=1.0, alpha=0.9, label="%s slot error" % r)
    ax.plot(series.t, series.slot_rms, "-", color="black", lw=2.0, label="fleet slot RMS")
    ax.plot(series.t, series.fit_rms, "--", color="#666666", lw=1.2, label="shape error after\nbest rigid fit (RMS)")
    if formation_limit is not None:
        ax.axhline(formation_limit, color="#d62728", ls=":", lw=2,
                   label="limit %.2f m (RMS while\nNAVIGATING and moving)" % formation_limit)
    moving = np.array([s in ("NAVIGATING", "DEGRADED", "ARRIVED") for s in series.state])
    top = error_limit(series.slot_rms[moving] if moving.any() else series.slot_rms, formation_limit)
    # A bar along the bottom, one row per follower, where its slot lay in a wall (it drove the
    # free path instead): the error there is not the controller's.
    for k, r in enumerate(series.followers()):
        blocked = series.slot_blocked[r]
        if blocked.any():
            y = top * (0.015 + 0.03 * k)
            ax.plot(series.t, np.where(blocked, y, np.nan), "-", color=colors[r], lw=5, solid_capstyle="butt",
                    label="%s: slot in a wall" % r)
    ax.set_ylim(0.0, top)
    ax.set_ylabel("slot error [m]")
    ax.set_title("Formation error over time" + _cut_note(
        np.concatenate([series.slot_rms] + [series.slot_error[r] for r in series.followers()]), top))
    mark_events(ax, run, series.t0)
    mark_events(ax2, run, series.t0, label=False)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9, framealpha=0.9)
    ax2.plot(series.t, series.leader_lateral, "-", color="black", lw=1.5, label="leader: distance\nfrom its plan")
    if lateral_limit is not None:
        ax2.axhline(lateral_limit, color="#d62728", ls=":", lw=2, label="limit %.2f m (RMS)" % lateral_limit)
    top2 = error_limit(series.leader_lateral, lateral_limit)
    ax2.set_ylim(0.0, top2)
    ax2.set_ylabel("lateral error [m]")
    ax2.set_xlabel("time from the target [s] (sim time)")
    ax2.set_title("Leader's distance from its global plan" + _cut_note(series.leader_lateral, top2), fontsize=10)
    ax2.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9, framealpha=0.9)
    return save(fig, path)


def plot_latency(run, colors, path, limit):
    """Histogram of the control latency [ms] per follower, with the 95th percentile and the limit."""
    fig, ax = figure(8.0, 4.0)
    robots = [r for r in run.robots if any(c.robot == r and math.isfinite(c.latency) for c in run.controller)]
    values = [np.array([1000.0 * c.latency for c in run.controller if c.robot == r and math.isfinite(c.latency)])
              for r in robots]
    pooled = np.concatenate(values) if values else np.array([])
    if len(pooled):
        top = max(float(pooled.max()), 1000.0 * (limit or 0.0)) + 10.0
        bins = np.arange(0.0, top + 5.0, 5.0)   # the physics step is 10 ms: 5 ms bins show its steps
        ax.hist(values, bins=bins, stacked=True, color=[colors[r] for r in robots], label=robots)
        p95 = float(np.percentile(pooled, 95))
        ax.axvline(p95, color="black", ls="--", lw=1.5, label="95th percentile %.0f ms" % p95)
    else:
        ax.text(0.5, 0.5, "no controller cycle used a pose", transform=ax.transAxes, ha="center")
    if limit is not None:
        ax.axvline(1000.0 * limit, color="#d62728", ls=":", lw=2,
                   label="limit %.0f ms (95th percentile)" % (1000.0 * limit))
    methods = [e.name for e in run.events if e.kind == "latency_method"]
    labels = {"simulator": "the pose's age when the simulator applied the command [ms] (sim time)",
              "pose_age": "the pose's age when the command was computed (no simulator report: without "
                          "transport and actuation) [ms]",
              "": "the pose's age when the command was computed + one physics step (recorded before the "
                  "simulator's report) [ms]"}
    ax.set_xlabel("control latency: " + labels.get(methods[-1] if methods else "", labels[""]))
    ax.set_ylabel("controller cycles [count]")
    dropped = sum(1 for c in run.controller if c.applied == 0.0)
    ax.set_title("Control latency of the followers (%d cycles%s)"
                 % (len(pooled), ", %d commands not applied" % dropped if dropped else ""))
    ax.legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return save(fig, path)


def plot_speeds(run, colors, path):
    """Ground-truth speed of every robot over time, with the state bands and the events."""
    series = Series(run)
    fig, ax = figure(12.5, 4.0)
    fig.subplots_adjust(left=0.07, right=0.74, top=0.9, bottom=0.14)
    end = series.t[-1]
    ax.set_xlim(series.t[0], end)
    shade_states(ax, run, series)
    for r in series.robots:
        ax.plot(series.t, speeds(series.t, series.x[r], series.y[r], STYLE.speed_window, run.config.stale_after),
                "-", color=colors[r], lw=1.5, label=r)
    mark_events(ax, run, series.t0)
    ax.set_ylim(bottom=0.0)
    ax.set_xlabel("time from the target [s] (sim time)")
    ax.set_ylabel("speed [m/s]")
    ax.set_title("Speed of each robot (ground truth, averaged over %.0f s)" % STYLE.speed_window)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9, framealpha=0.9)
    return save(fig, path)


def animation_frames(series, max_frames):
    """Sample indices of the animation's frames: evenly over the run, at most max_frames."""
    n = len(series.t)
    if n == 0:
        return []
    step = max(1, int(math.ceil(n / float(max_frames))))
    frames = list(range(0, n, step))
    if frames[-1] != n - 1:
        frames.append(n - 1)
    return frames


def gif_writer(fps):
    """matplotlib's PillowWriter when Pillow is there, else its ImageMagick writer (convert)."""
    from matplotlib import animation
    try:
        import PIL  # noqa: F401  (only to know whether Pillow is there)
        return animation.PillowWriter(fps=fps)
    except ImportError:
        return animation.ImageMagickWriter(fps=fps)


def frame_scans(series, scans, i):
    """{robot: points (n x 2) in the map frame} of each robot's newest scan at frame i (report_scans),
    placed with the robot's pose of the scan's time."""
    from mbot_bringup.report_scans import in_map, scan_at
    out = {}
    for r in series.robots:
        found = scan_at(scans or {}, r, series.t[i] + series.t0)
        # the pose of the scan's time; the frame's when that sample missed the robot
        pose = found and (series.pose(r, _index_at(series, found[0] - series.t0)) or series.pose(r, i))
        if found is not None and pose is not None:
            out[r] = in_map(found[1], pose)
    return out


class AnimationFrame(object):
    """The animation's figure: the map, each robot's laser hits as dots (scans:
    report_scans.read_scans, None: none), robots as discs with a heading tick, their slots as
    dashed rings (a dotted line from each robot to its slot: its slot error), a line from the
    leader to each follower, each robot's recent path, the state, the formation and the time as
    the caption, and each event for a few seconds after it. draw(i) shows sample i."""

    def __init__(self, run, world, colors, radius, scans=None):
        from matplotlib.patches import Circle
        self.run, self.colors, self.radius, self.scans = run, colors, radius, scans
        self.series = series = Series(run)
        self.assigned = assignments(run)
        box = view_box(series, STYLE.margin)
        self.fig, self.ax = fig, ax = map_figure(box, 6.0)
        draw_map(ax, world, box)
        ax.set_xlabel("x [m]")
        ax.set_ylabel("y [m]")
        self.artists = {}
        for r in series.robots:
            trail, = ax.plot([], [], "-", color=colors[r], lw=1.2, alpha=0.6, zorder=3)
            slot = Circle((0, 0), radius * 2.0, facecolor="none", edgecolor=colors[r], lw=1.5, ls="--", zorder=4)
            error, = ax.plot([], [], ":", color=colors[r], lw=1.2, zorder=4)
            link, = ax.plot([], [], "-", color="#555555", lw=1.0, zorder=4)
            disc = Circle((0, 0), radius, facecolor=colors[r], edgecolor="black", lw=0.8, zorder=6)
            tick, = ax.plot([], [], "-", color="black", lw=1.5, zorder=7)
            name = ax.text(0, 0, r, fontsize=8, ha="center", va="bottom", zorder=8, color=colors[r])
            hits, = ax.plot([], [], ".", color=colors[r], ms=2.0, alpha=0.7, zorder=2)
            ax.add_patch(slot)
            ax.add_patch(disc)
            self.artists[r] = (trail, slot, error, link, disc, tick, name, hits)
        self.caption = ax.set_title("", fontsize=10, family="monospace")
        self.news = ax.text(0.01, 0.02, "", transform=ax.transAxes, fontsize=10, color=STYLE.mark_colors["switch"],
                            zorder=9, bbox=dict(boxstyle="round,pad=0.2", fc="white", ec="none", alpha=0.85))
        self.marks = event_marks(run)
        self.speedup = 1.0   # playback speed over sim time, for the caption

    def draw(self, i):
        """Put sample i of the run into the figure's artists."""
        series, colors, radius = self.series, self.colors, self.radius
        t = series.t[i]
        leader_name = series.leader[i]
        leader = series.pose(leader_name, i)
        a = assignment_at(self.assigned, t + series.t0)
        slots = slot_positions(a, leader, leader_trail(series, a, i) if a is not None and a.along_path else None)
        recent = (series.t >= t - STYLE.trail) & (series.t <= t)
        seen = frame_scans(series, self.scans, i)
        for r, (trail, slot, error, link, disc, tick, name, hits) in self.artists.items():
            hits.set_data(seen[r][:, 0] if r in seen else [], seen[r][:, 1] if r in seen else [])
            pose = series.pose(r, i)
            lost = r in series.lost[i]
            visible = pose is not None
            for artist in (disc, tick, name, trail):
                artist.set_visible(visible)
            if visible:
                x, y, theta = pose
                disc.center = (x, y)
                disc.set_facecolor("white" if lost else colors[r])
                tick.set_data([x, x + 2.2 * radius * math.cos(theta)], [y, y + 2.2 * radius * math.sin(theta)])
                name.set_position((x, y + 1.6 * radius))
                name.set_text(r + (" LOST" if lost else " (leads)" if r == leader_name else ""))
                trail.set_data(series.x[r][recent], series.y[r][recent])
            slot.set_visible(r in slots)
            error.set_visible(visible and r in slots)
            if r in slots:
                slot.center = slots[r]
                if visible:
                    error.set_data([pose[0], slots[r][0]], [pose[1], slots[r][1]])
            link.set_visible(visible and leader is not None and r != leader_name and not lost)
            if link.get_visible():
                link.set_data([leader[0], pose[0]], [leader[1], pose[1]])
        rms = series.slot_rms[i]
        self.caption.set_text("t = %5.1f s  %-10s %-9s slot RMS %s  (%.1fx speed)" % (
            t, series.state[i], a.formation if a else "", "%.2f m" % rms if math.isfinite(rms) else "  -   ",
            self.speedup))
        recent_marks = [m for m in self.marks if 0.0 <= t + series.t0 - m.t <= STYLE.news]
        self.news.set_visible(bool(recent_marks))
        if recent_marks:
            self.news.set_text(", ".join(m.label for m in recent_marks))
            self.news.set_color(STYLE.mark_colors.get(recent_marks[-1].kind, "#555555"))


def write_animation(run, world, colors, path, radius, scans=None):
    """A GIF of the run (AnimationFrame), sped up to at most gif_max_frames frames. Returns the
    number of frames."""
    plt = pyplot()
    frame = AnimationFrame(run, world, colors, radius, scans)
    series = frame.series
    frames = animation_frames(series, STYLE.gif_max_frames)
    dt = (series.t[-1] - series.t[0]) / max(1, len(frames) - 1)
    frame.speedup = dt * STYLE.gif_fps
    writer = gif_writer(STYLE.gif_fps)
    with writer.saving(frame.fig, path, STYLE.gif_width / frame.fig.get_figwidth()):
        for i in frames:
            frame.draw(i)
            writer.grab_frame()
    plt.close(frame.fig)
    return len(frames)


def plot_compare_errors(runs, labels, path, formation_limit):
    """The fleet slot RMS of several runs on one time axis (from each run's target), each run's
    events and arrival marked in its colour."""
    fig, ax = figure(12.5, 4.8)
    fig.subplots_adjust(left=0.07, right=0.78, top=0.9, bottom=0.12)
    run_colors = ["#1f77b4", "#d62728", "#2ca02c", "#9467bd"]
    top, start, end = 0.0, 0.0, 0.0
    lines = []   # (t, text, color, style) of every vertical line
    for k, (run, label) in enumerate(zip(runs, labels)):
        series = Series(run)
        color = run_colors[k % len(run_colors)]
        start, end = min(start, series.t[0]), max(end, series.t[-1])
        ax.plot(series.t, series.slot_rms, "-", color=color, lw=1.6, label="%s: fleet slot RMS" % label)
        lines += [(m.t - series.t0, "%s: %s" % (label, m.label), color, "--") for m in event_marks(run)]
        arrived = arrival_time(run)
        if arrived is not None:
            lines.append((arrived - series.t0, "%s: ARRIVED" % label, color, "-."))
        moving = np.array([s in ("NAVIGATING", "DEGRADED", "ARRIVED") for s in series.state])
        top = max(top, error_limit(series.slot_rms[moving] if moving.any() else series.slot_rms, formation_limit))
    ax.set_xlim(start, end)
    shown = []
    for t, text, color, style in sorted(lines):
        ax.axvline(t, color=color, ls=style, lw=1.2)
        level = sum(1 for s in shown if abs(s - t) < 0.08 * max(1.0, end - start))
        shown.append(t)
        text, ha = _label_beside(ax, t, text)
        ax.text(t, 0.97 - 0.08 * level, text, color=color, fontsize=8, va="top", ha=ha,
                transform=ax.get_xaxis_transform(), bbox=dict(boxstyle="square,pad=0.1", fc="white", ec="none",
                                                              alpha=0.75))
    if formation_limit is not None:
        ax.axhline(formation_limit, color="black", ls=":", lw=1.5, label="limit %.2f m" % formation_limit)
    ax.set_ylim(0.0, top)
    ax.set_xlabel("time from the target [s] (sim time)")
    ax.set_ylabel("slot RMS [m]")
    ax.set_title("Formation error of both runs (axis cut at %.2f m)" % top)
    ax.legend(loc="upper left", bbox_to_anchor=(1.01, 1.0), fontsize=9)
    return save(fig, path)
