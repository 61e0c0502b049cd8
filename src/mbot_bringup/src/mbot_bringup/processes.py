"""The processes a run started, found and stopped by PID: roslaunch starts each node in a
session of its own, so a process group kill misses them, and a node that runs a launch of its
own (fleet_navigation, formation_fleet) has children too. Used by the scenario runner and
fleet-hosts."""
import os
import signal
import time


def descendants(pid):
    """PIDs of every living process below `pid`, by the parent links in /proc."""
    children = {}
    for entry in os.listdir("/proc"):
        if not entry.isdigit():
            continue
        try:
            with open("/proc/%s/stat" % entry) as f:
                ppid = int(f.read().rsplit(")", 1)[1].split()[1])
        except (OSError, IndexError, ValueError):
            continue  # gone meanwhile
        children.setdefault(ppid, []).append(int(entry))
    found, todo = [], [pid]
    while todo:
        for child in children.get(todo.pop(), []):
            found.append(child)
            todo.append(child)
    return found


def start_time(pid):
    """When process `pid` started (clock ticks since boot), None when it is gone: with the PID it
    names one process (a PID can be used again)."""
    try:
        with open("/proc/%d/stat" % pid) as f:
            return int(f.read().rsplit(")", 1)[1].split()[19])
    except (OSError, IndexError, ValueError):
        return None


def stop_pids(pids, wait=5.0):
    """SIGTERM to each of `pids` ([(pid, start_time(pid))]) still alive, SIGKILL to those alive
    `wait` s later."""
    def alive(entry):
        return start_time(entry[0]) == entry[1] is not None

    for sig, pause in ((signal.SIGTERM, wait), (signal.SIGKILL, 0.0)):
        left = [entry for entry in pids if alive(entry)]
        for pid, _ in left:
            try:
                os.kill(pid, sig)
            except OSError:
                pass
        deadline = time.time() + pause
        while left and time.time() < deadline:
            time.sleep(0.1)
            left = [entry for entry in left if alive(entry)]
