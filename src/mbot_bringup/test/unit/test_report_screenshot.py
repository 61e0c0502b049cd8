"""scripts/screenshot (the fleet views fleet_rviz writes for trio, under Xvfb, captured by
mbot_bringup.screenshot) of a running trio world: the PNGs are not blank, and each robot's marker
colour appears where the robot stands, in the whole-map view and in the view that follows the
`fleet` frame.

Starts its own ROS master on a free port, the simulator (mbot_sim sim.launch world:=trio) and the
map server (empty map), and stops them by PID at the end. Skips when ROS, Xvfb, rviz or
ImageMagick's import is missing.

Where a robot should appear: rviz's top-down view shows the map square (20 m x 20 m, walls and
free cells in two greys) at the view's "Scale" [px/m]; its bounding box in the image gives the
map frame, so robot (x, y) belongs at left + (x - x0) * s, bottom - (y - y0) * s.
"""
import os
import shutil
import signal
import subprocess
import time

import numpy as np
import pytest
import yaml

from mbot_bringup.fleet_rviz import write_fleet_view
from mbot_common.net import free_port
from mbot_bringup.screenshot import looks_rendered
from mbot_common.paths import resolve_world
from mbot_common.world import load_world

HERE = os.path.dirname(os.path.abspath(__file__))
ROOT = os.path.normpath(os.path.join(HERE, "..", "..", "..", ".."))
NEEDED = ("roscore", "roslaunch", "rostopic", "Xvfb", "rviz", "import")
MISSING = [p for p in NEEDED if shutil.which(p) is None]
BACKGROUND = 48.0          # fleet.rviz "Background Color" 48; 48; 48
MAP_ALPHA = 0.7            # fleet.rviz Map "Alpha"
MARKER_ALPHA = 0.9         # stage_node's robot markers

pytestmark = pytest.mark.skipif(bool(MISSING), reason="not installed: %s" % ", ".join(MISSING))


def marker_rgb(index):
    """The colour stage_node gives robot `index` of the world on /stage/markers (hue = index / 6)."""
    import math
    hue = (index % 6) / 6.0
    return np.array([0.5 + 0.5 * math.cos(2.0 * math.pi * (hue - k / 3.0)) for k in range(3)]) * 255.0


def stop(process):
    """SIGINT (roslaunch and roscore shut their nodes down), then SIGKILL if it hangs."""
    if process.poll() is None:
        process.send_signal(signal.SIGINT)
        try:
            process.wait(timeout=30)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def wait_for(what, check, seconds):
    end = time.time() + seconds
    while time.time() < end:
        if check():
            return
        time.sleep(0.5)
    raise AssertionError("%s: not there after %d s" % (what, seconds))


#: Where the follow view's frame is put (a static map -> fleet transform): the trio's robots stand
#: 0.5-3 m from it and the 10 m wide view stays inside the 20 m room, so the map fills the view.
FOLLOW_FRAME = (-4.5, 0.25)
STATIC_TF = """
import sys, rospy, tf2_ros
from geometry_msgs.msg import TransformStamped
rospy.init_node("fleet_frame")
t = TransformStamped()
t.header.stamp = rospy.Time.now()
t.header.frame_id, t.child_frame_id = "map", "fleet"
t.transform.translation.x, t.transform.translation.y = float(sys.argv[1]), float(sys.argv[2])
t.transform.rotation.w = 1.0
tf2_ros.StaticTransformBroadcaster().sendTransform(t)
rospy.spin()
"""


def view_scale(view):
    with open(view) as f:
        return float(yaml.safe_load(f)["Visualization Manager"]["Views"]["Current"]["Scale"])


@pytest.fixture(scope="module")
def trio_screenshots(tmp_path_factory):
    """{"map": PNG of the whole-map view, "follow": PNG of the view following the `fleet` frame,
    "world": the trio world, "map_scale"/"follow_scale": the views' scales [px/m]} of
    scripts/screenshot against a running trio world."""
    tmp = tmp_path_factory.mktemp("screenshot")
    env = dict(os.environ, ROS_MASTER_URI="http://localhost:%d" % free_port(), ROS_LOG_DIR=str(tmp / "logs"))
    port = env["ROS_MASTER_URI"].rsplit(":", 1)[1]
    world = load_world(resolve_world("trio"))
    log = open(str(tmp / "ros.log"), "w")
    processes = []

    def shoot(name, view):
        png = str(tmp / (name + ".png"))
        shot = subprocess.run([os.path.join(ROOT, "scripts", "screenshot"), png, "--config", view, "--wait", "10"],
                              env=env,
                              stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=300)
        assert shot.returncode == 0, shot.stdout
        return png

    try:
        processes.append(subprocess.Popen(["roscore", "-p", port], env=env, stdout=log, stderr=log))
        wait_for("ROS master", lambda: subprocess.run(["rostopic", "list"], env=env, stdout=subprocess.DEVNULL,
                                                      stderr=subprocess.DEVNULL).returncode == 0, 60)
        processes.append(subprocess.Popen(["roslaunch", "mbot_sim", "sim.launch", "world:=trio"], env=env,
                                          stdout=log, stderr=log))
        processes.append(subprocess.Popen(["roslaunch", "mbot_navigation", "map_server.launch",
                                           "map:=" + world.map_path], env=env, stdout=log, stderr=log))
        processes.append(subprocess.Popen(["/usr/bin/python3", "-c", STATIC_TF] + ["%g" % v for v in FOLLOW_FRAME],
                                          env=env, stdout=log, stderr=log))

        def published():
            out = subprocess.run(["rostopic", "list"], env=env, stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                                 universal_newlines=True).stdout.split()
            return "/stage/markers" in out and "/map" in out and "/tf_static" in out
        wait_for("/stage/markers, /map and /tf_static", published, 120)
        whole = write_fleet_view("trio", str(tmp / "trio.rviz"))
        follow = write_fleet_view("trio", str(tmp / "trio_follow.rviz"), follow="fleet", width=10.0)
        return {"map": shoot("trio", whole), "follow": shoot("trio_follow", follow), "world": world,
                "map_scale": view_scale(whole), "follow_scale": view_scale(follow)}
    finally:
        for p in reversed(processes):
            stop(p)
        log.close()


