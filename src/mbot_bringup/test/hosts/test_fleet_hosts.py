"""The fleet across hosts (scripts/fleet-hosts): the trio with its robots on 3 hosts made as
network namespaces (the leader with the master and the simulator on mbot-h1, follower_1 on
mbot-h2, follower_2 on mbot-h3) passes every criterion of its scenario, every robot's nodes
registered from their own host, and nothing of the hosts is left afterwards.

Needs root (namespaces, veth pairs, a bridge). Where the machine does not allow them this test
fails and says why: scripts/test_summary counts a skip as a failure too, and a test that quietly
passes would claim what was not run."""
import json
import os
import subprocess

import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", "..", "..", ".."))
SCRIPT = os.path.join(ROOT, "scripts", "fleet-hosts")


def namespaces():
    out = subprocess.run(["ip", "netns", "list"], stdout=subprocess.PIPE, universal_newlines=True).stdout
    return set(line.split()[0] for line in out.splitlines() if line.strip())


def test_trio_on_three_hosts_passes_its_criteria(tmp_path):
    check = subprocess.run([SCRIPT, "check"], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                           universal_newlines=True, timeout=60)
    if check.returncode != 0:
        pytest.fail("this machine does not allow network namespaces, so the 3-host trio was not run: "
                    + check.stdout.strip())
    run_dir = str(tmp_path / "trio")
    result = subprocess.run([SCRIPT, "run", "--hosts", "3", "triangle_trio", "--no-rviz", "--no-record",
                             "--run-dir", run_dir], stdout=subprocess.PIPE, stderr=subprocess.STDOUT,
                            universal_newlines=True, timeout=1800)
    with open(str(tmp_path / "fleet-hosts.out"), "w") as f:
        f.write(result.stdout)
    tail = "\n".join(result.stdout.splitlines()[-40:])
    for name in ("hosts.json", "criteria.json"):
        assert os.path.isfile(os.path.join(run_dir, name)), "no %s (exit status %d):\n%s" % (
            name, result.returncode, tail)
    with open(os.path.join(run_dir, "hosts.json")) as f:
        hosts = json.load(f)
    assert [h["robots"] for h in hosts["hosts"]] == [["leader"], ["follower_1"], ["follower_2"]], tail
    assert hosts["nodes"] == hosts["expected"], "a robot's nodes did not register from its host:\n" + tail
    assert all(host == "mbot-h%d" % ({"leader": 1, "follower_1": 2, "follower_2": 3}[node.split("/")[1]])
               for node, host in hosts["nodes"].items()) and len(hosts["nodes"]) == 6
    with open(os.path.join(run_dir, "criteria.json")) as f:
        criteria = json.load(f)
    failed = ["%s %s (threshold %s)" % (c["name"], c["value"], c["threshold"])
              for c in criteria["criteria"] if not c["passed"]]
    assert not failed, "criteria failed: %s\n%s" % (", ".join(failed), tail)
    assert result.returncode == 0, tail
    left = sorted(set(hosts["namespaces"]) & namespaces())
    assert not left, "namespaces left behind: %s" % left
    left = [n for n in hosts["namespaces"] if os.path.exists(os.path.join("/etc/netns", n))]
    assert not left, "hosts files left in /etc/netns: %s" % left
