"""The table `scripts/bench formation` prints (scripts/bench.py formation_table): the overruns and
late starts stand beside the cycle time, "-" where a result has no such figure."""
import importlib.util
import os

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))


def bench():
    spec = importlib.util.spec_from_file_location("bench_script", os.path.join(ROOT, "scripts", "bench.py"))
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def row(runs=10, **values):
    """A row as formation_bench.worst gives it."""
    r = {"runs": runs, "succeeded": runs, "contacts": 0, "rms_straight_m": 0.02, "rms_route_m": 0.1,
         "converge_s": 5.0, "switch_s": 4.0, "degraded_s": 1.5, "recover_s": 3.0, "cycle_p99_ms": 93.34,
         "details": [{"wall_s": 120.0}, {"wall_s": 140.4}]}
    r.update(values)
    return r


def test_overruns_and_late_starts_stand_beside_the_cycle_time():
    result = {"formation": {"3": row(overruns=0, late_starts=2), "10": row(overruns=1234, late_starts=57)},
              "formation_office": {"3": row(runs=1)}}   # a result of before the counters
    lines = bench().formation_table(result).splitlines()
    header = lines[2].split()
    assert header[header.index("p99") + 1:] == ["overruns", "late", "starts", "wall", "s"]
    rows = dict((line[2:10].strip(), line.split()) for line in lines[3:])   # by the robots column
    assert rows["3"][-5:] == ["93.3", "ms", "0", "2", "140"]
    assert rows["10"][-5:] == ["93.3", "ms", "1234", "57", "140"]
    assert rows["3 office"][-5:] == ["93.3", "ms", "-", "-", "140"]   # not measured, not 0
    assert len(lines) == 6
