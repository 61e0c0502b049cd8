"""The invalid_* fixtures of test/fixtures/{maps,worlds}: each begins with `# expect: <message>`
({file} = the fixture's path, {dir} = its folder). The gtests (mbot_common/testing/fixture_cases.h) read the
same lines, so the C++ and the Python reader must give the same message for each."""
import os

FIXTURES = os.path.join(os.path.dirname(os.path.dirname(os.path.abspath(__file__))), "fixtures")
MAPS = os.path.join(FIXTURES, "maps")
WORLDS = os.path.join(FIXTURES, "worlds")


def invalid_fixtures(directory, suffix):
    """[(path, expected message)] of the files invalid_*<suffix> in directory, sorted by name."""
    cases = []
    for name in sorted(os.listdir(directory)):
        if name.startswith("invalid_") and name.endswith(suffix):
            path = os.path.join(directory, name)
            with open(path) as f:
                first = f.readline().rstrip("\n")
            tag = "# expect: "
            expected = first[len(tag):].replace("{file}", path).replace("{dir}", directory) \
                if first.startswith(tag) else ""
            cases.append((path, expected))
    return cases
