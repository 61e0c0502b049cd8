"""The rviz configs in rviz/ load as YAML and show what DESIGN.md's topics and frames name."""
import os

import pytest
import yaml

from paths import REPO_DIR

RVIZ_DIR = os.path.join(REPO_DIR, "rviz")


def load(name):
    with open(os.path.join(RVIZ_DIR, name + ".rviz")) as f:
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
    # a 20 m map fits the default render area (about 800 x 680 px) [px/m]
    assert 20.0 * view["Scale"] <= 680
    assert "/map" in topics(config, "rviz/Map")


def test_fleet_view_shows_three_robots_and_the_markers():
    config = load("fleet")
    assert topics(config, "rviz/RobotModel", "Robot Description") == [
        "robot_%d/robot_description" % i for i in range(3)]
    assert topics(config, "rviz/LaserScan") == ["/robot_%d/scan" % i for i in range(3)]
    markers = topics(config, "rviz/MarkerArray", "Marker Topic")
    assert markers == ["/fleet/markers", "/stage/markers"]
    assert [c for c, _ in displays(config)].count("rviz/TF") == 1


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
