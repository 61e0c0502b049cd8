/**
 * @file astar_planner.h
 * @brief Cost-aware 8-connected A* over a Costmap2D, followed by line-of-sight smoothing.
 *
 * Cost model (global_planner's): entering a cell with cost c by a step of length s [cells] costs
 *   s * (neutral_cost + cost_factor * c);
 * cells with c >= INSCRIBED (253) are impassable, except NO_INFORMATION (255) when allow_unknown.
 * A diagonal step also needs both cells beside it passable (no corner cutting), so the straight
 * segment between two cell centres of the path never touches an impassable cell.
 *
 * Heuristic: the octile distance times neutral_cost, the least any step can cost, so it never
 * overestimates (admissible and consistent) and heuristic_weight = 1 gives the optimal grid
 * path. heuristic_weight w > 1 is weighted A*: far fewer cells searched, path cost at most w times
 * the optimum. That bound is loose where it matters: w's slack goes into the cheapest thing to
 * give up, clearance, so a weighted path hugs the inflation zone unless cells near obstacles are
 * dear. With global_planner's cost_factor 3 they are: on the shared benchmark maps (plan_bench,
 * 1000^2 and 2000^2) w = 1.2 keeps the mean path cost (map costs of the cells the path passes)
 * at 64 and 159, against 54 and 90 for w = 1 and 518 and 1317 for w = 1.5, while it searches 3.5
 * (1000^2) to 6 (2000^2) times fewer cells than w = 1 at p95. With navfn's cost_factor 0.8 the
 * same w = 1.2 paths cost 806 and 1970 (w = 1: 184 and 339). (These figures depend on the open
 * list's first-in first-out order within a bucket, see OpenList.)
 *
 * Smoothing (string pulling, a cost-aware line of sight): from each kept vertex the path jumps to
 * the farthest later cell it can reach in a straight line whose cells (every cell the segment
 * touches) are all passable, whose cost integral is at most (1 + smoothing_tolerance) times that
 * of the path it replaces, and whose cells' map costs add up to no more than those of the cells
 * it replaces. The last condition keeps shortcuts out of the inflation zone: the planner's cost
 * alone trades clearance for length (50 + 3 c per cell), so a shortcut through cells of cost 100
 * could still "pay", and the path would brush the walls (plan_bench, w = 1.2, tolerance 0: mean
 * path cost 2877 and 6764 with cost_factor 0.8 and without this rule, 62 and 150 with both).
 * A later pass runs again over the cells of the previous pass's polyline, pulling each vertex
 * toward the obstacle corner that holds it; on the bench maps that shortens the path by only
 * 0.1 %, so the default is one pass. The result is never longer than the grid path.
 *
 * Speed: one 8-byte record per cell (Node: generation stamp + parent step, and g), sized once per
 * map size; the stamp says whether g belongs to the current query, so nothing is cleared between
 * queries, and a closed cell is marked by g's sign bit, so relaxing a neighbour is one stamp test
 * and one g test; the open list is a bucket queue on f (O(1) push and pop, see OpenList) in reused
 * vectors; neighbour offsets are precomputed and only the 1-cell outer ring of the grid is
 * expanded with bounds checks. All buffers are reused, so once they have grown nothing is
 * allocated per query but the returned path. Nearly all the time goes into the search, and in
 * the slow queries into cells expanded inside "heuristic depressions": the heuristic ignores
 * inflation costs, so narrow (inflated, dear) passages make A* flood the free space before them.
 * That is what the heuristic weight trades against path length.
 */
#pragma once

#include <cmath>
#include <cstdint>
#include <string>
#include <vector>

#include "mbot_navigation/costmap/costmap_2d.h"
#include "mbot_navigation/global_planner/global_planner.h"

