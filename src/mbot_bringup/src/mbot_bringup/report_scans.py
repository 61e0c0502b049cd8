"""The robots' laser scans for the report's animation, from RUN_DIR/run.bag (fleet.launch
record:=true records every /<robot>/scan): thinned to every `stride`-th beam, one scan per robot
every `period` seconds, so that a long run stays cheap to read and to draw."""
import bisect
import math

import numpy as np

from mbot_bringup.report_data import ReportError

LASER_X = 0.05   # the laser sits 5 cm ahead of the robot's centre (mbot_description/urdf: base_laser)


def read_scans(bag_path, robots, period=0.5, stride=4):
    """{robot: ([t], [points (n x 2) in the robot's frame])}: sim time t [s] of each kept scan and
    its hits (ranges within range_min..range_max). ReportError naming the bag when it cannot be read."""
    import rosbag
    topics = dict(("/%s/scan" % r, r) for r in robots)
    out = dict((r, ([], [])) for r in robots)
    try:
        with rosbag.Bag(bag_path) as bag:
            for topic, msg, _ in bag.read_messages(topics=list(topics)):
                r = topics[topic]
                t = msg.header.stamp.to_sec()
                times, points = out[r]
                if times and t - times[-1] < period - 1e-6:   # stamps are rounded to ns
                    continue
                d = np.asarray(msg.ranges, dtype=float)[::stride]
                a = msg.angle_min + msg.angle_increment * stride * np.arange(len(d))
                hit = np.isfinite(d) & (d >= msg.range_min) & (d < msg.range_max)
                times.append(t)
                points.append(np.column_stack([LASER_X + d[hit] * np.cos(a[hit]), d[hit] * np.sin(a[hit])]))
    except Exception as error:   # rosbag raises its own and IOError/OSError
        raise ReportError("%s: cannot read the scans: %s" % (bag_path, error))
    return out


def scan_at(scans, robot, t, max_age=1.0):
    """(t, points) of the robot's newest scan at or before sim time t, None if none within max_age."""
    times, points = scans.get(robot, ([], []))
    k = bisect.bisect_right(times, t + 1e-9) - 1
    if k < 0 or t - times[k] > max_age:
        return None
    return times[k], points[k]


def in_map(points, pose):
    """Points (n x 2) of the robot's frame in the map frame, the robot at pose (x, y, theta)."""
    x, y, theta = pose
    c, s = math.cos(theta), math.sin(theta)
    return np.column_stack([x + c * points[:, 0] - s * points[:, 1], y + s * points[:, 0] + c * points[:, 1]])
