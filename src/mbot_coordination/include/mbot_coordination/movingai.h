// Readers for the MovingAI benchmark formats (https://movingai.com/benchmarks/formats.html):
// `.map` (grid) and `.scen` (version 1: one start/goal pair per row). Strict: a malformed file
// throws FormatError naming the file, the line and the problem.
#pragma once

#include <stdexcept>
#include <string>
#include <vector>

#include "mbot_coordination/grid.h"

namespace mbot_coordination
{
class FormatError : public std::runtime_error
{
public:
  FormatError(const std::string& file, int line, const std::string& problem);
  const std::string& file() const { return file_; }
  int line() const { return line_; }

private:
  std::string file_;
  int line_;
};

// `.map`: "type octile", "height H", "width W", "map", then H rows of W characters. '.' and 'G'
// are free; '@', 'O', 'T', 'S', 'W' blocked (the MAPF benchmark treats all but ground as blocked);
// any other character is an error.
Grid readMap(const std::string& path);
Grid parseMap(const std::string& text, const std::string& name);

struct ScenRow
{
  int bucket = 0;
  std::string map;
  int map_width = 0;
  int map_height = 0;
  int start_x = 0, start_y = 0, goal_x = 0, goal_y = 0;
  double optimal_length = 0.0;  // the file's figure: octile (8-connected, diagonal sqrt 2) distance
  int line = 0;                 // line in the file, for messages
};

// `.scen` version 1: rows of 9 tab-separated fields. With `grid`, rows must match its size and
// put start and goal on free cells. An empty file (no rows) is an error.
std::vector<ScenRow> readScen(const std::string& path, const Grid* grid = nullptr);
std::vector<ScenRow> parseScen(const std::string& text, const std::string& name, const Grid* grid = nullptr);

}  // namespace mbot_coordination