def map_box(image, map_data, scale):
    """(left, right, top, bottom) [px] of the map square: columns and rows where most pixels have
    the colour of a free or an occupied cell under the map's alpha."""
    free = MAP_ALPHA * 254.0 + (1 - MAP_ALPHA) * BACKGROUND
    wall = (1 - MAP_ALPHA) * BACKGROUND
    grey = (np.abs(image - image[..., :1]).max(axis=2) <= 2)
    is_map = grey & ((np.abs(image[..., 0] - free) <= 3) | (np.abs(image[..., 0] - wall) <= 3))
    cols = np.flatnonzero(is_map.sum(axis=0) > 0.5 * map_data.height * map_data.resolution * scale)
    rows = np.flatnonzero(is_map.sum(axis=1) > 0.5 * map_data.width * map_data.resolution * scale)
    return cols[0], cols[-1] + 1, rows[0], rows[-1] + 1


@pytest.mark.parametrize("view", ["map", "follow"])
def test_the_screenshot_is_rendered(trio_screenshots, view):
    from PIL import Image
    png = trio_screenshots[view]
    assert looks_rendered(png)
    image = Image.open(png).convert("RGB")
    assert image.size == (1200, 846)                   # scripts/common.sh start_xvfb: 1200x846
    assert len(image.getcolors(1 << 20)) > 100         # map, markers, panels, text


def robot_pixels(image, index, free):
    """(rows, cols) of the pixels with robot `index`'s marker colour over a free cell."""
    colour = MARKER_ALPHA * marker_rgb(index) + (1 - MARKER_ALPHA) * free
    rows, cols = np.nonzero(np.abs(image - colour).max(axis=2) <= 12)
    assert len(rows) >= 15, "robot %d: its marker colour %s is not in the screenshot" % (index, colour.round())
    return rows, cols


def test_each_robots_colour_is_where_the_robot_is(trio_screenshots):
    from PIL import Image
    png, world, view_scale = trio_screenshots["map"], trio_screenshots["world"], trio_screenshots["map_scale"]
    image = np.asarray(Image.open(png).convert("RGB"), dtype=float)
    map_data = world.map_data
    left, right, top, bottom = map_box(image, map_data, view_scale)
    scale = (right - left) / (map_data.width * map_data.resolution)
    assert scale == pytest.approx(view_scale, rel=0.03)
    assert (bottom - top) / (map_data.height * map_data.resolution) == pytest.approx(view_scale, rel=0.03)
    x0, y0, _ = map_data.origin
    free = MAP_ALPHA * 254.0 + (1 - MAP_ALPHA) * BACKGROUND
    for index, robot in enumerate(world.robots):
        rows, cols = robot_pixels(image, index, free)
        expected = (left + (robot.pose.x - x0) * scale, bottom - (robot.pose.y - y0) * scale)
        found = (cols.mean(), rows.mean())
        # within 0.1 m (the robot's radius is 0.15 m) of where the world file puts it
        assert abs(found[0] - expected[0]) < 0.1 * scale and abs(found[1] - expected[1]) < 0.1 * scale, \
            "%s at %s px, expected %s px" % (robot.name, np.round(found, 1), np.round(expected, 1))
        assert cols.max() - cols.min() < 0.4 * scale      # one disc, not scattered pixels


def test_the_follow_view_is_centred_on_the_fleet_frame(trio_screenshots):
    """The view that follows `fleet` (the coordinator's frame in the middle of the fleet; here a
    static transform) shows each robot at its offset from that frame, at the view's scale: the
    map fills this view, so the middle of its map pixels is the frame."""
    from PIL import Image
    world, scale = trio_screenshots["world"], trio_screenshots["follow_scale"]
    image = np.asarray(Image.open(trio_screenshots["follow"]).convert("RGB"), dtype=float)
    free = MAP_ALPHA * 254.0 + (1 - MAP_ALPHA) * BACKGROUND
    is_free = (np.abs(image - free).max(axis=2) <= 3)
    # the render area: the rows and columns mostly of free cells (not the toolbar's odd pixel)
    cols = np.flatnonzero(is_free.sum(axis=0) > 0.5 * is_free.shape[0])
    rows = np.flatnonzero(is_free.sum(axis=1) > 0.5 * is_free.shape[1])
    # the render area is about 1160 px wide: a 10 m view is about 116 px/m (fleet_rviz)
    assert scale == pytest.approx(116.0, rel=0.05)
    assert cols[-1] - cols[0] > 0.9 * 10.0 * scale, "the map does not fill the view"
    centre = (0.5 * (cols[0] + cols[-1]), 0.5 * (rows[0] + rows[-1]))
    for index, robot in enumerate(world.robots):
        rows, cols = robot_pixels(image, index, free)
        expected = (centre[0] + (robot.pose.x - FOLLOW_FRAME[0]) * scale,
                    centre[1] - (robot.pose.y - FOLLOW_FRAME[1]) * scale)
        found = (cols.mean(), rows.mean())
        assert abs(found[0] - expected[0]) < 0.1 * scale and abs(found[1] - expected[1]) < 0.1 * scale, \
            "%s at %s px, expected %s px" % (robot.name, np.round(found, 1), np.round(expected, 1))
        assert cols.max() - cols.min() < 0.4 * scale
