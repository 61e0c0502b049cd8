"""fleet_navigation.launch sim:=false runs without mbot_sim installed: mbot_navigation declares
mbot_sim only as a test dependency (a map server and nav nodes on a real robot must not pull in
the simulator), so its launch file may not need mbot_sim when the simulator is off. This is why
catkin_lint's launch_depend check is silenced (once) at that include.

Checked with roslaunch's own loader (`roslaunch --files`, no master, nothing started) and a
package path without mbot_sim."""
import os
import subprocess
import tempfile

import pytest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SETUP = os.path.join(ROOT, "devel", "setup.bash")


def launch_files(*args):
    """`roslaunch --files mbot_navigation fleet_navigation.launch ARGS` with mbot_sim off the
    package path; (exit status, output)."""
    without_sim = 'echo "$ROS_PACKAGE_PATH" | tr : "\\n" | grep -v /mbot_sim | paste -sd:'
    script = ('. "%s" && export ROS_PACKAGE_PATH="$(%s)" && roslaunch --files mbot_navigation '
              'fleet_navigation.launch %s' % (SETUP, without_sim, " ".join(args)))
    env = dict(os.environ, ROS_HOME=tempfile.mkdtemp(prefix="ros_home_"), PATH="/usr/bin:/bin:" + os.environ["PATH"])
    result = subprocess.run(["bash", "-c", script], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True, timeout=60, env=env)
    return result.returncode, result.stdout


@pytest.mark.skipif(not os.path.exists(SETUP), reason="the workspace is not built (scripts/setup)")
def test_fleet_navigation_without_the_simulator_needs_no_mbot_sim():
    status, out = launch_files("world:=office", "sim:=false")
    assert status == 0, out
    assert out.split() == [os.path.join(ROOT, "src", "mbot_navigation", "launch", "fleet_navigation.launch")], out
    # the check itself can fail: with the simulator on, the same path lacks mbot_sim
    status, out = launch_files("world:=office")
    assert "mbot_sim" in out and "not found" in out, out
