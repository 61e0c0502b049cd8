"""A fleet across hosts, on one machine: hosts made as Linux network namespaces (scripts/fleet-hosts).

    scripts/fleet-hosts check                      # may this machine make network namespaces?
    scripts/fleet-hosts up 3 [--netem]             # hosts mbot-h1..3 until `down`
    scripts/fleet-hosts down
    scripts/fleet-hosts run --hosts 3 [--netem] triangle_trio [--run-dir DIR] [--no-rviz] [--no-record]

Every host is a network namespace with its own address (10.77.0.<k>/24 on eth0, and loopback);
a switch namespace holds the bridge that joins them, so no packet of theirs touches the machine's
own interfaces. Every host's route to the others has `quickack 1` (`--no-quickack`: without), see
README. Host names resolve inside the namespaces only: `ip netns exec NS` mounts
/etc/netns/NS/hosts over /etc/hosts for the command it runs (the machine's /etc/hosts is never
written). `--netem` puts a Wi-Fi-like link on every host's interface (tc netem: each packet that
leaves a host is delayed 20 ms +- 10 ms and 0.5 % of them are lost).

`run` places the scenario's robots round-robin (robot i on host i mod K + 1, so the leader is on
host 1), runs the scenario runner (scripts/scenario) on host 1, where roslaunch starts the master,
the simulator, the map server, the tf relay, the coordinator, the metrics collector and host 1's
robots (fleet.launch reads MBOT_FLEET_HOST_ROBOTS), and on every other host, once the master is
up, `roslaunch mbot_follower formation.launch part:=robots host_robots:=...` with
ROS_MASTER_URI=http://mbot-h1:PORT and ROS_HOSTNAME=mbot-h<k>. The report is the runner's; the run
dir gets hosts.json (the placement, the link, and where each robot's nodes registered from) and
hosts/h<k>.log (each other host's roslaunch). Everything is stopped by PID and every namespace
removed at the end, on an error and on Ctrl-C.
"""
import argparse
import json
import os
import signal
import subprocess
import sys
import threading
import time

from mbot_bringup.processes import descendants

SUBNET = "10.77.0"                 # host k: SUBNET.k/24
NETEM = "delay 20ms 10ms loss 0.5%"
HOST_NAME = "mbot-h%d"             # resolvable inside the namespaces
NO_NETEM = ("this kernel has no netem qdisc (CONFIG_NET_SCH_NETEM not set, or sch_netem not loaded): the link's "
            "delay and loss come from a switch in user space (mbot_bringup/fleet_link.py)")
NO_QUICKACK = ("the hosts' routes without `quickack 1`: delayed ACKs, as a default Linux network has them "
               "(README: A fleet across hosts)")
MAX_HOSTS = 20
MASTER_WAIT = 120.0                # [s wall] for host 1's master to come up
STACK_WAIT = 120.0                 # [s wall] for a host's stack to see the master's parameters
ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))))


class HostsError(Exception):
    """Something the user has to fix (the message says what)."""


class NotAllowed(HostsError):
    """This machine (or user) cannot make network namespaces."""


class NoNetem(HostsError):
    """This kernel cannot emulate the link (no netem qdisc)."""


def say(text):
    sys.stderr.write("\033[1m[mbot]\033[0m %s\n" % text)
    sys.stderr.flush()


# --- placement (no ROS, no root) ----------------------------------------------------------------

def place(robots, hosts):
    """{host number (1..hosts): [robot names]}: robot i on host i mod hosts + 1 (the first robot,
    the leader by default, on host 1 with the simulator)."""
    if hosts < 1 or hosts > MAX_HOSTS:
        raise HostsError("--hosts %d: expected 1 to %d" % (hosts, MAX_HOSTS))
    if hosts > len(robots):
        raise HostsError("--hosts %d: more hosts than robots (%d: %s); every host runs at least one robot"
                         % (hosts, len(robots), ", ".join(robots)))
    placement = {k: [] for k in range(1, hosts + 1)}
    for i, name in enumerate(robots):
        placement[i % hosts + 1].append(name)
    return placement


