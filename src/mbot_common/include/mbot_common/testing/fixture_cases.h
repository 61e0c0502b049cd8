/**
 * @file fixture_cases.h
 * @brief The invalid_* fixtures of mbot_common's test/fixtures/{maps,worlds}: each begins with
 *        `# expect: <message>` ({file} = the fixture's path, {dir} = its folder). The gtests and
 *        the pytest tests (test/unit/common_fixture_cases.py) read the same lines, so the C++ and the
 *        Python reader must give the same message for each; mbot_sim's test_world_config runs the world
 *        fixtures through the simulator too.
 */
#pragma once

#include <algorithm>
#include <dirent.h>
#include <fstream>
#include <string>
#include <vector>

namespace mbot_common_test
{
/// @brief One invalid fixture: its path and the message it must give.
struct FixtureCase
{
  std::string path;
  std::string expected;
};

/// @brief Replace every `from` in `text` by `to`.
inline std::string replaceAll(std::string text, const std::string& from, const std::string& to)
{
  for (size_t pos = text.find(from); pos != std::string::npos; pos = text.find(from, pos + to.size()))
    text.replace(pos, from.size(), to);
  return text;
}

/// @brief The files invalid_*`suffix` in `dir` with their expected messages, sorted by name.
///        A fixture without an `# expect:` first line gets an empty message (a test failure).
inline std::vector<FixtureCase> invalidFixtures(const std::string& dir, const std::string& suffix)
{
  std::vector<std::string> names;
  if (DIR* d = opendir(dir.c_str()))
  {
    while (dirent* entry = readdir(d))
    {
      const std::string name = entry->d_name;
      if (name.rfind("invalid_", 0) == 0 && name.size() > suffix.size() &&
          name.compare(name.size() - suffix.size(), suffix.size(), suffix) == 0)
        names.push_back(name);
    }
    closedir(d);
  }
  std::sort(names.begin(), names.end());
  std::vector<FixtureCase> cases;
  for (const auto& name : names)
  {
    FixtureCase c;
    c.path = dir + "/" + name;
    std::ifstream in(c.path);
    std::string first;
    std::getline(in, first);
    const std::string tag = "# expect: ";
    if (first.rfind(tag, 0) == 0)
      c.expected = replaceAll(replaceAll(first.substr(tag.size()), "{file}", c.path), "{dir}", dir);
    cases.push_back(c);
  }
  return cases;
}

}  // namespace mbot_common_test
