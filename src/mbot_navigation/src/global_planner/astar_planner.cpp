#include "mbot_navigation/global_planner/astar_planner.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <limits>
#include <stdexcept>

namespace mbot_navigation
{
namespace
{
constexpr float kInf = std::numeric_limits<float>::infinity();
constexpr double kSqrt2 = 1.4142135623730951;

// Neighbour k: dx, dy. 0..3 straight, 4..7 diagonal.
constexpr int kDx[8] = {1, -1, 0, 0, 1, -1, 1, -1};
constexpr int kDy[8] = {0, 0, 1, -1, 1, 1, -1, -1};

std::string fmtPoint(double x, double y)
{
  char buf[64];
  std::snprintf(buf, sizeof(buf), "(%.2f, %.2f)", x, y);
  return buf;
}

}  // namespace

void AStarPlanner::OpenList::configure(double width, double span)
{
  inv_width_ = static_cast<float>(1.0 / width);
  size_t n = 2;
  while (static_cast<double>(n) < span / width + 3.0) n *= 2;
  buckets_.clear();  // also drops cells left from the last search
  buckets_.resize(n);
  mask_ = n - 1;
  low_ = high_ = 0;
}

void AStarPlanner::OpenList::reset(float f, uint32_t index)
{
  // Only [low_, high_] can hold anything; clear() keeps each bucket's capacity.
  for (uint64_t b = low_; b <= high_; ++b)
  {
    buckets_[b & mask_].cells.clear();
    buckets_[b & mask_].head = 0;
  }
  low_ = high_ = static_cast<uint64_t>(f * inv_width_);
  buckets_[low_ & mask_].cells.push_back(index);
}

AStarPlanner::AStarPlanner(const AStarConfig& config) : config_(config)
{
  if (!(config.neutral_cost > 0.0)) throw std::invalid_argument("AStarConfig: 'neutral_cost' must be > 0");
  if (!(config.cost_factor >= 0.0)) throw std::invalid_argument("AStarConfig: 'cost_factor' must be >= 0");
  if (!(config.heuristic_weight >= 1.0)) throw std::invalid_argument("AStarConfig: 'heuristic_weight' must be >= 1");
  if (!(config.smoothing_tolerance >= 0.0))
    throw std::invalid_argument("AStarConfig: 'smoothing_tolerance' must be >= 0");
  if (config.smoothing_passes < 1) throw std::invalid_argument("AStarConfig: 'smoothing_passes' must be >= 1");
  for (int c = 0; c < 256; ++c)
  {
    const bool passable = c < cost::INSCRIBED || (c == cost::NO_INFORMATION && config.allow_unknown);
    weight_[c] = passable ? static_cast<float>(config.neutral_cost + config.cost_factor * c) : kInf;
  }
}

void AStarPlanner::prepare(const Costmap2D& costmap)
{
  if (costmap.sizeX() == size_x_ && costmap.sizeY() == size_y_ && !nodes_.empty()) return;
  size_x_ = costmap.sizeX();
  size_y_ = costmap.sizeY();
  const size_t n = static_cast<size_t>(size_x_) * size_y_;
  nodes_.assign(n, Node{0, 0.0f});
  generation_ = 0;
  for (int k = 0; k < 8; ++k) offset_[k] = kDy[k] * static_cast<int>(size_x_) + kDx[k];
  // Span of f in the open list: one step (the dearest diagonal step plus the heuristic's change)
  // and, for weighted A*, the (weight - 1) * h by which f can fall below the start's f.
  float max_weight = 0.0f;
  for (float w : weight_)
    if (w != kInf) max_weight = std::max(max_weight, w);
  const double w = config_.heuristic_weight, c = config_.neutral_cost;
  const double span = kSqrt2 * (max_weight + w * c) + c + (w - 1.0) * c * (size_x_ + size_y_);
  open_.configure(c / 8.0, span);
}

PlanResult AStarPlanner::makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal)
{
  PlanResult result;
  stats_ = AStarStats();
  grid_path_.clear();
  vertices_.clear();

  if (!std::isfinite(start.x) || !std::isfinite(start.y) || !std::isfinite(start.theta))
  {
    result.error = "start pose is not finite (NaN or Inf)";
    return result;
  }
  if (!std::isfinite(goal.x) || !std::isfinite(goal.y) || !std::isfinite(goal.theta))
  {
    result.error = "goal pose is not finite (NaN or Inf)";
    return result;
  }
  if (costmap.sizeX() == 0 || costmap.sizeY() == 0)
  {
    result.error = "the costmap is empty";
    return result;
  }
  if (static_cast<uint64_t>(costmap.sizeX()) * costmap.sizeY() >= (1ull << 32))
  {
    result.error = "the costmap has more than 2^32 cells";
    return result;
  }

  // Start and goal cells: inside the map, not in an obstacle.
  unsigned cell[2][2];
  const Pose2D* ends[2] = {&start, &goal};
  const char* what[2] = {"start", "goal"};
  for (int i = 0; i < 2; ++i)
  {
    const Pose2D& p = *ends[i];
    if (!costmap.worldToMap(p.x, p.y, cell[i][0], cell[i][1]))
    {
      result.error = std::string(what[i]) + " " + fmtPoint(p.x, p.y) + " is outside the map (x " +
                     fmtPoint(costmap.originX(), costmap.originX() + costmap.sizeX() * costmap.resolution()) + ", y " +
                     fmtPoint(costmap.originY(), costmap.originY() + costmap.sizeY() * costmap.resolution()) + ")";
      return result;
    }
    const uint8_t c = costmap.cost(cell[i][0], cell[i][1]);
    if (weight_[c] == kInf)
    {
      std::string why = c == cost::LETHAL      ? "is in an obstacle"
                        : c == cost::INSCRIBED ? "is too close to an obstacle"
                                               : "is in unknown space and allow_unknown is false";
      result.error = std::string(what[i]) + " " + fmtPoint(p.x, p.y) + " " + why + " (cost " +
                     std::to_string(static_cast<int>(c)) + ")";
      return result;
    }
  }

  prepare(costmap);
  const uint32_t s = static_cast<uint32_t>(costmap.index(cell[0][0], cell[0][1]));
  const uint32_t g = static_cast<uint32_t>(costmap.index(cell[1][0], cell[1][1]));
  if (!search(costmap.data(), s, g))
  {
    result.error = "goal " + fmtPoint(goal.x, goal.y) + " unreachable from start " + fmtPoint(start.x, start.y) +
                   ": searched " + std::to_string(stats_.expanded) + " cells";
    return result;
  }

  if (config_.smooth_path)
    smooth(costmap.data());
  else
    vertices_ = grid_path_;
  if (vertices_.size() == 1) vertices_.push_back(vertices_.front());  // start and goal in one cell

  // Poses at most one cell apart along the vertices; the ends are the exact start and goal.
  const double res = costmap.resolution();
  auto centre = [&](uint32_t idx, double& x, double& y) { costmap.mapToWorld(idx % size_x_, idx / size_x_, x, y); };
  std::vector<Pose2D>& path = result.path;
  path.reserve(static_cast<size_t>(stats_.grid_path_length) + 2);
  double px = start.x, py = start.y;
  for (size_t i = 1; i < vertices_.size(); ++i)
  {
    double qx, qy;
    if (i + 1 == vertices_.size())
    {
      qx = goal.x;
      qy = goal.y;
    }
    else
    {
      centre(vertices_[i], qx, qy);
    }
    const double len = std::hypot(qx - px, qy - py);
    const double theta = std::atan2(qy - py, qx - px);
    const int n = std::max(1, static_cast<int>(std::ceil(len / res - 1e-9)));
    for (int k = 0; k < n; ++k)
    {
      const double t = static_cast<double>(k) / n;
      path.push_back(Pose2D{px + t * (qx - px), py + t * (qy - py), theta});
    }
    stats_.path_length += len / res;
    px = qx;
    py = qy;
  }
  path.push_back(Pose2D{goal.x, goal.y, goal.theta});
  result.ok = true;
  return result;
}

