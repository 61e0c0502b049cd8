"""The fleet benchmark's bookkeeping (fleet_bench.py): process kinds, the CPU of a process tree
read from /proc, and the figures of a run window. The runs themselves are a benchmark."""
import os
import subprocess
import sys
import time

import pytest

from mbot_bringup import fleet_bench
from mbot_bringup.scenario import load_scenario


def test_a_process_is_known_by_its_node_name_or_its_program():
    assert fleet_bench.kind_of("/usr/bin/python3 /ws/devel/lib/mbot_follower/follower_controller "
                               "__name:=follower_controller __log:=/x.log") == "follower_controller"
    assert fleet_bench.kind_of("/ws/devel/lib/mbot_navigation/nav_node __name:=move_base") == "move_base"
    assert fleet_bench.kind_of("/usr/bin/python3 /usr/bin/rosmaster --core -p 1234 -w 3") == "rosmaster"
    assert fleet_bench.kind_of("/usr/bin/python3 -m mbot_bringup.scenario_runner x.yaml") == "scenario_runner"
    assert fleet_bench.kind_of("/bin/sleep 5") == "sleep"


def test_the_process_tree_counts_the_cpu_of_a_child_that_works():
    child = subprocess.Popen([sys.executable, "-c", "import time\nt = time.process_time()\n"
                              "while time.process_time() - t < 0.3: pass\ntime.sleep(5)"])
    try:
        tree = fleet_bench.ProcessTree(child.pid)
        deadline = time.time() + 10.0
        while time.time() < deadline:
            tree.read()
            if sum(tree.by_kind().values()) >= 0.29:
                break
            time.sleep(0.1)
        cpu = tree.by_kind()
        assert 0.29 <= sum(cpu.values()) < 2.0, cpu
    finally:
        child.kill()
        child.wait()


def fake_proc(root, processes):
    """A /proc with `processes` {pid: (parent, CPU ticks, command line)}."""
    for pid, (parent, ticks, cmdline) in processes.items():
        d = root / str(pid)
        d.mkdir(exist_ok=True)
        fields = ["S", str(parent)] + ["0"] * 9 + [str(ticks), "0"] + ["0"] * 10
        (d / "stat").write_text("%d (x) %s\n" % (pid, " ".join(fields)))
        (d / "cmdline").write_bytes(cmdline.replace(" ", "\0").encode())


def test_a_child_read_between_fork_and_exec_is_counted_by_what_it_execs(tmp_path):
    """Between fork and exec a process roslaunch starts has roslaunch's command line: a kind
    fixed at that moment counted 40 robots' controllers as formation_fleet (13 % of the CPU)."""
    launcher = "/usr/bin/python3 /ws/devel/lib/mbot_follower/formation_fleet __name:=formation_fleet"
    follower = "/usr/bin/python3 /ws/devel/lib/mbot_follower/follower_controller __name:=follower_controller"
    tick = os.sysconf("SC_CLK_TCK")
    fake_proc(tmp_path, {10: (1, tick, launcher), 11: (10, 0, launcher)})   # 11 forked, not yet exec'd
    tree = fleet_bench.ProcessTree(10, proc=str(tmp_path))
    tree.read()
    up = tree.snapshot()
    fake_proc(tmp_path, {10: (1, tick, launcher), 11: (10, 5 * tick, follower)})
    tree.read()
    assert tree.cpu_between(up) == {"formation_fleet": 0.0, "follower_controller": 5.0}
    assert tree.by_kind() == {"formation_fleet": 1.0, "follower_controller": 5.0}


def test_the_figures_of_a_window_are_per_robot_and_per_sim_second(tmp_path):
    tick = os.sysconf("SC_CLK_TCK")
    fake_proc(tmp_path, {10: (1, 1 * tick, "/x/follower_controller __name:=follower_controller"),
                         11: (10, 2 * tick, "/x/nav_node __name:=move_base")})
    tree = fleet_bench.ProcessTree(10, proc=str(tmp_path))
    tree.read()
    before = tree.snapshot()
    fake_proc(tmp_path, {10: (1, 7 * tick, "/x/follower_controller __name:=follower_controller"),
                         11: (10, 4 * tick, "/x/nav_node __name:=move_base"),
                         12: (10, tick // 2, "/x/fleet_tf_relay __name:=fleet_tf_relay")})
    tree.read()
    cpu = tree.cpu_between(before, tree.snapshot())
    assert cpu == pytest.approx({"follower_controller": 6.0, "move_base": 2.0, "fleet_tf_relay": 0.5})
    f = fleet_bench.figures(robots=10, sim_s=20.0, wall_s=10.0, cpu=cpu)
    assert f["rtf"] == 2.0
    assert f["cpu_per_robot"] == pytest.approx(8.5 / (10 * 20.0))
    assert list(f["top"]) == ["follower_controller", "move_base", "fleet_tf_relay"]
    assert f["top"]["follower_controller"] == pytest.approx(6.0 / 8.5, abs=1e-3)


@pytest.mark.parametrize("robots", [3, 40])
def test_the_benchmark_scenarios_are_valid_scenario_files(tmp_path, robots):
    import yaml

    for make in (fleet_bench.formation_scenario, fleet_bench.navigation_scenario):
        path = tmp_path / ("%s_%d.yaml" % (make.__name__, robots))
        path.write_text(yaml.safe_dump(make(robots)))
        s = load_scenario(str(path))
        assert s.robots == robots
