"""docs/move_base_keys.md against the six packages' own documentation (upstream_keys.yaml: the keys
of their wiki pages and .cfg files, and the few their source reads besides): every documented key
stands in exactly one of the three tables (implemented, approximated, accepted and ignored), and
the tables list no key that the packages do not document unless it is marked with a † (accepted
although no list has it). A documented key missing from the tables would be an unknown key to the
node (a warning), not the info line the tables promise."""
import os
import re

import yaml

HERE = os.path.dirname(os.path.abspath(__file__))
DOC = os.path.join(HERE, "..", "..", "docs", "move_base_keys.md")
TABLES = ("Implemented", "Approximated", "Accepted and ignored")
MARK = "\u2020"   # † after a key: accepted, though none of the packages' lists has it


def upstream():
    """{part: set of documented keys} (a part that inherits another's keys has them too)."""
    with open(os.path.join(HERE, "upstream_keys.yaml")) as f:
        data = yaml.safe_load(f)
    for part, entry in data.items():
        assert set(entry) <= {"sources", "inherits", "wiki", "cfg", "code"}, part
        assert set(entry["sources"]) == set(entry) & {"wiki", "cfg", "code"}, "%s: a list without its source" % part
    return {part: set(entry.get("wiki", [])) | set(entry.get("cfg", [])) | set(entry.get("code", []))
            for part, entry in data.items()}, {part: entry.get("inherits") for part, entry in data.items()}


def table_keys():
    """[(table, part, key, marked)] for every key of the three tables."""
    rows, table = [], None
    with open(DOC) as f:
        for line in f:
            if line.startswith("## "):
                table = line[3:].strip()
            elif table in TABLES and line.startswith("| ") and not line.startswith("| package"):
                cells = [c.strip() for c in line.strip().strip("|").split("|")]
                for key, mark in re.findall(r"`([^`]+)`(%s?)" % MARK, cells[2]):
                    rows.append((table, cells[0], key, bool(mark)))
    return rows


def test_the_upstream_lists_name_the_six_packages_and_the_tables_use_their_parts():
    keys, _ = upstream()
    assert {part.split()[0] for part in keys} == {"move_base", "costmap_2d", "navfn", "global_planner",
                                                  "base_local_planner", "dwa_local_planner"}
    assert sum(len(k) for k in keys.values()) > 200
    assert {part for _, part, _, _ in table_keys()} == set(keys)


def test_every_documented_key_is_in_exactly_one_table():
    keys, inherits = upstream()
    where = {}
    for table, part, key, _ in table_keys():
        where.setdefault((part, key), set()).add(table)
    problems = []
    for part, documented in sorted(keys.items()):
        for key in sorted(documented):
            tables = where.get((part, key), set())
            if not tables and inherits[part]:
                tables = where.get((inherits[part], key), set())
            if len(tables) != 1:
                problems.append("%s %s: in %s" % (part, key, sorted(tables) or "no table"))
    assert problems == []


def test_the_tables_hold_no_key_that_no_package_documents_unless_marked():
    keys, inherits = upstream()
    problems = []
    for table, part, key, marked in table_keys():
        documented = key in keys[part] or bool(inherits[part] and key in keys[inherits[part]])
        if documented == marked:
            problems.append("%s, %s %s: %s" % (table, part, key, "marked %s but documented" % MARK if marked else
                                               "in no list of %s (upstream_keys.yaml) and not marked %s"
                                               % (part, MARK)))
    assert problems == []