bool AStarPlanner::search(const uint8_t* costs, uint32_t start, uint32_t goal)
{
  // New generation; on wrap-around (after ~2^29 queries) clear the stamps once.
  if (generation_ >= (std::numeric_limits<uint32_t>::max() >> 3) - 1)
  {
    for (Node& n : nodes_) n.stamp = 0;
    generation_ = 0;
  }
  ++generation_;
  const uint32_t seen = generation_ << 3;  // stamp >= seen: the cell's g is from this query

  const int W = static_cast<int>(size_x_), H = static_cast<int>(size_y_);
  const double inv_size_x = 1.0 / size_x_;
  const int gx = static_cast<int>(goal % size_x_), gy = static_cast<int>(goal / size_x_);
  const float h_straight = static_cast<float>(config_.neutral_cost * config_.heuristic_weight);
  const float h_diag = static_cast<float>(config_.neutral_cost * config_.heuristic_weight * (kSqrt2 - 1.0));
  // Octile distance to the goal times neutral_cost (times the weight).
  auto heuristic = [&](int x, int y) {
    const int dx = std::abs(x - gx), dy = std::abs(y - gy);
    return h_straight * static_cast<float>(std::max(dx, dy)) + h_diag * static_cast<float>(std::min(dx, dy));
  };

  Node* const nodes = nodes_.data();
  nodes[start] = Node{seen, 0.0f};
  open_.reset(heuristic(static_cast<int>(start % size_x_), static_cast<int>(start / size_x_)), start);

  const float diag = static_cast<float>(kSqrt2);
  size_t expanded = 0;
  bool found = false;
  uint32_t idx;
  while (open_.pop(idx))
  {
    Node& cur = nodes[idx];
    if (std::signbit(cur.g)) continue;  // closed: an outdated duplicate (lazy decrease-key)
    const float g = cur.g;
    cur.g = -g;  // close it (see Node)
    ++expanded;
    if (idx == goal)
    {
      found = true;
      break;
    }
    // x, y of idx without an integer division (slow): the double product is exact but for
    // rounding just below a whole row, which the check corrects.
    int y = static_cast<int>(static_cast<double>(idx) * inv_size_x);
    int x = static_cast<int>(idx) - y * W;
    if (x >= W)
    {
      x -= W;
      ++y;
    }

    // Relax neighbour n (at x + dx, y + dy) entered by neighbour step k of cost `step_cost`: keep
    // the better g and queue the cell. A closed cell has g < 0, so ng >= g rejects it too.
    auto relax = [&](uint32_t n, float step_cost, int dx, int dy, uint32_t k) {
      Node& nb = nodes[n];
      const float ng = g + step_cost;
      if (nb.stamp >= seen && ng >= nb.g) return;
      nb.stamp = seen | k;
      nb.g = ng;
      open_.push(ng + heuristic(x + dx, y + dy), n);
    };

    // Weights of the 8 neighbours (order of kDx/kDy). Only the outer ring of cells needs bounds
    // checks: the neighbours of an interior cell are always inside. (Unsigned: x - 1 < W - 2
    // is 0 < x < W - 1 in one test.)
    float w[8];
    if (static_cast<unsigned>(x - 1) < static_cast<unsigned>(W - 2) &&
        static_cast<unsigned>(y - 1) < static_cast<unsigned>(H - 2))
    {
      for (int k = 0; k < 8; ++k) w[k] = weight_[costs[idx + offset_[k]]];
    }
    else
    {
      for (int k = 0; k < 8; ++k)
      {
        const int nx = x + kDx[k], ny = y + kDy[k];
        w[k] = (nx < 0 || ny < 0 || nx >= W || ny >= H) ? kInf : weight_[costs[idx + offset_[k]]];
      }
    }
    // (w < kInf rather than w != kInf: one branch, no NaN check.)
    const bool east = w[0] < kInf, west = w[1] < kInf, north = w[2] < kInf, south = w[3] < kInf;
    if (east) relax(idx + offset_[0], w[0], 1, 0, 0);
    if (west) relax(idx + offset_[1], w[1], -1, 0, 1);
    if (north) relax(idx + offset_[2], w[2], 0, 1, 2);
    if (south) relax(idx + offset_[3], w[3], 0, -1, 3);
    // No corner cutting: a diagonal step needs both cells beside it passable, so that the segment
    // (which touches them at the corner) stays on passable cells.
    if (east && north && w[4] < kInf) relax(idx + offset_[4], w[4] * diag, 1, 1, 4);
    if (west && north && w[5] < kInf) relax(idx + offset_[5], w[5] * diag, -1, 1, 5);
    if (east && south && w[6] < kInf) relax(idx + offset_[6], w[6] * diag, 1, -1, 6);
    if (west && south && w[7] < kInf) relax(idx + offset_[7], w[7] * diag, -1, -1, 7);
  }
  stats_.expanded = expanded;
  if (!found) return false;

  // Walk the parents back from the goal.
  for (uint32_t c = goal;; c -= offset_[nodes[c].stamp & 7u])
  {
    grid_path_.push_back(c);
    if (c == start) break;
  }
  std::reverse(grid_path_.begin(), grid_path_.end());
  stats_.grid_path_cells = grid_path_.size();
  stats_.grid_path_cost = costTo(goal);
  stats_.grid_path_length = polylineLength(grid_path_);
  return true;
}

