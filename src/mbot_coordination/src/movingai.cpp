#include "mbot_coordination/movingai.h"

#include <cerrno>
#include <cstdlib>
#include <fstream>
#include <sstream>

namespace mbot_coordination
{
FormatError::FormatError(const std::string& file, int line, const std::string& problem)
    : std::runtime_error(file + (line > 0 ? ":" + std::to_string(line) : std::string()) + ": " + problem),
      file_(file),
      line_(line)
{}

namespace
{
std::string readFile(const std::string& path)
{
  std::ifstream in(path, std::ios::binary);
  if (!in) throw FormatError(path, 0, "cannot open the file");
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

// Lines without their '\n' (and a '\r' before it: files from Windows read the same).
std::vector<std::string> splitLines(const std::string& text)
{
  std::vector<std::string> lines;
  std::string cur;
  std::istringstream in(text);
  while (std::getline(in, cur))
  {
    if (!cur.empty() && cur.back() == '\r') cur.pop_back();
    lines.push_back(cur);
  }
  return lines;
}

bool parseInt(const std::string& s, int& out)
{
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  const long v = std::strtol(s.c_str(), &end, 10);
  if (errno != 0 || *end != '\0' || v < -1000000000L || v > 1000000000L) return false;
  out = static_cast<int>(v);
  return true;
}

bool parseDouble(const std::string& s, double& out)
{
  if (s.empty()) return false;
  char* end = nullptr;
  errno = 0;
  out = std::strtod(s.c_str(), &end);
  return errno == 0 && *end == '\0';
}

// "KEY N" with a positive N.
int headerNumber(const std::string& name, int line, const std::string& text, const std::string& key)
{
  int value = 0;
  if (text.compare(0, key.size() + 1, key + " ") != 0 || !parseInt(text.substr(key.size() + 1), value))
    throw FormatError(name, line, "expected '" + key + " N', got '" + text + "'");
  if (value <= 0) throw FormatError(name, line, key + " must be positive, got " + std::to_string(value));
  return value;
}
}  // namespace

Grid readMap(const std::string& path) { return parseMap(readFile(path), path); }

Grid parseMap(const std::string& text, const std::string& name)
{
  const auto lines = splitLines(text);
  if (lines.empty() || lines[0] != "type octile")
    throw FormatError(name, 1, "expected 'type octile', got '" + (lines.empty() ? std::string() : lines[0]) + "'");
  if (lines.size() < 4) throw FormatError(name, static_cast<int>(lines.size()) + 1, "header ends early");
  const int height = headerNumber(name, 2, lines[1], "height");
  const int width = headerNumber(name, 3, lines[2], "width");
  if (lines[3] != "map") throw FormatError(name, 4, "expected 'map', got '" + lines[3] + "'");
  std::vector<uint8_t> free(static_cast<size_t>(width) * height);
  for (int y = 0; y < height; ++y)
  {
    const int line = 5 + y;
    if (4 + y >= static_cast<int>(lines.size()))
      throw FormatError(name, line, "expected " + std::to_string(height) + " map rows, found " + std::to_string(y));
    const std::string& row = lines[4 + y];
    if (static_cast<int>(row.size()) != width)
      throw FormatError(name, line,
                        "row " + std::to_string(y) + " has " + std::to_string(row.size()) + " characters, width is " +
                            std::to_string(width));
    for (int x = 0; x < width; ++x)
    {
      const char c = row[x];
      if (c == '.' || c == 'G')
        free[static_cast<size_t>(y) * width + x] = 1;
      else if (c != '@' && c != 'O' && c != 'T' && c != 'S' && c != 'W')
        throw FormatError(name, line, std::string("unknown map character '") + c + "' at column " + std::to_string(x));
    }
  }
  for (size_t i = 4 + height; i < lines.size(); ++i)
    if (!lines[i].empty())
      throw FormatError(name, static_cast<int>(i) + 1,
                        "text after the " + std::to_string(height) + " map rows (height too small?)");
  return Grid(width, height, std::move(free));
}

std::vector<ScenRow> readScen(const std::string& path, const Grid* grid)
{
  return parseScen(readFile(path), path, grid);
}

std::vector<ScenRow> parseScen(const std::string& text, const std::string& name, const Grid* grid)
{
  const auto lines = splitLines(text);
  if (lines.empty() || (lines[0] != "version 1" && lines[0] != "version 1.0"))
    throw FormatError(name, 1, "expected 'version 1', got '" + (lines.empty() ? std::string() : lines[0]) + "'");
  std::vector<ScenRow> rows;
  for (size_t i = 1; i < lines.size(); ++i)
  {
    const int line = static_cast<int>(i) + 1;
    const std::string& s = lines[i];
    if (s.empty())
    {
      if (i + 1 == lines.size()) break;  // a blank last line
      throw FormatError(name, line, "empty line");
    }
    std::vector<std::string> f;
    size_t pos = 0;
    while (true)
    {
      const size_t tab = s.find('\t', pos);
      f.push_back(s.substr(pos, tab == std::string::npos ? std::string::npos : tab - pos));
      if (tab == std::string::npos) break;
      pos = tab + 1;
    }
    if (f.size() != 9)
      throw FormatError(name, line,
                        "expected 9 tab-separated fields (bucket, map, width, height, start x, start y, goal x, "
                        "goal y, optimal length), got " +
                            std::to_string(f.size()));
    ScenRow r;
    r.line = line;
    r.map = f[1];
    static const char* names[] = {"bucket", "", "map width", "map height", "start x", "start y", "goal x", "goal y"};
    int* ints[] = {&r.bucket, nullptr, &r.map_width, &r.map_height, &r.start_x, &r.start_y, &r.goal_x, &r.goal_y};
    for (int k = 0; k < 8; ++k)
      if (ints[k] && !parseInt(f[k], *ints[k]))
        throw FormatError(name, line, std::string(names[k]) + " is not an integer: '" + f[k] + "'");
    if (!parseDouble(f[8], r.optimal_length) || r.optimal_length < 0.0)
      throw FormatError(name, line, "optimal length is not a number >= 0: '" + f[8] + "'");
    if (r.map.empty()) throw FormatError(name, line, "empty map name");
    if (grid)
    {
      if (r.map_width != grid->width() || r.map_height != grid->height())
        throw FormatError(name, line,
                          "map size " + std::to_string(r.map_width) + " x " + std::to_string(r.map_height) +
                              " differs from the map's " + std::to_string(grid->width()) + " x " +
                              std::to_string(grid->height()));
      const auto cell = [&](const char* what, int x, int y) {
        if (!grid->inside(x, y))
          throw FormatError(
              name, line,
              std::string(what) + " (" + std::to_string(x) + "," + std::to_string(y) + ") is outside the map");
        if (!grid->isFree(x, y))
          throw FormatError(
              name, line,
              std::string(what) + " (" + std::to_string(x) + "," + std::to_string(y) + ") is a blocked cell");
      };
      cell("start", r.start_x, r.start_y);
      cell("goal", r.goal_x, r.goal_y);
    }
    rows.push_back(r);
  }
  if (rows.empty()) throw FormatError(name, static_cast<int>(lines.size()), "no scenario rows");
  return rows;
}

}  // namespace mbot_coordination
