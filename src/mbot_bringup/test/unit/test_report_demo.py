"""The goal-tour demo's report (report_demo.write_report, used by scripts/demo and the
fleet_office rostest) reads a recording and a world, and writes an HTML page with its plots."""
import json
import os

import numpy as np

from mbot_bringup.report import write_report as report_write_report
from mbot_bringup.report_demo import load_map_for_plot, write_report


def make_world(tmp_path):
    img = np.full((40, 60), 254, dtype=np.uint8)
    img[0, :] = 0                      # top row occupied (black)
    with open(str(tmp_path / "m.pgm"), "wb") as f:
        f.write(b"P5\n# test map\n60 40\n255\n" + img.tobytes())
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.1\norigin: [-1.0, -2.0, 0.0]\n"
                                     "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    (tmp_path / "w.world.yaml").write_text("map: m.yaml\nrobots: []\n")
    return str(tmp_path / "w.world.yaml")


def test_the_map_is_drawn_with_its_top_row_at_the_top(tmp_path):
    image, extent = load_map_for_plot(make_world(tmp_path))
    assert extent == (-1.0, 5.0, -2.0, 2.0)        # origin + 60 x 40 cells of 0.1 m
    assert image.shape == (40, 60)
    # imshow(origin="lower"): row 0 is drawn at the bottom, so the image's top row is the last one
    assert image[-1, 5] < 0.5 and image[0, 5] == 1.0 and image[-2, 5] == 1.0


def test_write_report(tmp_path):
    assert report_write_report is write_report     # scripts/demo imports it from report
    world = make_world(tmp_path)
    rec = {"world": "w", "sim_seconds": 2.0, "wall_seconds": 1.0,
           "contacts": [{"t": 1.0, "a": "robot_0", "b": "map", "x": 0.5, "y": 0.5}],
           "goals": [{"robot": "robot_0", "t": 0.0, "x": 1.0, "y": 0.0}],
           "nav_results": [{"robot": "robot_0", "t": 2.0, "status": "ABORTED", "text": "goal is in an obstacle"}],
           "robots": {"robot_0": {"t": [0.0, 1.0, 2.0], "x": [0.0, 0.5, 1.0], "y": [0.0, 0.0, 0.0],
                                  "yaw": [0.0, 0.0, 0.0], "rates": {"odom": 50.0, "scan": 10.0},
                                  "counts": {}, "distance": 1.0, "min_range": 0.4}}}
    rec_path = tmp_path / "rec.json"
    rec_path.write_text(json.dumps(rec))
    out = tmp_path / "report"
    index = write_report(str(rec_path), world, str(out))
    page = open(index).read()
    assert "2.0x real time" in page
    assert "<td>robot_0</td><td>50.0</td><td>10.0</td>" in page
    assert "robot_0 &harr; map" in page
    assert "<td>ABORTED</td><td style='text-align:left'>goal is in an obstacle</td>" in page
    for png in ("trajectories.png", "speeds.png"):
        assert os.path.getsize(str(out / png)) > 1000
