"""scripts/fleet-hosts without namespaces: the round-robin placement, the hosts file, finding the
runner's master, and bad input (more hosts than robots, a dispatch scenario, no root) named."""
import os
import subprocess

import pytest

from mbot_bringup.fleet_hosts import HostsError, hosts_file, master_port, place

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
SCRIPT = os.path.join(ROOT, "scripts", "fleet-hosts")


def run(*args, **kwargs):
    return subprocess.run(list(kwargs.get("prefix", [])) + [SCRIPT] + list(args), stdout=subprocess.PIPE,
                          stderr=subprocess.STDOUT, universal_newlines=True, timeout=120)


def test_robots_go_round_robin_with_the_leader_on_host_1():
    robots = ["leader", "follower_1", "follower_2"] + ["robot_%d" % i for i in range(3, 10)]
    placement = place(robots, 3)
    assert placement[1] == ["leader", "robot_3", "robot_6", "robot_9"]
    assert placement[2] == ["follower_1", "robot_4", "robot_7"]
    assert placement[3] == ["follower_2", "robot_5", "robot_8"]
    assert place(["a"], 1) == {1: ["a"]}


def test_more_hosts_than_robots_is_refused():
    with pytest.raises(HostsError) as error:
        place(["leader", "follower_1"], 3)
    assert "more hosts than robots (2: leader, follower_1)" in str(error.value)


def test_every_host_resolves_every_host():
    lines = hosts_file(3).splitlines()
    assert "10.77.0.1\tmbot-h1" in lines and "10.77.0.3\tmbot-h3" in lines
    assert "127.0.0.1\tlocalhost" in lines


def test_the_master_port_comes_from_rosmaster_s_command_line():
    assert master_port(["/usr/bin/python3", "/usr/bin/rosmaster", "--core", "-p", "37933", "-w", "3"]) == 37933
    assert master_port(["rosmaster", "--core", "-p", "11311"]) == 11311
    assert master_port(["roslaunch", "-p", "37933", "mbot_bringup", "fleet.launch"]) is None
    assert master_port([]) is None


def test_bad_runs_are_named_before_anything_starts():
    result = run("run", "--hosts", "4", "triangle_trio")
    assert result.returncode == 2 and "more hosts than robots (3: leader, follower_1, follower_2)" in result.stdout
    result = run("run", "--hosts", "2", "dispatch")
    assert result.returncode == 2 and "a fleet across hosts runs formation scenarios only" in result.stdout
    result = run("run", "--hosts", "2", "no_such_scenario")
    assert result.returncode == 2 and "no_such_scenario" in result.stdout


def test_without_root_it_says_namespaces_are_not_allowed():
    prefix = ["runuser", "-u", "nobody", "--"] if os.geteuid() == 0 else []
    result = run("check", prefix=prefix)
    assert result.returncode == 4, result.stdout
    assert "network namespaces are not allowed here: not root" in result.stdout


def test_the_user_space_link_reads_netem_s_words():
    from mbot_bringup.fleet_link import parse_netem

    spec = parse_netem("delay 20ms 10ms loss 0.5%")
    assert (spec.delay, spec.jitter, spec.loss) == pytest.approx((0.020, 0.010, 0.005))
    assert parse_netem("delay 5ms").jitter == 0.0
    for bad, words in (("delay 20", "'20' is not a duration"), ("loss 2", "'2' is not a percentage"),
                       ("rate 1mbit", "'rate' not understood"), ("delay 5ms 10ms", "jitter larger")):
        with pytest.raises(ValueError) as error:
            parse_netem(bad)
        assert words in str(error.value)