namespace
{
/**
 * Walk every cell that the segment between the centres of cells a and b passes through (exact
 * grid traversal after Amanatides & Woo, in integers), calling visit(cell index, weight, t0, t1)
 * with the part [t0, t1] of the segment (t in 0..T) inside that cell. Where the segment passes
 * exactly through a cell corner, the two cells beside it are touched too and must be passable.
 * @return false (early) at the first impassable cell; T through `T_out`
 */
template <class Visit>
bool traverse(const float* weight, const uint8_t* costs, unsigned size_x, uint32_t a, uint32_t b, int64_t& T_out,
              Visit visit)
{
  int x = static_cast<int>(a % size_x), y = static_cast<int>(a / size_x);
  const int bx = static_cast<int>(b % size_x), by = static_cast<int>(b / size_x);
  const int sx = bx > x ? 1 : -1, sy = by > y ? 1 : -1;
  const int64_t A = std::abs(bx - x), B = std::abs(by - y);
  const int64_t A1 = std::max<int64_t>(A, 1), B1 = std::max<int64_t>(B, 1);
  // t along the segment is scaled by T = 2 * A1 * B1: the next vertical cell boundary is crossed
  // at tx, the next horizontal one at ty.
  const int64_t T = 2 * A1 * B1;
  T_out = T;
  const int64_t never = std::numeric_limits<int64_t>::max();
  int64_t tx = A > 0 ? B1 : never, ty = B > 0 ? A1 : never;
  const int64_t step_x = 2 * B1, step_y = 2 * A1;
  int64_t t = 0;
  const ptrdiff_t row = static_cast<ptrdiff_t>(size_x);
  while (true)
  {
    const size_t cell = static_cast<size_t>(y) * size_x + x;
    const float w = weight[costs[cell]];
    if (w == kInf) return false;
    const int64_t t_next = std::min(std::min(tx, ty), T);
    visit(static_cast<uint32_t>(cell), w, t, t_next);
    if (t_next >= T) return true;
    t = t_next;
    if (tx == ty)
    {
      if (weight[costs[cell + sx]] == kInf || weight[costs[cell + sy * row]] == kInf) return false;
      x += sx;
      y += sy;
      tx += step_x;
      ty += step_y;
    }
    else if (tx < ty)
    {
      x += sx;
      tx += step_x;
    }
    else
    {
      y += sy;
      ty += step_y;
    }
  }
}
}  // namespace