namespace mbot_navigation
{
/// @brief A* settings (names as global_planner's where they exist).
struct AStarConfig
{
  /// Cost of a 1-cell step over a free cell [cost units] (global_planner ~neutral_cost).
  double neutral_cost = 50.0;
  /// Weight of a cell's cost value in a step [cost units per cost value] (global_planner
  /// ~cost_factor, 3.0 as there; navfn's COST_FACTOR 0.8 lets weighted A* hug the inflation zone,
  /// see the file comment).
  double cost_factor = 3.0;
  /// NO_INFORMATION cells are passable, at cost value 255 (global_planner ~allow_unknown).
  bool allow_unknown = true;
  /// >= 1: 1 = optimal A*, more = weighted A* (fewer cells searched, longer paths; see the file
  /// comment for why 1.2).
  double heuristic_weight = 1.2;
  /// Shorten the grid path by line-of-sight string pulling.
  bool smooth_path = true;
  /// A shortcut may cost this fraction more than the path piece it replaces, in the planner's
  /// cost [-] (its cells' map costs may never add up to more).
  double smoothing_tolerance = 0.0;
  /// String-pulling passes; each tightens the previous one (>= 1).
  int smoothing_passes = 1;
};

/// @brief Figures about the last makePlan() call (for benches and tests).
struct AStarStats
{
  size_t expanded = 0;            ///< cells taken off the open list
  size_t grid_path_cells = 0;     ///< cells in the 8-connected grid path
  double grid_path_length = 0.0;  ///< [cells] length of the grid path
  double path_length = 0.0;       ///< [cells] length of the returned (smoothed) path
  double grid_path_cost = 0.0;    ///< [cost units] cost of the grid path
};

/// @brief 8-connected cost-aware A* + line-of-sight smoothing (see the file comment).
class AStarPlanner : public GlobalPlanner
{
public:
  explicit AStarPlanner(const AStarConfig& config = AStarConfig());

  /**
   * @brief Plan from start to goal [m, m, rad]. The path holds poses at most one cell apart, each
   *        facing along the path, the first at the start and the last at the goal with the goal's
   *        orientation. (Segments are checked between cell centres; the first and last segment
   *        end at the exact start and goal instead, within half a cell of those centres.)
   *        On failure `error` says why (outside the map, in an obstacle, no path, NaN).
   */
  PlanResult makePlan(const Costmap2D& costmap, const Pose2D& start, const Pose2D& goal) override;
  std::string name() const override { return "astar"; }

  const AStarConfig& config() const { return config_; }
  const AStarStats& lastStats() const { return stats_; }
  /// @brief The last grid path (before smoothing) as cell indices, start first.
  const std::vector<uint32_t>& lastGridPath() const { return grid_path_; }
  /// @brief The last path's vertices (after smoothing) as cell indices, start first.
  const std::vector<uint32_t>& lastVertices() const { return vertices_; }

private:
  /**
   * Per-cell search state, 8 bytes so that a cell's whole state is one load. `stamp` is
   * generation << 3 | the neighbour step (0..7) that reached the cell: stamp >= the current
   * generation << 3 means `g` belongs to the current query (older queries' stamps are smaller), so
   * nothing is cleared between queries. `g` is the cost from the start; its sign bit is set once
   * the cell is closed (expanded), so `new g >= g` rejects a closed cell without a separate test.
   */
  struct Node
  {
    uint32_t stamp;
    float g;
  };
  /// @brief g of a cell of this query (closed or not).
  float costTo(uint32_t index) const { return std::fabs(nodes_[index].g); }

  /// @brief Size the per-cell arrays for a grid (only when the size changes).
  void prepare(const Costmap2D& costmap);
  /// @brief The A* search; false when the goal is unreachable. Fills grid_path_.
  bool search(const uint8_t* costs, uint32_t start, uint32_t goal);
  /// @brief String pulling over grid_path_ into vertices_ (smoothing_passes greedy passes).
  void smooth(const uint8_t* costs);
  /// @brief One greedy pass over dense_: the picked indices into pick_.
  void greedyPass(const uint8_t* costs);
  /// @brief Replace dense_/cum_ by the cells of the polyline through the picked cells.
  void rasterize(const uint8_t* costs);
  /// @brief May the path go straight from dense_[i] to dense_[j] (passable, cost within tolerance)?
  bool shortcutOk(const uint8_t* costs, size_t i, size_t j) const;
  /// @brief Length of the polyline through the centres of `cells` [cells].
  double polylineLength(const std::vector<uint32_t>& cells) const;
  /**
   * @brief Walk the cells that the segment between the centres of cells a and b touches.
   * @param cell_sum the sum of the map costs of the cells it passes through, a's excepted
   * @return the segment's cost integral [cost units], or a negative value when a cell is impassable
   */
  double lineCost(const uint8_t* costs, uint32_t a, uint32_t b, double& cell_sum) const;

