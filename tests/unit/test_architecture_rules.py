"""docs/ARCHITECTURE.md's dependency rules and the size rule hold for the package.xml files and
the sources as they are: a new package or dependency that breaks one fails here, not in a review."""
import os
import re
import xml.etree.ElementTree as ET

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SRC = os.path.join(ROOT, "src")
MAX_LINES = 800   # a source file longer than this is split by role


def packages():
    return sorted(d for d in os.listdir(SRC) if os.path.exists(os.path.join(SRC, d, "package.xml")))


def depends(package, kinds=("depend", "build_depend", "exec_depend", "build_export_depend")):
    root = ET.parse(os.path.join(SRC, package, "package.xml")).getroot()
    return {e.text.strip() for kind in kinds for e in root.findall(kind)}


def test_every_package_depends_on_mbot_common_but_the_ones_the_architecture_names():
    with open(os.path.join(ROOT, "docs", "ARCHITECTURE.md")) as f:
        text = f.read()
    sentence = re.search(r"Every package but (.*?) depends on `mbot_common`", text, re.S)
    assert sentence, "docs/ARCHITECTURE.md no longer says which packages do not depend on mbot_common"
    named = set(re.findall(r"`(mbot_\w+)`", sentence.group(1)))
    without = {p for p in packages() if p != "mbot_common" and "mbot_common" not in depends(p)}
    assert without == named, "not depending on mbot_common: %s; ARCHITECTURE.md names %s" % (
        sorted(without), sorted(named))


def test_the_stated_rules_hold():
    assert "mbot_sim" not in depends("mbot_navigation"), "a map server on a robot must not pull in the simulator"
    assert not {"mbot_navigation", "mbot_sim"} & depends("mbot_localization")
    assert not {"mbot_navigation", "mbot_sim"} & depends("mbot_coordination", ("depend", "build_depend"))
    assert not (depends("mbot_common") - {"catkin"}) & set(packages()), "mbot_common depends on no package of ours"


def test_no_source_file_is_longer_than_the_limit():
    long = []
    for base, dirs, files in os.walk(SRC):
        if "/test" in base[len(SRC):]:
            continue
        for name in files:
            if name.endswith((".py", ".cpp", ".h")) or base.endswith(("/nodes", "/scripts")):
                path = os.path.join(base, name)
                with open(path, errors="replace") as f:
                    lines = sum(1 for _ in f)
                if lines > MAX_LINES:
                    long.append("%s (%d lines)" % (os.path.relpath(path, ROOT), lines))
    assert not long, "split by role: %s" % ", ".join(long)
