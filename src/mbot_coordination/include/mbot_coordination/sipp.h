// Safe-interval path planning (SIPP, Phillips & Likhachev 2011) for one agent among agents whose
// paths are already fixed, and prioritized planning on top of it.
#pragma once

#include <chrono>
#include <cstdint>
#include <limits>
#include <unordered_set>
#include <vector>

#include "mbot_coordination/grid.h"

namespace mbot_coordination
{
constexpr int kForever = std::numeric_limits<int>::max();

// Time steps [start, end] (inclusive) in which a cell is free of the agents planned so far.
struct SafeInterval
{
  int start;
  int end;  // kForever: free from start on
};

// The fixed agents' paths as safe intervals per cell and their moves (for swap conflicts).
// following: also forbid following conflicts (entering a cell another agent was in one step
// before, or being in a cell another agent enters one step later): each path cell is reserved at
// t - 1, t and t + 1, so two agents keep at least one step between them in every cell.
class ReservationTable
{
public:
  explicit ReservationTable(int cells, bool following = false);
  // The agent occupies path[t] at time t and its last cell from then on.
  void reservePath(const std::vector<int>& path);
  // One cell at one time step (e.g. an agent not planned yet standing on its start at t = 0, 1).
  void reserveCell(int cell, int t) { reserve(cell, t); }
  bool following() const { return following_; }
  const std::vector<SafeInterval>& safeIntervals(int cell) const { return safe_[cell]; }
  // True when a fixed agent moves `to` -> `from` arriving at time t (moving from -> to then swaps).
  bool swapBlocked(int from, int to, int t) const;

private:
  void reserve(int cell, int t);
  void reserveFrom(int cell, int t);
  uint64_t key(int from, int to, int t) const;

  std::vector<std::vector<SafeInterval>> safe_;
  std::unordered_set<uint64_t> moves_;
  bool following_ = false;
};

using Clock = std::chrono::steady_clock;

// The earliest-arriving path from start to goal that stays at the goal forever and conflicts with
// no reservation; h: steps to the goal from every cell (Grid::distancesTo). Empty when there is
// none, or when the deadline passes (then *timed_out is set).
std::vector<int> sippPath(const Grid& grid, const ReservationTable& table, int start, int goal,
                          const std::vector<int>& h, Clock::time_point deadline, bool* timed_out = nullptr);

}  // namespace mbot_coordination
