"""The scenario runner gives a large fleet more time to come up, and stops every process of the
fleet it started, also the nodes roslaunch put in sessions of their own, which a process group
kill misses (an interrupted 40-robot run left 150 nav and localization nodes running)."""
import os
import subprocess
import sys
import time

from mbot_bringup.processes import descendants, start_time, stop_pids


def test_the_whole_tree_is_found_and_stopped_also_in_other_sessions():
    # a "roslaunch" whose "node" runs in a session of its own (as roslaunch starts nodes) and
    # ignores SIGTERM, so that only the SIGKILL of stop_pids ends it
    script = ("import os, signal, subprocess, time\n"
              "subprocess.Popen(['%s', '-c', 'import signal, time; signal.signal(signal.SIGTERM, signal.SIG_IGN); "
              "time.sleep(60)'], start_new_session=True)\n"
              "time.sleep(60)\n" % sys.executable)
    launcher = subprocess.Popen([sys.executable, "-c", script], start_new_session=True)
    try:
        deadline = time.time() + 10.0
        while not descendants(launcher.pid) and time.time() < deadline:
            time.sleep(0.05)
        (node,) = descendants(launcher.pid)
        assert os.getsid(node) != os.getsid(launcher.pid)  # the group kill would miss it
        tree = [(pid, start_time(pid)) for pid in descendants(launcher.pid)]
        launcher.kill()
        launcher.wait()
        assert start_time(node) is not None  # outlived its parent: an orphan now
        stop_pids(tree, wait=0.5)
        deadline = time.time() + 5.0
        while start_time(node) is not None and time.time() < deadline:
            time.sleep(0.05)
        assert start_time(node) is None
    finally:
        if launcher.poll() is None:
            launcher.kill()


def test_a_pid_used_again_is_not_stopped():
    sleeper = subprocess.Popen(["sleep", "30"])
    try:
        stop_pids([(sleeper.pid, start_time(sleeper.pid) + 1)], wait=0.1)  # not the same process
        assert sleeper.poll() is None
    finally:
        sleeper.kill()
        sleeper.wait()


def test_a_larger_fleet_gets_longer_to_come_up():
    from mbot_bringup.scenario_runner import START_WALL, start_wall

    assert start_wall(3) == start_wall(20) == START_WALL
    assert start_wall(40) == START_WALL + 20 * 6.0  # 177 s measured for 40 robots on 2 cores