  AStarConfig config_;
  float weight_[256];  ///< neutral_cost + cost_factor * c per cost value; +inf if impassable
  unsigned size_x_ = 0, size_y_ = 0;
  int offset_[8];  ///< index offsets of the 8 neighbours
  uint32_t generation_ = 0;
  std::vector<Node> nodes_;
  /**
   * @brief The open list: a bucket queue on f. Bucket b holds the cells with f in
   *        [b * width, (b + 1) * width); a ring of buckets covers the span of f values the open
   *        list can hold at once, so push and pop are O(1) instead of a heap's O(log n). Within a
   *        bucket the first pushed comes first: that is closer to exact f order than last-in
   *        first-out, and on the bench maps gives ~0.3 % shorter paths for about as many cells
   *        searched (which is what lets the default heuristic_weight be 1.2). With width =
   *        neutral_cost / 8 the order differs from exact f order by at most 1/8 of a free cell
   *        step, so the path cost is at most that above the A* optimum.
   */
  class OpenList
  {
  public:
    /// @brief Size the ring for f values spread over `span` [cost units] in buckets `width` wide.
    void configure(double width, double span);
    /// @brief Empty the queue and queue the first cell: its f is where the ring starts.
    void reset(float f, uint32_t index);
    void push(float f, uint32_t index)
    {
      uint64_t b = static_cast<uint64_t>(f * inv_width_);  // float: exact enough, and fast
      if (b < low_)
      {
        // Weighted A* can push an f below every queued one. The ring is sized for the widest
        // spread (configure()); clamping only guards against wrapping onto the other end.
        if (high_ - b > mask_) b = high_ - mask_;
        low_ = b;
      }
      else if (b > high_)
      {
        if (b - low_ > mask_) b = low_ + mask_;
        high_ = b;
      }
      buckets_[b & mask_].cells.push_back(index);
    }
    /// @brief Take the first queued cell of the lowest bucket into `index`; false when empty.
    bool pop(uint32_t& index)
    {
      while (true)
      {
        Bucket& b = buckets_[low_ & mask_];
        if (b.head < b.cells.size())
        {
          index = b.cells[b.head++];
          if (b.head == b.cells.size())  // all taken: rewind (keeps the capacity)
          {
            b.cells.clear();
            b.head = 0;
          }
          return true;
        }
        if (low_ == high_) return false;  // [low_, high_] is all empty
        ++low_;
      }
    }

  private:
    /// Cells in push order; the ones before `head` are taken already.
    struct Bucket
    {
      std::vector<uint32_t> cells;
      size_t head = 0;
    };
    std::vector<Bucket> buckets_;  ///< reused: no allocation once warm
    uint64_t mask_ = 0;            ///< ring size - 1 (a power of two)
    uint64_t low_ = 0;             ///< no queued cell is in a bucket below this one
    uint64_t high_ = 0;            ///< nor above this one
    float inv_width_ = 1.0f;
  };
  OpenList open_;
  std::vector<uint32_t> grid_path_;
  std::vector<uint32_t> vertices_;
  // Smoothing buffers (reused): the current path as the cells it passes, the cost from the start
  // to each [cost units] and the sum of the map costs of the cells up to each, the cells a pass
  // picks, and the next pass's path.
  std::vector<uint32_t> dense_, next_dense_;
  std::vector<double> cum_, next_cum_;
  std::vector<double> cell_cum_, next_cell_cum_;
  std::vector<size_t> pick_;
  std::vector<uint32_t> candidate_;
  AStarStats stats_;
};

}  // namespace mbot_navigation
