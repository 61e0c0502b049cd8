"""Judging a scenario run: its criteria against the metrics collector's files over the
scenario's time, and criteria.json."""
import json

from mbot_bringup.console import say
from mbot_bringup.scenario import CRITERIA, evaluate, scenario_window


def judge(scenario, metrics_dir, facts):
    """(criteria results, summary or None): the criteria against the metrics files of the run,
    over the scenario's time (facts start_s to end_s, sim time)."""
    from mbot_follower.metrics import RunFileError, load_run, summarize

    try:
        run = scenario_window(load_run(metrics_dir), facts["start_s"], facts["start_s"] + facts["end_s"])
        summary = summarize(run)
    except (RunFileError, OSError) as error:
        say("no metrics to judge: %s" % error)
        return [{"name": n, "value": None, "threshold": v, "op": CRITERIA[n][0], "passed": False}
                for n, v in scenario.criteria.items()], None
    return evaluate(scenario.criteria, summary, run, facts), summary


def write_criteria(path, scenario, results, facts):
    with open(path, "w") as f:
        json.dump({"scenario": scenario.name, "passed": all(c["passed"] for c in results), "criteria": results,
                   "facts": facts}, f, indent=1)
        f.write("\n")
