/**
 * @file test_strict_yaml.cpp
 * @brief strict_yaml.h: each kind of mistake gives `<file>: <key>: <problem>` on one line.
 */
#include "mbot_common/strict_yaml.h"

#include <gtest/gtest.h>

#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <string>

using mbot_common::ConfigError;
using mbot_common::StrictYaml;

namespace
{
/// A file in /tmp with `text`, removed at the end of the test.
class TempYaml
{
public:
  explicit TempYaml(const std::string& text)
  {
    char name[] = "/tmp/mbot_common_strict_XXXXXX";
    const int fd = mkstemp(name);
    path_ = name;
    std::ofstream(path_) << text;
    if (fd >= 0) close(fd);
  }
  ~TempYaml() { std::remove(path_.c_str()); }
  const std::string& path() const { return path_; }

private:
  std::string path_;
};

/// The message of running f, or "" when it throws nothing.
template <class F>
std::string errorOf(F f)
{
  try
  {
    f();
  }
  catch (const ConfigError& e)
  {
    return e.what();
  }
  return "";
}
}  // namespace

TEST(StrictYaml, MissingFileAndBadYamlNameTheFile)
{
  const StrictYaml<> missing("/nonexistent/x.yaml");
  EXPECT_EQ(errorOf([&] { missing.load(); }), "/nonexistent/x.yaml: cannot read the file (missing or unreadable)");
  const TempYaml bad("a: 1\nb: [1, 2\n");
  const std::string e = errorOf([&] { StrictYaml<>(bad.path()).load(); });
  EXPECT_EQ(e.rfind(bad.path() + ": not valid YAML: ", 0), 0u) << e;
  EXPECT_NE(e.find("line"), std::string::npos) << e;
  const TempYaml list("- 1\n- 2\n");
  EXPECT_EQ(errorOf([&] { StrictYaml<>(list.path()).load(); }),
            list.path() + ": (top level): expected a map of keys, got a list of 2");
}

TEST(StrictYaml, KeysUnknownDuplicateMissing)
{
  const TempYaml file("rate: 1\nrat: 2\nrate: 3\n");
  const StrictYaml<> r(file.path());
  const YAML::Node root = r.load();
  EXPECT_EQ(errorOf([&] {
              r.checkKeys(root, "", {"rate", "gain"});
            }),
            file.path() + ": rat: unknown key (expected one of rate, gain)");
  EXPECT_EQ(errorOf([&] { r.checkKeys(root, "", {"rate", "rat"}); }), file.path() + ": rate: duplicate key");
  const TempYaml nested("robots:\n  - name: a\n");
  const StrictYaml<> n(nested.path());
  const YAML::Node robots = n.load()["robots"];
  EXPECT_EQ(errorOf([&] {
              n.checkKeys(robots[0], StrictYaml<>::index("robots", 0), {"name", "pose"}, {"pose"});
            }),
            nested.path() + ": robots[0].pose: missing key (required)");
}

TEST(StrictYaml, TypesAreStrict)
{
  const TempYaml file("q: \"0.5\"\nb: true\nf: 1.5\nn: 2\nl: [1, x, 3]\ninf: .inf\n");
  const StrictYaml<> r(file.path());
  const YAML::Node root = r.load();
  const std::string p = file.path() + ": ";
  EXPECT_EQ(errorOf([&] { r.number(root["q"], "q"); }), p + "q: expected a number, got \"0.5\"");
  EXPECT_EQ(errorOf([&] { r.number(root["b"], "b"); }), p + "b: expected a number, got \"true\"");
  EXPECT_EQ(errorOf([&] { r.number(root["inf"], "inf"); }), p + "inf: expected a number, got \".inf\"");
  EXPECT_EQ(errorOf([&] { r.integer(root["f"], "f"); }), p + "f: expected an integer, got \"1.5\"");
  EXPECT_EQ(errorOf([&] { r.boolean(root["n"], "n"); }), p + "n: expected true or false, got \"2\"");
  EXPECT_EQ(errorOf([&] { r.numbers(root["l"], "l", 3, "a list of 3 numbers"); }),
            p + "l: expected a list of 3 numbers, got \"x\"");
  EXPECT_EQ(errorOf([&] { r.number(root["none"], "none"); }), p + "none: expected a number, got nothing");
  EXPECT_DOUBLE_EQ(r.number(root["f"], "f"), 1.5);
  EXPECT_EQ(r.integer(root["n"], "n"), 2);
  EXPECT_TRUE(r.boolean(root["b"], "b"));
}
