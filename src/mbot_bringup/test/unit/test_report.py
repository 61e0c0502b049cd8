"""The report reads a recording and a world, and writes an HTML page with its plots."""
import json
import os

import numpy as np

from mbot_bringup.report import read_pgm, write_report


def make_world(tmp_path):
    img = np.full((40, 60), 254, dtype=np.uint8)
    img[0, :] = 0                      # top row occupied (black)
    with open(str(tmp_path / "m.pgm"), "wb") as f:
        f.write(b"P5\n# test map\n60 40\n255\n" + img.tobytes())
    (tmp_path / "m.yaml").write_text("image: m.pgm\nresolution: 0.1\norigin: [-1.0, -2.0, 0.0]\n"
                                      "occupied_thresh: 0.65\nfree_thresh: 0.196\nnegate: 0\n")
    (tmp_path / "w.world.yaml").write_text("map: m.yaml\nrobots: []\n")
    return str(tmp_path / "w.world.yaml")


def test_read_pgm_keeps_rows_and_comments(tmp_path):
    make_world(tmp_path)
    img = read_pgm(str(tmp_path / "m.pgm"))
    assert img.shape == (40, 60)
    assert img[0, 5] == 0 and img[1, 5] == 254


def test_write_report(tmp_path):
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