double AStarPlanner::lineCost(const uint8_t* costs, uint32_t a, uint32_t b, double& cell_sum) const
{
  double sum = 0.0;  // sum of weight * scaled length
  cell_sum = 0.0;    // map costs of the cells after a
  int64_t T = 1;
  const bool ok = traverse(weight_, costs, size_x_, a, b, T,
                           [&sum, &cell_sum, costs, a](uint32_t cell, float w, int64_t t0, int64_t t1) {
                             sum += static_cast<double>(w) * static_cast<double>(t1 - t0);
                             if (cell != a) cell_sum += costs[cell];
                           });
  if (!ok) return -1.0;
  const double dx = static_cast<double>(a % size_x_) - static_cast<double>(b % size_x_);
  const double dy = static_cast<double>(a / size_x_) - static_cast<double>(b / size_x_);
  return sum / static_cast<double>(T) * std::sqrt(dx * dx + dy * dy);
}

bool AStarPlanner::shortcutOk(const uint8_t* costs, size_t i, size_t j) const
{
  double cell_sum = 0.0;
  const double line = lineCost(costs, dense_[i], dense_[j], cell_sum);
  // Cost-aware line of sight: passable, within the tolerance of the planner's cost, and no dearer
  // in map costs than the cells it replaces (the planner's cost alone would let a shorter segment
  // cut through the inflation zone, which is what makes a path brush the walls).
  return line >= 0.0 && line <= (cum_[j] - cum_[i]) * (1.0 + config_.smoothing_tolerance) + 1e-6 &&
         cell_sum <= cell_cum_[j] - cell_cum_[i];
}