def hosts_file(count):
    """The /etc/hosts of every namespace: loopback and the K hosts."""
    lines = ["127.0.0.1\tlocalhost", "::1\tlocalhost ip6-localhost ip6-loopback"]
    lines += ["%s.%d\t%s" % (SUBNET, k, HOST_NAME % k) for k in range(1, count + 1)]
    return "\n".join(lines) + "\n"


def master_port(cmdline):
    """The port of `rosmaster --core -p PORT ...` (argv list), or None for another process."""
    if not cmdline or not any(os.path.basename(a) == "rosmaster" for a in cmdline[:2]):
        return None
    for flag, value in zip(cmdline, cmdline[1:]):
        if flag == "-p" and value.isdigit():
            return int(value)
    return None


# --- processes ----------------------------------------------------------------------------------

def _cmdline(pid):
    try:
        with open("/proc/%d/cmdline" % pid, "rb") as f:
            return [a.decode("utf-8", "replace") for a in f.read().split(b"\0") if a]
    except OSError:
        return []


def find_master_port(pid):
    """The port of the rosmaster that `pid` (the scenario runner) started, or None yet."""
    for child in descendants(pid):
        port = master_port(_cmdline(child))
        if port is not None:
            return port
    return None


def stop(process, name, waits=((signal.SIGINT, 30.0), (signal.SIGTERM, 10.0)), group=False):
    """Stop a process we started in its own session: SIGINT (roslaunch stops its nodes), then
    SIGTERM, then SIGKILL to its group. `group`: every signal to the group (a shell script's
    foreground child gets them too)."""
    if process is None:
        return
    for sig, wait in waits:
        if process.poll() is not None:
            break
        try:
            if group:
                os.killpg(process.pid, sig)
            else:
                process.send_signal(sig)
        except ProcessLookupError:
            pass
        try:
            process.wait(wait)
        except subprocess.TimeoutExpired:
            say("%s did not stop on %s" % (name, signal.Signals(sig).name))
    try:
        os.killpg(process.pid, signal.SIGKILL if process.poll() is None else signal.SIGTERM)
    except (ProcessLookupError, PermissionError):
        pass
    process.wait()


# --- namespaces ---------------------------------------------------------------------------------

def _ip(*args, **kwargs):
    result = subprocess.run(["ip"] + list(args), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            universal_newlines=True)
    if result.returncode != 0 and not kwargs.get("check") is False:
        raise HostsError("ip %s: %s" % (" ".join(args), result.stderr.strip()))
    return result.stdout


