"""stage_node's ~lockstep_report: when it stops, the simulator writes how much wall time sim time
waited at the lockstep boundaries and for whom (the last to answer), so a benchmark can tell what
a faster fleet has to speed up. Here one robot is commanded at 5 Hz of wall time while the
boundaries come every 0.05 s of sim time: nearly all the run is waiting, for robot_0's cmd_vel."""
import os
import re
import signal
import subprocess
import time

import pytest

from mbot_common.net import free_port

HERE = os.path.dirname(os.path.abspath(__file__))
WORLD = os.path.join(HERE, "..", "fixtures", "cmdpose.world.yaml")


def stage_node():
    for root in os.environ.get("CMAKE_PREFIX_PATH", "").split(":"):
        path = os.path.join(root, "lib", "mbot_sim", "stage_node")
        if os.path.exists(path):
            return path
    pytest.fail("stage_node not found on CMAKE_PREFIX_PATH: build mbot_sim and source devel/setup.bash")


def stop(process, sig=signal.SIGINT, timeout=20.0):
    if process.poll() is None:
        process.send_signal(sig)
        try:
            process.wait(timeout)
        except subprocess.TimeoutExpired:
            process.kill()
            process.wait()


def wait_for(master_uri, what, condition, process, timeout=60.0):
    """Until condition(master) holds: a starved machine takes seconds to start a ROS process."""
    import rosgraph.masterapi

    master = rosgraph.masterapi.Master("/test_lockstep_report", master_uri=master_uri)
    deadline = time.time() + timeout
    while time.time() < deadline and process.poll() is None:
        try:
            if condition(master):
                return
        except Exception:   # the master is still starting
            pass
        time.sleep(0.2)
    pytest.fail("%s: not after %.0f s wall (its process: exit %s)" % (what, timeout, process.poll()))


def test_the_report_names_the_robot_whose_commands_sim_time_waited_for(tmp_path):
    port = free_port()
    env = dict(os.environ, ROS_MASTER_URI="http://127.0.0.1:%d" % port, ROS_LOG_DIR=str(tmp_path))
    report = tmp_path / "lockstep.txt"
    master = subprocess.Popen(["rosmaster", "--core", "-p", str(port)], env=env, stdout=subprocess.DEVNULL,
                              stderr=subprocess.DEVNULL)
    sim = command = None
    try:
        wait_for(env["ROS_MASTER_URI"], "the master", lambda m: m.getPid(), master)
        sim = subprocess.Popen([stage_node(), "_world:=" + WORLD, "_lockstep:=true", "_real_time_factor:=0",
                                "_lockstep_report:=" + str(report)], env=env, stdout=subprocess.DEVNULL,
                               stderr=subprocess.DEVNULL)
        command = subprocess.Popen(["rostopic", "pub", "-r", "5", "/robot_0/cmd_vel", "geometry_msgs/Twist",
                                    "{linear: {x: 0.1}}"], env=env, stdout=subprocess.DEVNULL,
                                   stderr=subprocess.DEVNULL)
        wait_for(env["ROS_MASTER_URI"], "a publisher on /robot_0/cmd_vel",
                 lambda m: any(t == "/robot_0/cmd_vel" and nodes for t, nodes in m.getSystemState()[0]), command)
        time.sleep(5.0)   # wall: about 25 commands, a boundary and a wait each
        assert sim.poll() is None, "stage_node stopped early (exit %s)" % sim.returncode
        stop(sim)
        text = report.read_text()
    finally:
        for p in (command, sim, master):
            if p is not None:
                stop(p)
    # e.g. "... 60 boundaries, 0 wall timeouts (2 s wall each); 6.1 s of 7.9 s wall waiting at
    # boundaries (77 %); the last to answer: robot_0 cmd_vel 6.1 s"
    assert "the last to answer: robot_0 cmd_vel" in text, text
    waited, run = (float(v) for v in re.search(r"([\d.]+) s of ([\d.]+) s wall waiting", text).groups())
    assert waited > 0.4 * run, text