void AStarPlanner::greedyPass(const uint8_t* costs)
{
  // From each kept cell, jump to the farthest later cell that passes shortcutOk(): double the
  // jump until one fails, then bisect between the last success and that failure.
  const size_t n = dense_.size();
  pick_.clear();
  pick_.push_back(0);
  size_t a = 0;
  while (a + 1 < n)
  {
    size_t good = a + 1;  // a neighbouring cell is always reachable
    size_t bad = n;       // n: no failure seen
    for (size_t step = 2;; step *= 2)
    {
      const size_t j = std::min(a + step, n - 1);
      if (j <= good) break;
      if (!shortcutOk(costs, a, j))
      {
        bad = j;
        break;
      }
      good = j;
      if (j == n - 1) break;
    }
    while (bad != n && bad - good > 1)
    {
      const size_t mid = good + (bad - good) / 2;
      if (shortcutOk(costs, a, mid))
        good = mid;
      else
        bad = mid;
    }
    pick_.push_back(good);
    a = good;
  }
}

void AStarPlanner::rasterize(const uint8_t* costs)
{
  // The cells the polyline through the picked cells passes, with the cost from the start.
  next_dense_.clear();
  next_cum_.clear();
  next_cell_cum_.clear();
  next_dense_.push_back(dense_[pick_[0]]);
  next_cum_.push_back(0.0);
  next_cell_cum_.push_back(0.0);
  for (size_t k = 1; k < pick_.size(); ++k)
  {
    const uint32_t a = dense_[pick_[k - 1]], b = dense_[pick_[k]];
    const double dx = static_cast<double>(a % size_x_) - static_cast<double>(b % size_x_);
    const double dy = static_cast<double>(a / size_x_) - static_cast<double>(b / size_x_);
    const double length = std::sqrt(dx * dx + dy * dy);
    int64_t T = 1;
    double c = next_cum_.back(), cells = next_cell_cum_.back();
    bool first = true;
    traverse(weight_, costs, size_x_, a, b, T, [&](uint32_t cell, float w, int64_t t0, int64_t t1) {
      // Cost of a cell = its weight times the length inside it, counted when it is entered.
      c += static_cast<double>(w) * static_cast<double>(t1 - t0) / static_cast<double>(T) * length;
      if (first)
      {
        first = false;  // cell a is already in the list
        return;
      }
      cells += costs[cell];
      next_dense_.push_back(cell);
      next_cum_.push_back(c);
      next_cell_cum_.push_back(cells);
    });
  }
  dense_.swap(next_dense_);
  cum_.swap(next_cum_);
  cell_cum_.swap(next_cell_cum_);
}

double AStarPlanner::polylineLength(const std::vector<uint32_t>& cells) const
{
  double len = 0.0;
  for (size_t i = 1; i < cells.size(); ++i)
  {
    const double dx = static_cast<double>(cells[i] % size_x_) - static_cast<double>(cells[i - 1] % size_x_);
    const double dy = static_cast<double>(cells[i] / size_x_) - static_cast<double>(cells[i - 1] / size_x_);
    len += std::sqrt(dx * dx + dy * dy);
  }
  return len;
}

void AStarPlanner::smooth(const uint8_t* costs)
{
  dense_.assign(grid_path_.begin(), grid_path_.end());
  cum_.resize(grid_path_.size());
  cell_cum_.resize(grid_path_.size());
  for (size_t i = 0; i < grid_path_.size(); ++i)
  {
    cum_[i] = costTo(grid_path_[i]);
    cell_cum_[i] = i == 0 ? 0.0 : cell_cum_[i - 1] + costs[grid_path_[i]];
  }
  vertices_ = grid_path_;
  double best = stats_.grid_path_length;
  // Each pass pulls the string tighter: the next pass may pick cells along the previous pass's
  // segments, which moves a vertex toward the obstacle corner that holds it. The first pass only
  // replaces grid-path pieces by straight segments, so it is never longer than the grid path;
  // the later ones pick cell centres near (not on) the previous segments, so a pass is kept only
  // when it is shorter.
  for (int pass = 0; pass < config_.smoothing_passes; ++pass)
  {
    greedyPass(costs);
    candidate_.clear();
    for (size_t k : pick_) candidate_.push_back(dense_[k]);
    const double len = polylineLength(candidate_);
    if (len >= best - 1e-9) break;
    best = len;
    vertices_.swap(candidate_);
    if (vertices_.size() <= 2 || pass + 1 == config_.smoothing_passes) break;
    rasterize(costs);
  }
}

}  // namespace mbot_navigation
