"""A Run on disk: RunWriter writes metrics.csv, events.csv, controller.csv and metrics.json;
load_run reads them back into the same Run."""
import csv
import io
import json
import math
import os

from mbot_follower.metrics.records import NAN, ControllerSample, Event, MetricsConfig, RobotSample, Run, Sample


SAMPLE_COLUMNS = ["t_s", "state", "leader", "formation", "lost", "slot_rms_m", "slot_max_m", "fit_rms_m",
                  "fit_max_m", "edge_max_m", "heading_max_rad", "leader_lateral_m", "min_clearance_m",
                  "clearance_pair"]
ROBOT_COLUMNS = ["x_m", "y_m", "theta_rad", "slot_error_m", "fit_error_m", "distance_m", "energy_j", "slot_free"]
#: what runs recorded before slot_free have
OLD_ROBOT_COLUMNS = ROBOT_COLUMNS[:-1]
EVENT_COLUMNS = ["t_s", "kind", "name", "detail", "x_m", "y_m"]
CONTROLLER_COLUMNS = ["t_s", "robot", "latency_s", "cycle_time_ms", "lookups", "lookup_failures", "mode",
                      "overruns", "late_starts", "applied"]
FILES = ("metrics.csv", "events.csv", "controller.csv", "metrics.json")


def _cell(value):
    """A CSV cell: floats exactly (repr), NaN as an empty cell."""
    if isinstance(value, float):
        return repr(value) if math.isfinite(value) else ""
    return str(value)


def sample_columns(robots):
    """metrics.csv's header: the fleet columns, then ROBOT_COLUMNS of each robot as "<robot>/<column>"."""
    return SAMPLE_COLUMNS + ["%s/%s" % (r, c) for r in robots for c in ROBOT_COLUMNS]


def _sample_row(sample, robots):
    row = [sample.t, sample.state, sample.leader, sample.formation, " ".join(sample.lost), sample.slot_rms,
           sample.slot_max, sample.fit_rms, sample.fit_max, sample.edge_max, sample.heading_max,
           sample.leader_lateral, sample.min_clearance, sample.clearance_pair]
    for r in robots:
        row += list(sample.robots[r]) if r in sample.robots else [NAN] * len(ROBOT_COLUMNS)
    return [_cell(v) for v in row]


class RunWriter(object):
    """Writes a Run into output_dir: the CSV files grow by the rows that are new since the last
    write (metrics.csv is written again whole when a robot appears: it adds columns);
    metrics.json is replaced atomically, so a killed run always leaves a complete one."""

    def __init__(self, output_dir):
        self.output_dir = output_dir
        try:
            os.makedirs(output_dir, exist_ok=True)
        except OSError as error:
            raise OSError("metrics output_dir %s: cannot create it: %s" % (output_dir, error.strerror))
        if not os.access(output_dir, os.W_OK):
            raise OSError("metrics output_dir %s: not writable" % output_dir)
        self.written = {}        # file -> rows written
        self.columns = None      # metrics.csv's current header

    def path(self, name):
        return os.path.join(self.output_dir, name)

    def _append(self, name, header, items, convert):
        """Write the items that are new since the last write (all of them, with the header, the first time)."""
        done = self.written.get(name)
        # A new file is written whole and renamed, so a reader never sees it truncated.
        path = self.path(name) if done is not None else self.path(name + ".tmp")
        with open(path, "a" if done is not None else "w", newline="") as f:
            out = csv.writer(f)
            if done is None:
                out.writerow(header)
            out.writerows(convert(item) for item in items[done or 0:])
        if done is None:
            os.replace(path, self.path(name))
        self.written[name] = len(items)

    def write(self, run, summary):
        """The run's new rows; metrics.json too unless `summary` is None."""
        columns = sample_columns(run.robots)
        if columns != self.columns:
            self.written.pop("metrics.csv", None)   # new columns: write it again from the start
            self.columns = columns
        self._append("metrics.csv", columns, run.samples, lambda s: _sample_row(s, run.robots))
        self._append("events.csv", EVENT_COLUMNS, run.events, lambda e: [_cell(v) for v in e])
        self._append("controller.csv", CONTROLLER_COLUMNS, run.controller, lambda c: [_cell(v) for v in c])
        if summary is None:
            return
        tmp = self.path("metrics.json.tmp")
        with open(tmp, "w") as f:
            json.dump(summary, f, indent=1)
            f.write("\n")
        os.replace(tmp, self.path("metrics.json"))


class RunFileError(ValueError):
    """A run file that cannot be read back; the message names the file, the line and the problem."""