def check_allowed(netem=None):
    """Raise NotAllowed with the reason when this process cannot make network namespaces. With
    `netem` (tc netem's parameters): True when the kernel's netem takes them, False when the
    kernel has no netem (the user-space link of fleet_link stands in); NoNetem for other errors."""
    import shutil

    if os.geteuid() != 0:
        raise NotAllowed("not root (uid %d): making network namespaces, veth pairs and a bridge needs root; "
                         "run as root or with sudo" % os.geteuid())
    for tool in ("ip", "tc"):
        if shutil.which(tool) is None:
            raise NotAllowed("no '%s' command (Debian/Ubuntu package iproute2)" % tool)
    probe = "mbot-probe-%d" % os.getpid()
    result = subprocess.run(["ip", "netns", "add", probe], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            universal_newlines=True)
    if result.returncode != 0:
        raise NotAllowed("'ip netns add' failed: %s (a container without CAP_SYS_ADMIN/CAP_NET_ADMIN?)"
                         % result.stderr.strip())
    try:
        result = subprocess.run(["ip", "-n", probe, "link", "add", "br0", "type", "bridge"],
                                stdout=subprocess.PIPE, stderr=subprocess.PIPE, universal_newlines=True)
        if result.returncode != 0:
            raise NotAllowed("cannot make a bridge in a namespace: %s" % result.stderr.strip())
        if netem:
            subprocess.run(["ip", "-n", probe, "link", "add", "v0", "type", "veth", "peer", "name", "v1"],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE)
            result = subprocess.run(["ip", "netns", "exec", probe, "tc", "qdisc", "add", "dev", "v0", "root", "netem"]
                                    + netem.split(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                    universal_newlines=True)
            if result.returncode != 0:
                if "unknown" in result.stderr.lower():
                    return False
                raise NoNetem("tc netem %s: %s" % (netem, result.stderr.strip()))
            return True
    finally:
        subprocess.run(["ip", "netns", "del", probe], stderr=subprocess.DEVNULL)
    return None


class Hosts(object):
    """K hosts (namespaces PREFIX-h1..K) joined by a bridge in the namespace PREFIX-sw."""

    def __init__(self, count, prefix="mbot", quickack=True):
        if count < 1 or count > MAX_HOSTS:
            raise HostsError("%d hosts: expected 1 to %d" % (count, MAX_HOSTS))
        self.count = count
        self.prefix = prefix
        self.switch = "%s-sw" % prefix
        self.link = None           # the user-space switch's process (no kernel netem)
        self.quickack = quickack

    def ns(self, k):
        return "%s-h%d" % (self.prefix, k)

    def address(self, k):
        return "%s.%d" % (SUBNET, k)

    def name(self, k):
        return HOST_NAME % k

    def namespaces(self):
        return [self.switch] + [self.ns(k) for k in range(1, self.count + 1)]

    def up(self, netem=None, kernel_netem=True, link_log=None):
        """Make the namespaces, the bridge, one veth pair per host, the hosts files and (netem)
        the link's delay and loss: tc netem on every host's interface, or without `kernel_netem`
        a user-space switch (fleet_link) in the bridge's place, its counts into `link_log`. On an
        error, what was made is removed again."""
        userspace = bool(netem) and not kernel_netem
        if userspace:
            from mbot_bringup.fleet_link import parse_netem

            parse_netem(netem)     # a ValueError before anything is made
        existing = set(line.split()[0] for line in _ip("netns", "list").splitlines() if line.strip())
        taken = sorted(existing & set(self.namespaces()))
        if taken:
            raise HostsError("namespaces %s exist already (scripts/fleet-hosts down%s removes them)"
                             % (", ".join(taken), "" if self.prefix == "mbot" else " --prefix " + self.prefix))
        try:
            _ip("netns", "add", self.switch)
            _ip("-n", self.switch, "link", "add", "br0", "type", "bridge")
            _ip("-n", self.switch, "link", "set", "br0", "up")
            os.makedirs("/etc/netns", exist_ok=True)
            text = hosts_file(self.count)
            for k in range(1, self.count + 1):
                ns = self.ns(k)
                _ip("netns", "add", ns)
                os.makedirs("/etc/netns/%s" % ns, exist_ok=True)
                with open("/etc/netns/%s/hosts" % ns, "w") as f:
                    f.write(text)
                # both ends made inside their namespaces: no interface ever appears on the machine's own
                _ip("link", "add", "eth0", "netns", ns, "type", "veth", "peer", "name", "h%d" % k, "netns", self.switch)
                if userspace:
                    _ip("-n", self.switch, "link", "set", "h%d" % k, "up")
                else:
                    _ip("-n", self.switch, "link", "set", "h%d" % k, "master", "br0", "up")
                _ip("-n", ns, "addr", "add", "%s/24" % self.address(k), "dev", "eth0")
                _ip("-n", ns, "link", "set", "eth0", "up")
                _ip("-n", ns, "link", "set", "lo", "up")
                if self.quickack:
                    # ACK at once: ROS 1 subscriptions without TCP_NODELAY (scans, odometry) otherwise
                    # wait up to 40 ms for a delayed ACK on messages over one segment (Nagle)
                    _ip("-n", ns, "route", "replace", "%s.0/24" % SUBNET, "dev", "eth0", "quickack", "1")
                if netem and not userspace:
                    tc = subprocess.run(["ip", "netns", "exec", ns, "tc", "qdisc", "add", "dev", "eth0", "root",
                                         "netem"] + netem.split(), stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                                        universal_newlines=True)
                    if tc.returncode != 0:
                        raise HostsError("tc netem %s: %s" % (netem, tc.stderr.strip()))
            if userspace:
                ports = ",".join("h%d" % k for k in range(1, self.count + 1))
                log = open(link_log or os.devnull, "w")
                self.link = subprocess.Popen(["ip", "netns", "exec", self.switch, sys.executable, "-m",
                                              "mbot_bringup.fleet_hosts", "_link", "--ports", ports, "--netem", netem],
                                             stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
                log.close()
        except BaseException:
            self.down()
            raise

    def exec_prefix(self, k):
        return ["ip", "netns", "exec", self.ns(k)]

    def resolves(self, src, dst):
        """The address host `src` finds for host `dst`'s name (getent: /etc/hosts as programs read it)."""
        result = subprocess.run(self.exec_prefix(src) + ["getent", "hosts", self.name(dst)],
                                stdout=subprocess.PIPE, stderr=subprocess.STDOUT, universal_newlines=True)
        return result.stdout.split()[0] if result.returncode == 0 and result.stdout.strip() else None

    def down(self):
        """Remove every namespace of these hosts (their veths and the bridge go with them) and the
        hosts files. Processes left in a namespace (ours: nothing else runs there) get SIGKILL."""
        if self.link is not None:
            stop(self.link, "the user-space link", waits=((signal.SIGTERM, 5.0),))
            self.link = None
        existing = set(line.split()[0] for line in _ip("netns", "list").splitlines() if line.strip())
        for ns in self.namespaces():
            if ns in existing:
                for pid in _ip("netns", "pids", ns, check=False).split():
                    try:
                        os.kill(int(pid), signal.SIGKILL)
                    except (ProcessLookupError, ValueError):
                        pass
                _ip("netns", "del", ns, check=False)
            path = "/etc/netns/%s" % ns
            if os.path.isdir(path):
                for name in os.listdir(path):
                    os.remove(os.path.join(path, name))
                os.rmdir(path)
        # made by the first of several runs, which may end before the others: the last one removes it
        if os.path.isdir("/etc/netns") and not os.listdir("/etc/netns"):
            try:
                os.rmdir("/etc/netns")
            except OSError:
                pass  # another run made its hosts file meanwhile


def existing_hosts(prefix):
    """The number of hosts of `prefix` that exist (0: none)."""
    names = set(line.split()[0] for line in _ip("netns", "list").splitlines() if line.strip())
    count = 0
    while "%s-h%d" % (prefix, count + 1) in names:
        count += 1
    return count


# --- the run ------------------------------------------------------------------------------------

def load_run_scenario(name_or_path):
    """(scenario, robot names of its run's world) as the scenario runner will place them."""
    import rospkg

    from mbot_bringup.fleet_world import run_world
    from mbot_bringup.scenario import load_scenario
    from mbot_common.paths import resolve_world

    if "/" in name_or_path or name_or_path.endswith(".yaml"):
        path = os.path.abspath(name_or_path)
    else:
        path = os.path.join(rospkg.RosPack().get_path("mbot_bringup"), "scenarios", name_or_path + ".yaml")
    if not os.path.isfile(path):
        raise HostsError("scenario %s: no file %s" % (name_or_path, path))
    scenario = load_scenario(path)
    if scenario.mode != "formation":
        raise HostsError("scenario %s: mode %s; a fleet across hosts runs formation scenarios only"
                         % (scenario.name, scenario.mode))
    world = scenario.world
    if ("/" in world or world.endswith(".yaml")) and not os.path.isabs(world):
        world = os.path.join(os.path.dirname(path), world)
    robots = run_world(resolve_world(world), scenario.robots)[1]
    return path, scenario, robots


def host_env(hosts, k, master_uri, robots=None):
    env = dict(os.environ, ROS_HOSTNAME=hosts.name(k), ROS_MASTER_URI=master_uri)
    env.pop("ROS_IP", None)    # ROS_HOSTNAME names the host; a stray ROS_IP of the machine must not
    if robots is not None:
        env["MBOT_FLEET_HOST_ROBOTS"] = ",".join(robots)
    return env


def wait_stack_ready(master_uri, timeout):
    """(In a host's namespace) wait until host 1's master has /use_sim_time and /fleet/world_file;
    return the world file's path."""
    import rosgraph

    master = rosgraph.Master("/fleet_hosts_wait", master_uri=master_uri)
    end = time.time() + timeout
    last = None
    while time.time() < end:
        try:
            if master.getParam("/use_sim_time") is True:
                # the output of fleet_world (a command parameter): the path and a newline
                return master.getParam("/fleet/world_file").strip()
        except Exception as error:  # noqa: B902 (no master yet, or the parameters are not set yet)
            last = error
        time.sleep(0.5)
    raise HostsError("no master with /use_sim_time and /fleet/world_file at %s after %.0f s (%s)"
                     % (master_uri, timeout, last))


def record_nodes(master_uri, host_of, out, timeout):
    """(On host 1) wait until every robot's move_base and follower_controller are registered and
    write where each registered from (the host name in its URI; `host_of`: {robot: host name}
    expected) to `out` (JSON). A robot's move_base is the node that publishes
    ``/<robot>/move_base/status``: its own process, or the host's ``fleet_host`` that loaded it."""
    from urllib.parse import urlparse

    import rosgraph

    master = rosgraph.Master("/fleet_hosts_nodes", master_uri=master_uri)
    expected = {"/%s/%s" % (r, node): host for r, host in host_of.items()
                for node in ("move_base", "follower_controller")}
    found = {}
    end = time.time() + timeout
    while time.time() < end and len(found) < len(expected):
        try:
            publishers = dict(master.getSystemState()[0])
        except Exception:  # noqa: B902 (no master any more)
            publishers = {}
        for node in expected:
            if node not in found:
                provider = node
                if node.endswith("/move_base"):
                    provider = (publishers.get(node + "/status") or [node])[0]
                try:
                    found[node] = urlparse(master.lookupNode(provider)).hostname
                except Exception:  # noqa: B902 (not registered yet, or no master any more)
                    pass
        time.sleep(1.0)
    with open(out, "w") as f:
        json.dump({"nodes": found, "expected": expected,
                   "all_where_placed": all(found.get(n) == h for n, h in expected.items())}, f, indent=1)
        f.write("\n")


def run(args):
    """`run`: see the module docstring. Returns the exit status (the runner's, or 2 bad input,
    3 the fleet did not come up, 4 no namespaces)."""
    path, scenario, robots = load_run_scenario(args.scenario)
    placement = place(robots, args.hosts)
    netem = args.netem_spec if args.netem else None
    run_dir = os.path.abspath(args.run_dir or os.path.join(
        ROOT, "out", "runs", "%s-hosts%d%s" % (scenario.name, args.hosts, "-netem" if netem else "")))
    kernel_netem = check_allowed(netem)
    hosts = Hosts(args.hosts, prefix="mbot%d" % os.getpid(), quickack=not args.no_quickack)
    names = {k: hosts.name(k) for k in placement}
    link = ("link: netem " + netem if netem else "no netem") + ("" if hosts.quickack else ", no quickack")
    say("%s on %d hosts (%s): %s" % (scenario.name, args.hosts, link,
                                     "; ".join("%s %s: %s" % (names[k], hosts.address(k), ", ".join(placement[k]))
                                               for k in sorted(placement))))
    runner = None
    stacks = {}
    recorder = None

    def on_term(_signum, _frame):
        raise KeyboardInterrupt

    signal.signal(signal.SIGTERM, on_term)
    if netem and not kernel_netem:
        say(NO_NETEM)
    os.makedirs(os.path.dirname(run_dir), exist_ok=True)   # the link's log goes beside the run dir until it exists
    hosts.up(netem, kernel_netem, link_log="%s-link.log" % run_dir.rstrip("/"))
    try:
        for k in range(2, args.hosts + 1):
            if hosts.resolves(k, 1) != hosts.address(1):
                raise HostsError("%s does not resolve %s to %s" % (hosts.name(k), hosts.name(1), hosts.address(1)))
        command = [os.path.join(ROOT, "scripts", "scenario"), path, "--run-dir", run_dir]
        command += [a for a, on in (("--no-rviz", args.no_rviz), ("--no-record", args.no_record),
                                    ("--real-time", args.real_time)) if on]
        # the runner sets ROS_MASTER_URI (localhost:its port) itself
        # its own session: a Ctrl-C reaches us only, and we stop the runner once (it then stops its launch)
        runner = subprocess.Popen(hosts.exec_prefix(1) + command, start_new_session=True,
                                  env=host_env(hosts, 1, "http://localhost:11311", placement[1]))
        port = None
        end = time.time() + MASTER_WAIT
        while port is None and runner.poll() is None and time.time() < end:
            time.sleep(0.5)
            port = find_master_port(runner.pid)
        if port is None:
            if runner.poll() is None:
                raise HostsError("no master on host 1 after %.0f s" % MASTER_WAIT)
            return runner.returncode
        master_uri = "http://%s:%d" % (hosts.name(1), port)
        say("master %s; starting the other hosts' robots" % master_uri)
        os.makedirs(os.path.join(run_dir, "hosts"), exist_ok=True)
        me = [sys.executable, "-m", "mbot_bringup.fleet_hosts"]
        for k in range(2, args.hosts + 1):
            log = open(os.path.join(run_dir, "hosts", "h%d.log" % k), "w")
            stack = me + ["_stack", "--master", master_uri, "--robots", ",".join(placement[k]),
                          "--localization", scenario.localization, "--controller", scenario.controller,
                          "--leader-max-vel", str(scenario.leader_max_vel),
                          "--lockstep", "false" if args.real_time else "true"]
            env = host_env(hosts, k, master_uri)
            env["ROS_LOG_DIR"] = os.path.join(run_dir, "hosts", "ros_logs_h%d" % k)
            stacks[k] = subprocess.Popen(hosts.exec_prefix(k) + stack, stdout=log, stderr=subprocess.STDOUT,
                                         env=env, start_new_session=True)
            log.close()
        recorder = subprocess.Popen(hosts.exec_prefix(1) + me + [
            "_nodes", "--master", master_uri, "--host-of", json.dumps({r: names[k] for k in placement
                                                                       for r in placement[k]}),
            "--out", os.path.join(run_dir, "hosts", "nodes.json")], env=host_env(hosts, 1, master_uri),
            start_new_session=True)
        write_hosts_json(run_dir, scenario, hosts, placement, netem, master_uri,
                         "" if not netem else "tc netem" if kernel_netem else "user-space switch (fleet_link)")
        while runner.poll() is None:
            gone = [k for k, process in sorted(stacks.items()) if process.poll() is not None]
            if gone:
                log = os.path.join(run_dir, "hosts", "h%d.log" % gone[0])
                with open(log) as f:
                    tail = "".join(f.readlines()[-8:])
                say("error: %s's robots stopped (exit status %d): the run cannot go on. The end of %s:\n%s"
                    % (hosts.name(gone[0]), stacks[gone[0]].returncode, log, tail))
                stop(runner, "the scenario runner", waits=((signal.SIGINT, 120.0), (signal.SIGTERM, 15.0)), group=True)
                runner = None
                return 3
            time.sleep(1.0)
        status = runner.returncode
        runner = None
        return status
    except KeyboardInterrupt:
        say("interrupted: stopping what this run started")
        return 130
    finally:
        if runner is not None:   # interrupted: the runner stops its launch on SIGINT
            stop(runner, "the scenario runner", waits=((signal.SIGINT, 120.0), (signal.SIGTERM, 15.0)), group=True)
        # all hosts at once: each roslaunch takes its time to stop its nodes once the master is gone
        stopping = [threading.Thread(target=stop, args=(process, "host %d's robots" % k))
                    for k, process in sorted(stacks.items())]
        for thread in stopping:
            thread.start()
        for thread in stopping:
            thread.join()
        if recorder is not None and recorder.poll() is None:
            stop(recorder, "the node recorder", waits=((signal.SIGTERM, 5.0),))
        hosts.down()
        link_log = "%s-link.log" % run_dir.rstrip("/")
        if os.path.isfile(link_log):
            if os.path.isdir(os.path.join(run_dir, "hosts")):
                os.rename(link_log, os.path.join(run_dir, "hosts", "link.log"))
            else:
                os.remove(link_log)
        if os.path.isdir(os.path.join(run_dir, "hosts")):
            finish_hosts_json(run_dir)


def write_hosts_json(run_dir, scenario, hosts, placement, netem, master_uri, link):
    with open(os.path.join(run_dir, "hosts.json"), "w") as f:
        json.dump({"scenario": scenario.name, "master": master_uri, "netem": netem or "", "link": link,
                   "quickack": hosts.quickack,
                   "namespaces": hosts.namespaces(),
                   "hosts": [{"name": hosts.name(k), "address": hosts.address(k), "robots": placement[k],
                              "runs": "master, simulator, map server, tf relay, coordinator, metrics, its robots"
                              if k == 1 else "its robots"} for k in sorted(placement)]}, f, indent=1)
        f.write("\n")


def finish_hosts_json(run_dir):
    """hosts.json gets nodes.json's findings (where each robot's nodes registered from)."""
    path = os.path.join(run_dir, "hosts.json")
    nodes = os.path.join(run_dir, "hosts", "nodes.json")
    if not (os.path.isfile(path) and os.path.isfile(nodes)):
        return
    with open(path) as f:
        data = json.load(f)
    with open(nodes) as f:
        data.update(json.load(f))
    with open(path, "w") as f:
        json.dump(data, f, indent=1)
        f.write("\n")
    say("hosts: %s (%s)" % (path, "every robot's nodes ran on their host" if data.get("all_where_placed")
                            else "NOT every robot's nodes registered from their host"))


def stack(args):
    """`_stack` (in a host's namespace): wait for host 1's master, then become roslaunch of this
    host's robots (exec: the process we stop by PID is roslaunch itself)."""
    world_file = wait_stack_ready(args.master, STACK_WAIT)
    command = ["roslaunch", "mbot_follower", "formation.launch", "part:=robots", "host_robots:=" + args.robots,
               "world:=" + world_file, "localization:=" + args.localization, "controller:=" + args.controller,
               "leader_max_vel:=" + args.leader_max_vel, "lockstep:=" + args.lockstep]
    print("# %s" % " ".join(command))
    sys.stdout.flush()
    os.execvp(command[0], command)


def link(args):
    """`_link` (in the switch namespace): the user-space switch until SIGTERM/SIGINT; its counts
    at the end."""
    from mbot_bringup.fleet_link import Switch, parse_netem

    stopping = []
    signal.signal(signal.SIGTERM, lambda *_: stopping.append(1))
    signal.signal(signal.SIGINT, lambda *_: stopping.append(1))
    spec = parse_netem(args.netem)
    switch = Switch(args.ports.split(","), spec)
    print("user-space link between %s: %s" % (args.ports, spec))
    sys.stdout.flush()
    try:
        switch.run(lambda: bool(stopping))
    except InterruptedError:
        pass
    print(switch.counts())
    return 0


def parse_args(argv):
    parser = argparse.ArgumentParser(prog="fleet-hosts", description=__doc__.split("\n\n")[0],
                                     epilog="README.md, section 'A fleet across hosts'.")
    sub = parser.add_subparsers(dest="command")
    sub.add_parser("check", help="say whether this machine can make network namespaces")
    p = sub.add_parser("up", help="make K hosts (namespaces mbot-h1..K) until `down`")
    p.add_argument("count", type=int)
    p.add_argument("--netem", action="store_true", help="a Wi-Fi-like link: tc netem " + NETEM)
    p.add_argument("--netem-spec", default=NETEM, help="tc netem's parameters (default: %(default)s)")
    p.add_argument("--no-quickack", action="store_true", help=NO_QUICKACK)
    sub.add_parser("down", help="remove the hosts `up` made")
    p = sub.add_parser("run", help="run a formation scenario with its robots spread over K hosts")
    p.add_argument("scenario", help="a name (scenarios/NAME.yaml of mbot_bringup) or a path")
    p.add_argument("--hosts", type=int, default=3, help="number of hosts (default %(default)s)")
    p.add_argument("--netem", action="store_true", help="a Wi-Fi-like link: tc netem " + NETEM)
    p.add_argument("--netem-spec", default=NETEM, help="tc netem's parameters (default: %(default)s)")
    p.add_argument("--run-dir", help="default out/runs/NAME-hostsK[-netem]")
    p.add_argument("--no-rviz", action="store_true")
    p.add_argument("--no-record", action="store_true")
    p.add_argument("--real-time", action="store_true")
    p.add_argument("--no-quickack", action="store_true", help=NO_QUICKACK)
    p = sub.add_parser("_stack")       # inside a host: its robots (run starts it)
    for name in ("--master", "--robots", "--localization", "--controller", "--leader-max-vel", "--lockstep"):
        p.add_argument(name, required=True)
    p = sub.add_parser("_link")        # inside the switch namespace: the user-space link
    p.add_argument("--ports", required=True)
    p.add_argument("--netem", required=True)
    p = sub.add_parser("_nodes")       # inside host 1: where the robots' nodes registered from
    p.add_argument("--master", required=True)
    p.add_argument("--host-of", required=True, help="JSON {robot: host name}")
    p.add_argument("--out", required=True)
    args = parser.parse_args(argv)
    if args.command is None:
        parser.error("name a command: check, up, down or run")
    return args


def main(argv=None):
    args = parse_args(sys.argv[1:] if argv is None else argv)
    try:
        if args.command == "check":
            check_allowed()
            print("network namespaces: allowed (root, ip and tc, a namespace with a bridge could be made)")
            return 0
        if args.command == "up":
            netem = args.netem_spec if args.netem else None
            kernel_netem = check_allowed(netem)
            if netem and not kernel_netem:
                say(NO_NETEM)
            hosts = Hosts(args.count, quickack=not args.no_quickack)
            hosts.up(netem, kernel_netem)
            for k in range(1, args.count + 1):
                print("%s\t%s\tip netns exec %s ..." % (hosts.name(k), hosts.address(k), hosts.ns(k)))
            return 0
        if args.command == "down":
            count = existing_hosts("mbot")
            Hosts(max(count, 1)).down()
            print("removed %d hosts" % count)
            return 0
        if args.command == "run":
            return run(args)
        if args.command == "_stack":
            return stack(args)
        if args.command == "_link":
            return link(args)
        if args.command == "_nodes":
            record_nodes(args.master, json.loads(args.host_of), args.out, STACK_WAIT + 60.0)
            return 0
    except NotAllowed as error:
        say("error: network namespaces are not allowed here: %s" % error)
        return 4
    except NoNetem as error:
        say("error: the Wi-Fi-like link cannot be made here: %s" % error)
        return 4
    except HostsError as error:
        say("error: %s" % error)
        return 2
    except ValueError as error:     # a bad scenario file (ConfigError)
        say("error: %s" % error)
        return 2
    return 2


if __name__ == "__main__":
    sys.exit(main())
