"""fleet_navigation.launch on a machine without mbot_sim (a real fleet): with sim:=false roslaunch
never reads the simulator's include, so mbot_navigation needs mbot_sim only for its tests."""
import os
import subprocess

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
SRC_DIR = os.path.dirname(PACKAGE_DIR)


def roslaunch_nodes(tmp_path, *args):
    """`roslaunch --nodes` of fleet_navigation.launch with only mbot_navigation on the package path."""
    packages = tmp_path / "packages"
    packages.mkdir(exist_ok=True)
    link = packages / "mbot_navigation"
    if not link.exists():
        link.symlink_to(PACKAGE_DIR)
    system = [p for p in os.environ.get("ROS_PACKAGE_PATH", "").split(os.pathsep)
              if p and not os.path.abspath(p).startswith(SRC_DIR)]
    env = dict(os.environ, ROS_PACKAGE_PATH=os.pathsep.join([str(packages)] + system), ROS_HOME=str(tmp_path))
    launch = os.path.join(PACKAGE_DIR, "launch", "fleet_navigation.launch")
    # The timeout only guards against a hang: with an empty ROS_HOME rospack crawls the whole
    # package path, which took over 60 s on a 2-core machine at load 50.
    return subprocess.run(["roslaunch", "--nodes", launch, "world:=office"] + list(args), env=env,
                          stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True, timeout=600)


def test_without_the_simulator_only_the_fleet_node_starts(tmp_path):
    result = roslaunch_nodes(tmp_path, "sim:=false")
    assert result.returncode == 0, result.stdout
    assert result.stdout.split() == ["/fleet_navigation"]


def test_with_the_simulator_it_needs_mbot_sim(tmp_path):
    # The same path without mbot_sim: the default sim:=true must fail, naming the package.
    result = roslaunch_nodes(tmp_path)
    assert result.returncode != 0
    assert "mbot_sim" in result.stdout
