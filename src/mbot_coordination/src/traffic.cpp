#include "mbot_coordination/traffic.h"

#include <algorithm>
#include <cmath>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include "mbot_common/strict_yaml.h"
#include "mbot_coordination/sipp.h"

namespace mbot_coordination
{
namespace
{
std::string num(double v)
{
  std::ostringstream s;
  s << v;
  return s.str();
}
}  // namespace

bool PlanningGrid::insideMap(double x, double y) const
{
  return x >= origin_x && y >= origin_y && x < origin_x + map_width && y < origin_y + map_height;
}

int PlanningGrid::cellAt(double x, double y) const
{
  if (!std::isfinite(x) || !std::isfinite(y)) return -1;
  const int cx = static_cast<int>(std::floor((x - origin_x) / cell_size));
  const int cy = static_cast<int>(std::floor((y - origin_y) / cell_size));
  return grid.inside(cx, cy) ? grid.id(cx, cy) : -1;
}

int PlanningGrid::nearestFreeCell(double x, double y) const
{
  int best = -1;
  double best_d = 0.0;
  for (int v = 0; v < grid.size(); ++v)
    if (grid.isFree(v))
    {
      const auto c = centre(v);
      const double d = std::hypot(c.x - x, c.y - y);
      if (best < 0 || d < best_d) best = v, best_d = d;
    }
  return best;
}

mbot_common::Point2D PlanningGrid::centre(int cell) const
{
  return {origin_x + (grid.x(cell) + 0.5) * cell_size, origin_y + (grid.y(cell) + 0.5) * cell_size};
}

PlanningGrid makePlanningGrid(const mbot_common::OccupancyMap& map, double cell_size, double robot_radius)
{
  if (!std::isfinite(cell_size) || !std::isfinite(robot_radius) || robot_radius < 0.0)
    throw std::invalid_argument("planning grid: cell_size and robot_radius must be finite, robot_radius >= 0");
  if (cell_size < 2.0 * robot_radius)
    throw std::invalid_argument("planning grid: cell_size " + num(cell_size) +
                                " m is smaller than the robot's diameter " + num(2.0 * robot_radius) + " m");
  if (map.origin_yaw != 0.0)
    throw std::invalid_argument("planning grid: the map is rotated (origin yaw " + num(map.origin_yaw) +
                                " rad); only yaw 0 is supported");
  PlanningGrid g;
  g.grid = Grid::fromOccupancy(map.data, static_cast<int>(map.width), static_cast<int>(map.height), map.resolution,
                               cell_size, robot_radius);
  g.origin_x = map.origin_x;
  g.origin_y = map.origin_y;
  g.cell_size = cell_size;
  g.map_width = map.width * map.resolution;
  g.map_height = map.height * map.resolution;
  return g;
}

std::vector<TimedPose> timedWaypoints(const PlanningGrid& grid, const std::vector<int>& path, double t0, double speed,
                                      double final_yaw)
{
  if (!(speed > 0.0) || !std::isfinite(speed)) throw std::invalid_argument("timed waypoints: speed must be > 0");
  const double step = grid.cell_size / speed;
  std::vector<TimedPose> poses(path.size());
  for (size_t k = 0; k < path.size(); ++k)
  {
    const auto c = grid.centre(path[k]);
    poses[k].x = c.x;
    poses[k].y = c.y;
    poses[k].t = t0 + step * static_cast<double>(k);
    poses[k].cell = path[k];
    poses[k].yaw = final_yaw;
    for (size_t j = k + 1; j < path.size(); ++j)
      if (path[j] != path[k])
      {
        const auto n = grid.centre(path[j]);
        poses[k].yaw = std::atan2(n.y - c.y, n.x - c.x);
        break;
      }
  }
  return poses;
}

size_t waitEnd(const std::vector<int>& path, size_t k)
{
  while (k + 1 < path.size() && path[k + 1] == path[k]) ++k;
  return k;
}

std::vector<size_t> markedPoses(const std::vector<int>& path, const std::vector<bool>& hold_before)
{
  std::vector<size_t> marked;
  if (path.empty()) return marked;
  const size_t last = path.size() - 1;
  for (size_t k = 0; k <= last; ++k)
  {
    bool mark = k == 0 || k == last;
    if (k > 0 && path[k - 1] == path[k]) continue;  // inside a wait: its first pose is the mark
    if (k < last && path[k + 1] == path[k]) mark = true;
    if (k > 0 && k < last && path[k + 1] != path[k])
    {
      // a corner: the move into k and the move out of k differ in direction
      const int in = path[k] - path[k - 1], out = path[k + 1] - path[k];
      if (in != out) mark = true;
    }
    const size_t next = waitEnd(path, k) + 1;
    if (next <= last && next < hold_before.size() && hold_before[next]) mark = true;
    if (mark) marked.push_back(k);
  }
  return marked;
}

std::vector<FleetGoal> readGoalsFile(const std::string& path)
{
  const mbot_common::StrictYaml<> yaml(path);
  const YAML::Node root = yaml.load();
  yaml.checkKeys(root, "(top level)", {"goals"}, {"goals"});
  const YAML::Node goals = root["goals"];
  if (!goals.IsMap() || goals.size() == 0)
    yaml.expected("goals", "a map robot name: [x, y, yaw] (at least one)", goals);
  std::vector<FleetGoal> out;
  std::set<std::string> seen;
  for (const auto& item : goals)
  {
    if (!item.first.IsScalar()) yaml.expected("goals", "robot names as keys", item.first);
    const std::string name = item.first.Scalar();
    if (!seen.insert(name).second) yaml.fail("goals." + name, "a robot twice");
    const auto v = yaml.numbers(item.second, "goals." + name, 3, "[x, y, yaw] in m, m, rad (3 finite numbers)");
    out.push_back({name, v[0], v[1], v[2]});
  }
  return out;
}

std::vector<int> checkGoals(const std::vector<FleetGoal>& goals, const std::vector<std::string>& known_robots,
                            const PlanningGrid& grid)
{
  if (goals.empty()) throw std::invalid_argument("no goals");
  std::set<std::string> seen;
  std::vector<int> cells;
  for (const auto& g : goals)
  {
    if (std::find(known_robots.begin(), known_robots.end(), g.robot) == known_robots.end())
    {
      std::string known;
      for (const auto& n : known_robots) known += (known.empty() ? "" : ", ") + n;
      throw std::invalid_argument("unknown robot '" + g.robot + "' (known: " + known + ")");
    }
    if (!seen.insert(g.robot).second) throw std::invalid_argument(g.robot + ": two goals for one robot");
    const std::string where = g.robot + ": goal (" + num(g.x) + ", " + num(g.y) + ", " + num(g.yaw) + ")";
    if (!std::isfinite(g.x) || !std::isfinite(g.y) || !std::isfinite(g.yaw))
      throw std::invalid_argument(where + " is not a finite pose");
    if (!grid.insideMap(g.x, g.y))
      throw std::invalid_argument(where + " is outside the map ([" + num(grid.origin_x) + ", " +
                                  num(grid.origin_x + grid.map_width) + "] x [" + num(grid.origin_y) + ", " +
                                  num(grid.origin_y + grid.map_height) + "] m)");
    const int c = grid.cellAt(g.x, g.y);
    if (c < 0 || !grid.grid.isFree(c))
      throw std::invalid_argument(where + " is in a wall or too close to one for the robot (planning cell of " +
                                  num(grid.cell_size) + " m blocked)");
    for (size_t i = 0; i < cells.size(); ++i)
      if (cells[i] == c)
        throw std::invalid_argument(goals[i].robot + " and " + g.robot +
                                    ": two robots, one goal (the same planning cell of " + num(grid.cell_size) + " m)");
    cells.push_back(c);
  }
  return cells;
}

Paths planAround(const Grid& grid, const Paths& fixed, const std::vector<int>& starts, const std::vector<int>& goals,
                 const PlannerOptions& options, std::string* why)
{
  const size_t n = starts.size();
  if (goals.size() != n) throw std::invalid_argument("planAround: starts and goals differ in number");
  const auto deadline = Clock::now() + std::chrono::duration_cast<Clock::duration>(
                                           std::chrono::duration<double>(std::max(0.0, options.time_limit_s)));
  ReservationTable base(grid.size(), options.following);
  for (const auto& p : fixed) base.reservePath(p);
  std::vector<std::vector<int>> h(n);
  for (size_t i = 0; i < n; ++i) h[i] = grid.distancesTo(goals[i]);
  std::vector<size_t> order(n);
  std::iota(order.begin(), order.end(), 0);
  std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return h[a][starts[a]] < h[b][starts[b]]; });
  std::string failure = "no robots";
  for (long attempt = 1;; ++attempt)
  {
    ReservationTable table = base;
    Paths paths(n);
    long failed = -1;
    bool timed_out = false;
    for (size_t k = 0; k < n && failed < 0; ++k)
    {
      const size_t i = order[k];
      ReservationTable with_starts = table;
      for (size_t j = k + 1; j < n; ++j)
        for (int t = 0; t <= (options.following ? 1 : 0); ++t) with_starts.reserveCell(starts[order[j]], t);
      paths[i] = h[i][starts[i]] < 0 ? std::vector<int>{}
                                     : sippPath(grid, with_starts, starts[i], goals[i], h[i], deadline, &timed_out);
      if (paths[i].empty())
        failed = static_cast<long>(i);
      else
        table.reservePath(paths[i]);
    }
    if (failed < 0) return paths;
    failure =
        "robot " + std::to_string(failed) + " found no path around the others" + (timed_out ? " (time limit)" : "");
    if (timed_out || Clock::now() > deadline || attempt > 64 || n == 1) break;
    order.erase(std::find(order.begin(), order.end(), static_cast<size_t>(failed)));
    order.insert(order.begin(), static_cast<size_t>(failed));
  }
  if (why) *why = failure;
  return {};
}

}  // namespace mbot_coordination
