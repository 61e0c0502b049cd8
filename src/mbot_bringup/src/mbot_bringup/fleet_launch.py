"""Launching a scenario's fleet: fleet.launch on its own master (a free port), in a process group
of its own, and stopping all of it by PID (mbot_bringup.processes); the run dir it writes to;
how long (wall time) a fleet may take to come up and a run may last."""
import os
import shutil
import signal
import subprocess

from mbot_bringup.processes import descendants, start_time, stop_pids
from mbot_common.strict_yaml import ConfigError

WALL_PER_SIM = 20.0        # a run gives up after time_limit x this + START_WALL wall seconds
START_WALL = 180.0         # [s wall] for a fleet of up to START_ROBOTS robots to come up
START_ROBOTS = 20
START_WALL_PER_ROBOT = 6.0  # [s wall] more per robot beyond: 40 robots took 177 s on 2 cores


def start_wall(robots):
    """How long [s wall] a fleet of `robots` robots may take to come up: every robot's processes
    start on the same cores (a 40-robot fleet starts about 200 processes)."""
    return START_WALL + START_WALL_PER_ROBOT * max(0, robots - START_ROBOTS)


def prepare_run_dir(run_dir):
    """An empty run dir: a previous run's (it has scenario.yaml) is cleared; anything else that
    is not empty is refused, so a wrong --run-dir never deletes someone's files."""
    if os.path.isdir(run_dir) and os.listdir(run_dir):
        if not os.path.isfile(os.path.join(run_dir, "scenario.yaml")):
            raise ConfigError("%s: not empty and not a run dir (no scenario.yaml): choose another --run-dir" % run_dir)
        shutil.rmtree(run_dir)
    os.makedirs(run_dir, exist_ok=True)


class FleetLaunch(object):
    """`roslaunch -p PORT mbot_bringup fleet.launch ...` in its own process group; stop() ends it by PID."""

    def __init__(self, port, args, log_path, env):
        self.log_path = log_path
        self.log = open(log_path, "w")
        command = ["roslaunch", "-p", str(port), "mbot_bringup", "fleet.launch"] + ["%s:=%s" % kv for kv in args]
        self.log.write("# %s\n" % " ".join(command))
        self.log.flush()
        self.process = subprocess.Popen(command, stdout=self.log, stderr=subprocess.STDOUT, env=env,
                                        start_new_session=True)

    def alive(self):
        return self.process.poll() is None

    def tail(self, lines=12):
        with open(self.log_path) as f:
            return "".join(f.readlines()[-lines:])

    def stop(self):
        """SIGINT (roslaunch stops its nodes, the metrics collector and rosbag write their files),
        then SIGTERM, then SIGKILL to the process group we started."""
        p = self.process
        # Every process of the fleet, taken before anything stops: once roslaunch is gone its
        # nodes' parent is init and nothing leads to them (an interrupted 40-robot run left 150
        # nav and localization nodes running).
        tree = [(pid, start_time(pid)) for pid in descendants(p.pid)]
        for sig, wait in ((signal.SIGINT, 60.0), (signal.SIGTERM, 15.0)):
            if p.poll() is not None:
                break
            p.send_signal(sig)
            try:
                p.wait(wait)
            except subprocess.TimeoutExpired:
                pass
        if p.poll() is None:
            os.killpg(p.pid, signal.SIGKILL)
            p.wait()
        else:
            try:   # nodes that outlived roslaunch, in the group we started
                os.killpg(p.pid, signal.SIGTERM)
            except ProcessLookupError:
                pass
        stop_pids(tree)  # and those in sessions of their own
        self.log.close()
