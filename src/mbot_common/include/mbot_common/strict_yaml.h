/**
 * @file strict_yaml.h
 * @brief A strict YAML reader for config files (map yaml, world files, model settings): every
 *        error names the file, the key and what was expected, e.g.
 *        `office.world.yaml: robots[1].pose: expected a list of 3 numbers [x, y, yaw], got "1.0"`.
 *
 * Header-only (needs yaml-cpp); free of ROS types; the Python twin is mbot_common.strict_yaml.
 * `Error` is the exception type thrown (default ConfigError; MapError and WorldConfigError derive
 * from it), so a caller can keep its own type. Numbers carry no units here: the caller's
 * `what` text says them ("a number > 0 [m/s]").
 */
#pragma once

#include <yaml-cpp/yaml.h>

#include <cmath>
#include <stdexcept>
#include <fstream>
#include <set>
#include <sstream>
#include <string>
#include <utility>
#include <vector>

namespace mbot_common
{
/// @brief A config file that cannot be used; what() is one line `<file>: <key>: <problem>`.
class ConfigError : public std::runtime_error
{
public:
  using std::runtime_error::runtime_error;
};

/// @brief Reads one YAML file strictly: unknown keys, duplicate keys, missing required keys and
///        wrong types are errors of type `Error` whose message is `<file>: <key>: <problem>`.
template <class Error = ConfigError>
class StrictYaml
{
public:
  /// @param file the path shown in messages (and read by load())
  explicit StrictYaml(std::string file) : file_(std::move(file)) {}

  const std::string& file() const { return file_; }

  /// @brief Read and parse the file; the top level must be a map.
  YAML::Node load() const
  {
    std::ifstream in(file_);
    if (!in) throw Error(file_ + ": cannot read the file (missing or unreadable)");
    std::stringstream text;
    text << in.rdbuf();
    YAML::Node root;
    try
    {
      root = YAML::Load(text.str());
    }
    catch (const YAML::Exception& e)
    {
      throw Error(file_ + ": not valid YAML: " + e.what());
    }
    if (!root.IsMap()) expected("(top level)", "a map of keys", root);
    return root;
  }

  /// @brief Throw `<file>: <key>: <problem>`.
  [[noreturn]] void fail(const std::string& key, const std::string& problem) const
  {
    throw Error(file_ + ": " + key + ": " + problem);
  }

  /// @brief Throw `<file>: <key>: expected <what>, got <the node>`.
  [[noreturn]] void expected(const std::string& key, const std::string& what, const YAML::Node& got) const
  {
    fail(key, "expected " + what + ", got " + describe(got));
  }

  /// @brief The map `node` (at `where`) may hold only `allowed` keys and must hold `required` ones.
  void checkKeys(const YAML::Node& node, const std::string& where, const std::vector<std::string>& allowed,
                 const std::vector<std::string>& required = {}) const
  {
    if (!node.IsDefined() || !node.IsMap()) expected(where, "a map", node);
    const std::set<std::string> known(allowed.begin(), allowed.end());
    std::set<std::string> seen;
    for (const auto& item : node)
    {
      if (!item.first.IsScalar()) expected(where, "plain keys", item.first);
      const std::string key = item.first.Scalar();
      if (known.count(key) == 0) fail(join(where, key), "unknown key (expected one of " + list(allowed) + ")");
      if (!seen.insert(key).second) fail(join(where, key), "duplicate key");
    }
    for (const auto& key : required)
      if (!node[key]) fail(join(where, key), "missing key (required)");
  }

  /// @brief A finite number; quoted scalars ("0.5") are strings, not numbers.
  double number(const YAML::Node& node, const std::string& key, const std::string& what = "a number") const
  {
    if (!isPlainScalar(node)) expected(key, what, node);
    double value = 0.0;
    try
    {
      value = node.as<double>();
    }
    catch (const YAML::Exception&)
    {
      expected(key, what, node);
    }
    if (!std::isfinite(value)) expected(key, what, node);
    return value;
  }

  /// @brief An integer (no fraction, no quotes).
  long long integer(const YAML::Node& node, const std::string& key, const std::string& what = "an integer") const
  {
    if (!isPlainScalar(node)) expected(key, what, node);
    try
    {
      return node.as<long long>();
    }
    catch (const YAML::Exception&)
    {
      expected(key, what, node);
    }
  }

  /// @brief true/false (YAML booleans only; 0/1 are numbers, not booleans).
  bool boolean(const YAML::Node& node, const std::string& key) const
  {
    if (!isPlainScalar(node)) expected(key, "true or false", node);
    try
    {
      return node.as<bool>();
    }
    catch (const YAML::Exception&)
    {
      expected(key, "true or false", node);
    }
  }

  /// @brief A string (any scalar).
  std::string text(const YAML::Node& node, const std::string& key, const std::string& what = "a string") const
  {
    if (!node.IsDefined() || !node.IsScalar()) expected(key, what, node);
    return node.Scalar();
  }

  /// @brief A list of exactly `n` numbers, e.g. a pose [x, y, yaw].
  std::vector<double> numbers(const YAML::Node& node, const std::string& key, size_t n, const std::string& what) const
  {
    if (!node.IsDefined() || !node.IsSequence() || node.size() != n) expected(key, what, node);
    std::vector<double> values;
    for (size_t i = 0; i < n; ++i) values.push_back(number(node[i], key, what));
    return values;
  }

  /// @brief `where.key`, or `key` at the top level.
  static std::string join(const std::string& where, const std::string& key)
  {
    return where.empty() || where == "(top level)" ? key : where + "." + key;
  }

  /// @brief `where[i]`.
  static std::string index(const std::string& where, size_t i) { return where + "[" + std::to_string(i) + "]"; }

  /// @brief How a node looks in a message: "1.0" (quoted scalar), a list of 2, a map, nothing.
  static std::string describe(const YAML::Node& node)
  {
    if (!node.IsDefined() || node.IsNull()) return "nothing";
    if (node.IsMap()) return "a map";
    if (node.IsSequence()) return "a list of " + std::to_string(node.size());
    return "\"" + node.Scalar() + "\"";
  }

private:
  /// A missing key (an invalid node) is not a scalar: yaml-cpp would throw on IsScalar().
  static bool isPlainScalar(const YAML::Node& node) { return node.IsDefined() && node.IsScalar() && node.Tag() != "!"; }

  static std::string list(const std::vector<std::string>& keys)
  {
    std::string out;
    for (const auto& key : keys) out += (out.empty() ? "" : ", ") + key;
    return out;
  }

  std::string file_;
};

}  // namespace mbot_common
