"""The rviz views (src/mbot_bringup/rviz, linked from rviz/) load as YAML and show the
workspace's topics and frames; the fleet view written for a world shows every robot of it."""
import os

import pytest
import yaml

from mbot_bringup.colors import robot_colors
from mbot_bringup.fleet_rviz import VIEW_PX, main, write_fleet_view
from mbot_common.paths import resolve_world
from mbot_common.world import load_world

PKG_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
RVIZ_DIR = os.path.join(PKG_DIR, "rviz")
REPO_RVIZ_DIR = os.path.join(PKG_DIR, "..", "..", "rviz")


def load(name, directory=RVIZ_DIR):
    with open(os.path.join(directory, name + ".rviz")) as f:
        return yaml.safe_load(f)


def displays(config):
    """Every display, groups flattened: [(class, properties)]."""
    found = []

    def walk(items):
        for item in items:
            found.append((item["Class"], item))
            walk(item.get("Displays", []))

    walk(config["Visualization Manager"]["Displays"])
    return found


def topics(config, cls, key="Topic"):
    return sorted(d[key] for c, d in displays(config) if c == cls and d.get("Enabled", True))


def tool_topics(config):
    return {t["Class"]: t.get("Topic") for t in config["Visualization Manager"]["Tools"]}


@pytest.mark.parametrize("name", ["fleet", "navigation"])
def test_layout_is_rviz_1_14(name):
    config = load(name)
    assert set(config) >= {"Panels", "Visualization Manager", "Window Geometry"}
    manager = config["Visualization Manager"]
    assert manager["Global Options"]["Fixed Frame"] == "map"
    view = manager["Views"]["Current"]
    assert view["Class"] == "rviz/TopDownOrtho"
    # a 20 m map fits the window's render area (the window less a toolbar) [px/m]
    assert 20.0 * view["Scale"] <= config["Window Geometry"]["Height"] - 80
    assert "/map" in topics(config, "rviz/Map")


def test_the_repository_links_the_package_views():
    for name in ("fleet", "navigation"):
        assert load(name, REPO_RVIZ_DIR) == load(name)


def test_fleet_template_names_no_robot():
    config = load("fleet")
    assert [c for c, _ in displays(config)].count("rviz/TF") == 1
    assert topics(config, "rviz/MarkerArray", "Marker Topic") == ["/fleet/markers", "/stage/markers"]
    assert "robot_" not in yaml.safe_dump(config)


@pytest.mark.parametrize("world", ["office", "trio", "corridor_fleet"])
def test_fleet_view_shows_every_robot_of_the_world_in_its_colour(tmp_path, world):
    out = str(tmp_path / "view" / "fleet.rviz")
    assert main(["--world", world, "--out", out]) == 0
    config = yaml.safe_load(open(out))
    names = [r.name for r in load_world(resolve_world(world)).robots]
    assert topics(config, "rviz/RobotModel", "Robot Description") == sorted(n + "/robot_description" for n in names)
    assert topics(config, "rviz/LaserScan") == sorted("/%s/scan" % n for n in names)
    assert topics(config, "rviz/Path") == sorted("/%s/move_base/global_plan" % n for n in names)
    colors = robot_colors(names, names)
    scans = {d["Topic"]: d["Color"] for c, d in displays(config) if c == "rviz/LaserScan"}
    for n in names:
        assert scans["/%s/scan" % n] == "; ".join(str(int(round(255 * c))) for c in colors[n])
    # the template is kept: map, markers, tf
    assert topics(config, "rviz/MarkerArray", "Marker Topic") == ["/fleet/markers", "/stage/markers"]
    assert "/map" in topics(config, "rviz/Map")


def test_fleet_view_is_centred_on_the_map_and_fits_it(tmp_path):
    world = load_world(resolve_world("office"))
    m = world.map_data
    x0, y0 = m.origin[0], m.origin[1]
    x1, y1 = x0 + m.width * m.resolution, y0 + m.height * m.resolution
    with open(write_fleet_view("office", str(tmp_path / "o.rviz"))) as f:
        view = yaml.safe_load(f)["Visualization Manager"]["Views"]["Current"]
    assert view["X"] == pytest.approx(0.5 * (x0 + x1), abs=0.01)
    assert view["Y"] == pytest.approx(0.5 * (y0 + y1), abs=0.01)
    window = load("fleet")["Window Geometry"]
    assert (x1 - x0) * view["Scale"] <= window["Width"] and (y1 - y0) * view["Scale"] <= window["Height"]
    assert (x1 - x0) * view["Scale"] >= 0.6 * window["Width"] or (y1 - y0) * view["Scale"] >= 0.6 * window["Height"]


def test_a_follow_view_tracks_the_fleet_frame_and_fits_a_column(tmp_path):
    """office (3 robots): 10 m across at least; fleet10-like 10 robots at 1.5 m: the column
    (13.5 m) and 2 m on each side; never wider than the map (20 m)."""
    window = load("fleet")["Window Geometry"]

    def view(argv):
        out = str(tmp_path / "f.rviz")
        assert main(["--world", "office", "--out", out] + argv) == 0
        with open(out) as f:
            return yaml.safe_load(f)["Visualization Manager"]["Views"]["Current"]
    v = view(["--follow", "fleet", "--spacing", "1.0"])
    assert v["Target Frame"] == "fleet" and v["X"] == 0.0 and v["Y"] == 0.0
    assert window["Width"] / v["Scale"] == pytest.approx(10.0, rel=0.05)
    v = view(["--follow", "fleet", "--view-width", "17.5"])
    assert window["Width"] / v["Scale"] == pytest.approx(17.5, rel=0.05)
    v = view(["--follow", "fleet", "--view-width", "50"])
    assert VIEW_PX[0] / v["Scale"] == pytest.approx(20.0, rel=0.01)                # the map's width
    assert view(["--follow", ""])["Target Frame"] == "<Fixed Frame>"               # empty: the whole map


def test_a_broken_world_is_one_line_and_exit_1(tmp_path, capsys):
    bad = tmp_path / "bad.world.yaml"
    bad.write_text("map: nowhere.yaml\nrobots: []\n")
    assert main(["--world", str(bad), "--out", str(tmp_path / "x.rviz")]) == 1
    err = capsys.readouterr().err.strip()
    assert err.startswith("fleet_rviz: ") and "bad.world.yaml" in err and len(err.splitlines()) == 1
    assert not (tmp_path / "x.rviz").exists()


def test_navigation_view_shows_robot_0_plans_and_costmaps():
    config = load("navigation")
    assert topics(config, "rviz/Path") == [
        "/robot_0/move_base/global_plan", "/robot_0/move_base/local_plan"]
    costmaps = {d["Topic"]: d["Color Scheme"] for c, d in displays(config) if c == "rviz/Map"}
    assert costmaps["/robot_0/move_base/global_costmap/costmap"] == "costmap"
    assert costmaps["/robot_0/move_base/local_costmap/costmap"] == "costmap"
    assert costmaps["/map"] == "map"
    assert topics(config, "rviz/RobotModel", "Robot Description") == ["robot_0/robot_description"]
    assert topics(config, "rviz/LaserScan") == ["/robot_0/scan"]
    tools = tool_topics(config)
    assert tools["rviz/SetGoal"] == "/robot_0/move_base_simple/goal"
    assert tools["rviz/SetInitialPose"] == "/robot_0/initialpose"
