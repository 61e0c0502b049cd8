"""What a demo run saw, as plain data: trajectories, message counts, contacts, laser ranges.

`Recording` knows nothing of ROS; the recorder node feeds it messages' contents. It is saved as
JSON for scripts/report.
"""
import json
import math


class RobotTrack(object):
    """Ground-truth samples and sensor statistics of one robot."""

    def __init__(self):
        self.t = []        # sim time [s]
        self.x = []        # [m] in map
        self.y = []
        self.yaw = []      # [rad]
        self.counts = {}   # topic kind ("odom", "scan", "ground_truth") -> messages received
        self.first = {}    # topic kind -> sim time of the first message [s]
        self.last = {}     # topic kind -> sim time of the last message [s]
        self.min_range = math.inf  # nearest laser return seen [m]

    def count(self, kind, stamp):
        self.counts[kind] = self.counts.get(kind, 0) + 1
        self.first.setdefault(kind, stamp)
        self.last[kind] = stamp

    def rate(self, kind):
        """Messages per sim second between the first and last message, or 0."""
        n = self.counts.get(kind, 0)
        span = self.last.get(kind, 0.0) - self.first.get(kind, 0.0)
        return (n - 1) / span if n > 1 and span > 0 else 0.0

    def distance(self):
        """Path length of the ground-truth track [m]."""
        return sum(math.hypot(x1 - x0, y1 - y0)
                   for x0, y0, x1, y1 in zip(self.x, self.y, self.x[1:], self.y[1:]))


class Recording(object):
    """Everything the recorder collected during one run."""

    def __init__(self, world="", sample_period=0.1):
        self.world = world
        self.sample_period = sample_period  # ground-truth sampling [s sim time]
        self.robots = {}
        self.contacts = []                  # dicts: t, a, b, x, y
        self.goals = []                     # dicts: robot, t, x, y (goals sent to move_base)
        self.nav_results = []               # dicts: robot, t, status, text
        self.wall_seconds = 0.0

    def robot(self, name):
        return self.robots.setdefault(name, RobotTrack())

    def add_pose(self, name, stamp, x, y, yaw):
        track = self.robot(name)
        track.count("ground_truth", stamp)
        if not track.t or stamp - track.t[-1] >= self.sample_period - 1e-9:
            track.t.append(stamp)
            track.x.append(x)
            track.y.append(y)
            track.yaw.append(yaw)

    def add_scan(self, name, stamp, ranges):
        track = self.robot(name)
        track.count("scan", stamp)
        finite = [r for r in ranges if not (math.isinf(r) or math.isnan(r))]
        if finite:
            track.min_range = min(track.min_range, min(finite))

    def add_odom(self, name, stamp):
        self.robot(name).count("odom", stamp)

    def add_contact(self, stamp, a, b, x, y):
        self.contacts.append({"t": stamp, "a": a, "b": b, "x": x, "y": y})

    def add_goal(self, name, stamp, x, y):
        self.goals.append({"robot": name, "t": stamp, "x": x, "y": y})

    def add_nav_result(self, name, stamp, status, text):
        self.nav_results.append({"robot": name, "t": stamp, "status": status, "text": text})

    def sim_seconds(self):
        ends = [tr.t[-1] for tr in self.robots.values() if tr.t]
        starts = [tr.t[0] for tr in self.robots.values() if tr.t]
        return max(ends) - min(starts) if ends else 0.0

    def summary_lines(self):
        """Human-readable lines: one per robot, then the contacts."""
        lines = ["%-10s %8s %8s %8s %9s %9s %8s" % ("robot", "odom Hz", "scan Hz", "gt Hz",
                                                    "moved m", "nearest m", "final x,y")]
        for name in sorted(self.robots):
            tr = self.robots[name]
            final = "%.2f,%.2f" % (tr.x[-1], tr.y[-1]) if tr.x else "-"
            nearest = "%.2f" % tr.min_range if math.isfinite(tr.min_range) else "-"
            lines.append("%-10s %8.1f %8.1f %8.1f %9.2f %9s %8s" % (
                name, tr.rate("odom"), tr.rate("scan"), tr.rate("ground_truth"),
                tr.distance(), nearest, final))
        for r in self.nav_results:
            lines.append("  %s: goal %s at t=%.1f s %s" % (r["robot"], r["status"], r["t"], r["text"]))
        lines.append("contacts: %d" % len(self.contacts))
        for c in self.contacts[:10]:
            lines.append("  t=%.2f s  %s <-> %s at (%.2f, %.2f)" % (c["t"], c["a"], c["b"], c["x"], c["y"]))
        return lines

    def to_dict(self):
        return {
            "world": self.world,
            "sim_seconds": self.sim_seconds(),
            "wall_seconds": self.wall_seconds,
            "contacts": self.contacts,
            "goals": self.goals,
            "nav_results": self.nav_results,
            "robots": {
                name: {"t": tr.t, "x": tr.x, "y": tr.y, "yaw": tr.yaw,
                       "rates": {k: tr.rate(k) for k in tr.counts},
                       "counts": tr.counts,
                       "distance": tr.distance(),
                       "min_range": tr.min_range if math.isfinite(tr.min_range) else None}
                for name, tr in self.robots.items()},
        }

    def save(self, path):
        with open(path, "w") as f:
            json.dump(self.to_dict(), f, indent=1)
