"""docs/move_base_keys.md against test/config_sets/: every key that the three tables (implemented,
approximated, accepted and ignored) list for move_base, costmap_2d, navfn, global_planner,
base_local_planner and dwa_local_planner stands in at least one of the sets, in its namespace, so
that nav_dropin_sets.test, which loads the sets and wants no unknown-key warning, covers them all."""
import os
import re

import yaml

PKG = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..")
TABLES = ("Implemented", "Approximated", "Accepted and ignored")
PACKAGES = ("move_base", "costmap_2d", "navfn", "global_planner", "base_local_planner", "dwa_local_planner")
# The planners' namespaces; every other key of a set is move_base's or a costmap's.
PLANNER_NAMESPACES = ("NavfnROS", "GlobalPlanner", "DWAPlannerROS", "TrajectoryPlannerROS")


def table_rows():
    """(table, package, where, [keys]) of every row of the three tables."""
    rows, table = [], None
    with open(os.path.join(PKG, "docs", "move_base_keys.md")) as f:
        for line in f:
            if line.startswith("## "):
                table = line[3:].strip()
            elif table in TABLES and line.startswith("| ") and not line.startswith("| package") \
                    and not line.startswith("|---"):
                cells = [c.strip() for c in line.strip().strip("|").split("|")]
                rows.append((table, cells[0], cells[1], re.findall(r"`([^`]+)`", cells[2])))
    return rows


def set_keys():
    """{namespace: keys}: "" for everything outside the planners' namespaces (move_base's and the
    costmaps' keys, at any depth), else the keys under that planner's namespace."""
    keys = {ns: set() for ns in ("",) + PLANNER_NAMESPACES}

    def walk(value, ns):
        if isinstance(value, dict):
            for k, v in value.items():
                inner = k if ns == "" and k in PLANNER_NAMESPACES else ns
                if inner == ns:
                    keys[ns].add(k)
                walk(v, inner)
        elif isinstance(value, list):
            for v in value:
                walk(v, ns)

    root = os.path.join(PKG, "test", "config_sets")
    for folder in sorted(os.listdir(root)):
        for name in sorted(os.listdir(os.path.join(root, folder))):
            if name.endswith(".yaml"):
                with open(os.path.join(root, folder, name)) as f:
                    walk(yaml.safe_load(f), "")
    return keys


def test_the_tables_list_the_six_packages():
    rows = table_rows()
    assert {table for table, _, _, _ in rows} == set(TABLES)
    assert {package.split()[0] for _, package, _, _ in rows} == set(PACKAGES)
    assert sum(len(keys) for _, _, _, keys in rows) > 150


def test_every_key_of_the_tables_is_in_a_config_set():
    keys = set_keys()
    missing = []
    for table, package, where, names in table_rows():
        ns = next((n for n in PLANNER_NAMESPACES if "~%s/" % n in where), "")
        missing += ["%s: %s %s" % (table, where, name) for name in names if name not in keys[ns]]
    assert missing == []