def _read_csv(path, expected=None):
    """(header, rows) of a CSV file; RunFileError if missing or if its header is not `expected`."""
    if not os.path.isfile(path):
        raise RunFileError("%s: missing (a metrics run folder holds %s)" % (path, ", ".join(FILES)))
    with open(path, newline="") as f:
        text = f.read()
    if text and not text.endswith("\n"):
        # The collector appends while others read: a last line without its newline is a row
        # still being written, not a broken file.
        text = text[:text.rfind("\n") + 1]
    rows = list(csv.reader(io.StringIO(text, newline="")))
    if not rows:
        raise RunFileError("%s: empty, expected a header line" % path)
    header = rows[0]
    if expected is not None and header != expected:
        raise RunFileError("%s: line 1: expected the columns %s, got %s" % (path, ",".join(expected), ",".join(header)))
    for number, row in enumerate(rows[1:], start=2):
        if len(row) != len(header):
            raise RunFileError("%s: line %d: %d cells, expected %d" % (path, number, len(row), len(header)))
    return header, rows[1:]


def _float(path, number, column, text):
    if text == "":
        return NAN
    try:
        return float(text)
    except ValueError:
        raise RunFileError("%s: line %d: %s: expected a number, got %r" % (path, number, column, text))


def _int(path, number, column, text):
    try:
        return int(text)
    except ValueError:
        raise RunFileError("%s: line %d: %s: expected an integer, got %r" % (path, number, column, text))


def load_run(output_dir):
    """The Run that a RunWriter wrote into output_dir (metrics.csv, events.csv, controller.csv;
    the config from metrics.json when it is there, else the default one)."""
    config = MetricsConfig()
    json_path = os.path.join(output_dir, "metrics.json")
    if os.path.isfile(json_path):
        try:
            with open(json_path) as f:
                config = MetricsConfig.from_dict(json.load(f).get("config", {}), json_path + ": config")
        except (ValueError, TypeError, AttributeError) as error:
            raise RunFileError("%s: %s" % (json_path, error))
    run = Run(config)

    path = os.path.join(output_dir, "metrics.csv")
    header, rows = _read_csv(path)
    if header[:len(SAMPLE_COLUMNS)] != SAMPLE_COLUMNS:
        raise RunFileError("%s: line 1: expected the columns to start with %s" % (path, ",".join(SAMPLE_COLUMNS)))
    robot_columns = header[len(SAMPLE_COLUMNS):]
    run.robots, per_robot = None, None
    for columns in (ROBOT_COLUMNS, OLD_ROBOT_COLUMNS):   # an old run has no slot_free: NaN (unknown)
        names = [c.rsplit("/", 1)[0] for c in robot_columns[::len(columns)]]
        if robot_columns == ["%s/%s" % (r, c) for r in names for c in columns]:
            run.robots, per_robot = names, columns
            break
    if per_robot is None:
        raise RunFileError("%s: line 1: expected %s for every robot after the fleet columns, got %s"
                           % (path, ",".join("<robot>/" + c for c in ROBOT_COLUMNS), ",".join(robot_columns)))
    n = len(SAMPLE_COLUMNS)
    for number, row in enumerate(rows, start=2):
        def num(i):
            return _float(path, number, header[i], row[i])
        robots = {}
        for k, r in enumerate(run.robots):
            cells = range(n + k * len(per_robot), n + (k + 1) * len(per_robot))
            if any(row[i] != "" for i in cells):   # all empty: the robot was not known yet
                robots[r] = RobotSample(*[num(i) for i in cells])
        run.samples.append(Sample(num(0), row[1], row[2], row[3], tuple(row[4].split()), num(5), num(6),
                                  num(7), num(8), num(9), num(10), num(11), num(12), row[13], robots))

    path = os.path.join(output_dir, "events.csv")
    for number, row in enumerate(_read_csv(path, EVENT_COLUMNS)[1], start=2):
        run.events.append(Event(_float(path, number, "t_s", row[0]), row[1], row[2], row[3],
                                _float(path, number, "x_m", row[4]), _float(path, number, "y_m", row[5])))

    path = os.path.join(output_dir, "controller.csv")
    header, rows = _read_csv(path)
    # runs of before the overrun counters (7 columns) and before `applied` (9) read as well
    if header not in (CONTROLLER_COLUMNS, CONTROLLER_COLUMNS[:7], CONTROLLER_COLUMNS[:9]):
        _read_csv(path, CONTROLLER_COLUMNS)   # raises, naming the expected columns
    for number, row in enumerate(rows, start=2):
        counters = [_int(path, number, "overruns", row[7]), _int(path, number, "late_starts", row[8])] \
            if len(row) > 7 else [0, 0]
        applied = _float(path, number, "applied", row[9]) if len(row) > 9 else NAN
        run.controller.append(ControllerSample(
            _float(path, number, "t_s", row[0]), row[1], _float(path, number, "latency_s", row[2]),
            _float(path, number, "cycle_time_ms", row[3]), _int(path, number, "lookups", row[4]),
            _int(path, number, "lookup_failures", row[5]), row[6], *counters, applied))
    return run
