"""The report's animation draws each robot's laser hits from RUN_DIR/run.bag (report_scans): the
scans are thinned, placed in the map with the robot's pose of the scan's time, every frame of
the recorded trio run has hits for each robot, and a frame drawn shows them as dots of the
robot's colour where they are, and nothing of that colour elsewhere; a broken bag is one line
naming it."""
import math
import os

import numpy as np
import pytest
import rosbag
import rospy
from sensor_msgs.msg import LaserScan

from mbot_bringup.report_data import ReportError, Series
from mbot_bringup.report_plots import AnimationFrame, _index_at, animation_frames, frame_scans
from mbot_bringup.report_scans import LASER_X, read_scans
from mbot_follower.metrics import Event, RobotSample, Run, Sample, load_run

HERE = os.path.dirname(os.path.abspath(__file__))
FIXTURE = os.path.join(HERE, "..", "fixtures", "run_trio")
BEAMS = 360
WALL = 2.0   # every beam hits at 2 m; beams 0..89 (the front-left quarter) see nothing


def scan(t):
    m = LaserScan()
    m.header.stamp = rospy.Time.from_sec(t)
    m.angle_min, m.angle_increment = -math.pi, 2 * math.pi / BEAMS
    m.range_min, m.range_max = 0.1, 8.0
    m.ranges = [float("inf") if k < 90 else WALL for k in range(BEAMS)]
    return m


def write_bag(path, robots, t_from, t_to, rate=10.0):
    with rosbag.Bag(path, "w") as bag:
        for t in np.arange(t_from, t_to, 1.0 / rate):
            for r in robots:
                bag.write("/%s/scan" % r, scan(t), rospy.Time.from_sec(t))
    return path


def test_scans_are_thinned_in_time_and_beams(tmp_path):
    bag = write_bag(str(tmp_path / "run.bag"), ["a", "b"], 100.0, 103.0)
    scans = read_scans(bag, ["a", "b", "c"], period=0.5, stride=4)
    times, points = scans["a"]
    assert times == pytest.approx([100.0, 100.5, 101.0, 101.5, 102.0, 102.5])
    assert len(points[0]) == (BEAMS - 90) // 4              # every 4th beam, the ones that hit
    assert np.hypot(points[0][:, 0] - LASER_X, points[0][:, 1]) == pytest.approx(WALL)
    assert scans["c"] == ([], [])                           # a robot without scans has none


def test_every_frame_has_each_robots_hits_where_its_laser_sees_them(tmp_path):
    run = load_run(os.path.join(FIXTURE, "metrics"))
    series = Series(run)
    t0, t1 = series.t0 + series.t[0], series.t0 + series.t[-1]
    scans = read_scans(write_bag(str(tmp_path / "run.bag"), run.robots, t0 - 0.5, t1 + 0.5), run.robots)
    frames = animation_frames(series, 240)
    for i in frames:
        seen = frame_scans(series, scans, i)
        for r in run.robots:
            if series.pose(r, i) is None or series.pose(r, _index_at(series, series.t[i] - 0.5)) is None:
                continue        # not there, or not yet at its scan's time
            assert r in seen and len(seen[r]) > 50, (r, series.t[i])
    # the hits of a frame lie 2 m from the laser of the robot's pose at the scan's time
    i = frames[len(frames) // 2]
    for r, points in frame_scans(series, scans, i).items():
        t_scan = max(t for t in scans[r][0] if t <= series.t0 + series.t[i])
        k = max(0, int(np.searchsorted(series.t, t_scan - series.t0 + 1e-9)) - 1)
        x, y, theta = series.pose(r, k)
        laser = (x + LASER_X * math.cos(theta), y + LASER_X * math.sin(theta))
        assert np.hypot(points[:, 0] - laser[0], points[:, 1] - laser[1]) == pytest.approx(WALL)
    # no scans: no hits (a run recorded without run.bag)
    assert frame_scans(series, None, frames[0]) == {}


def test_a_broken_bag_is_one_line_naming_it(tmp_path):
    bag = tmp_path / "run.bag"
    bag.write_text("not a bag")
    with pytest.raises(ReportError) as error:
        read_scans(str(bag), ["leader"])
    assert str(error.value).startswith("%s: cannot read the scans: " % bag)
    assert "\n" not in str(error.value)


def test_a_frame_shows_the_hits_as_dots_of_the_robots_colour_where_they_are():
    from mbot_common.paths import resolve_world
    from mbot_common.world import load_world
    nan = float("nan")
    poses = {"a": (0.0, 0.0, math.pi / 2), "b": (4.0, 3.0, 0.0)}   # a faces +y; b has no scan
    run = Run()
    run.robots = ["a", "b"]
    run.events = [Event(10.0, "state", "NAVIGATING", "", nan, nan)]
    for t in (10.0, 10.2):
        robots = dict((r, RobotSample(x, y, th, nan, nan, 0.0, 0.0)) for r, (x, y, th) in poses.items())
        run.samples.append(Sample(t, "NAVIGATING", "a", "", (), nan, nan, nan, nan, nan, nan, nan, nan, "", robots))
    # a's scan at 10.0 s: three hits in its own frame (x ahead), so at (-0.5, 2), (1.5, 1), (2, 3) in the map
    hits = np.array([[2.0, 0.5], [1.0, -1.5], [3.0, -2.0]])
    scans = {"a": ([10.0], [hits]), "b": ([], [])}
    colors = {"a": (0.0, 0.4, 0.8), "b": (0.8, 0.2, 0.2)}
    frame = AnimationFrame(run, load_world(resolve_world("field")), colors, 0.15, scans)
    frame.draw(1)
    fig, ax = frame.fig, frame.ax
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())[:, :, :3] / 255.0
    height = image.shape[0]
    dot = 0.7 * np.array(colors["a"]) + 0.3   # the dots: alpha 0.7 on the free (white) map

    def near(xy, color, tolerance=0.08):
        """Pixels within 2 px of the map point xy whose colour is within tolerance of color."""
        px, py = ax.transData.transform(xy)
        row, col = int(round(height - py)), int(round(px))
        patch = image[row - 2:row + 3, col - 2:col + 3]
        return int(np.sum(np.max(np.abs(patch - color), axis=2) < tolerance))

    for x, y in [(-0.5, 2.0), (1.5, 1.0), (2.0, 3.0)]:
        assert near((x, y), dot) >= 1, (x, y)
    # the same distances in other directions (no beam hit there), and around b (no scan): no dot
    for x, y in [(0.5, -0.7), (-0.7, 0.7), (2.5, 0.0), (1.0, 3.5), (3.0, 2.0), (4.5, 2.0)]:
        assert near((x, y), dot) == 0, (x, y)
        assert near((x, y), np.array([1.0, 1.0, 1.0]), 0.02) == 25, (x, y)   # white: the free map only
    # with no scans the same frame has no dot at the hits
    frame = AnimationFrame(run, load_world(resolve_world("field")), colors, 0.15, None)
    frame.draw(1)
    fig, ax = frame.fig, frame.ax
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())[:, :, :3] / 255.0
    for x, y in [(-0.5, 2.0), (1.5, 1.0), (2.0, 3.0)]:
        assert near((x, y), dot) == 0, (x, y)
