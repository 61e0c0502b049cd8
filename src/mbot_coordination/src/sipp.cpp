#include "mbot_coordination/sipp.h"

#include <algorithm>
#include <queue>
#include <stdexcept>
#include <unordered_map>

namespace mbot_coordination
{
ReservationTable::ReservationTable(int cells, bool following)
    : safe_(cells, std::vector<SafeInterval>{{0, kForever}}), following_(following)
{
  if (cells >= (1 << 21)) throw std::invalid_argument("ReservationTable: grid over 2^21 cells");
}

uint64_t ReservationTable::key(int from, int to, int t) const
{
  return (static_cast<uint64_t>(t) << 42) | (static_cast<uint64_t>(from) << 21) | static_cast<uint64_t>(to);
}

void ReservationTable::reserve(int cell, int t)
{
  auto& s = safe_[cell];
  for (size_t k = 0; k < s.size(); ++k)
    if (s[k].start <= t && t <= s[k].end)
    {
      const SafeInterval before{s[k].start, t - 1}, after{t + 1, s[k].end};
      s.erase(s.begin() + k);
      if (after.start <= after.end && t != kForever) s.insert(s.begin() + k, after);
      if (before.start <= before.end) s.insert(s.begin() + k, before);
      return;
    }
}

void ReservationTable::reserveFrom(int cell, int t)
{
  auto& s = safe_[cell];
  while (!s.empty() && s.back().start >= t) s.pop_back();
  if (!s.empty() && s.back().end >= t) s.back().end = t - 1;
}

void ReservationTable::reservePath(const std::vector<int>& path)
{
  if (path.empty()) return;
  const int last = static_cast<int>(path.size()) - 1;
  for (int t = 0; t < last; ++t)
  {
    reserve(path[t], t);
    if (following_)
    {
      if (t > 0) reserve(path[t], t - 1);
      reserve(path[t], t + 1);
    }
    if (path[t + 1] != path[t]) moves_.insert(key(path[t], path[t + 1], t + 1));
  }
  reserveFrom(path[last], following_ && last > 0 ? last - 1 : last);
}

bool ReservationTable::swapBlocked(int from, int to, int t) const { return moves_.count(key(to, from, t)) != 0; }

namespace
{
struct Node
{
  int cell;
  int interval;  // index into the cell's safe intervals
  int time;      // arrival time (the earliest found)
  int parent;    // index into the node list, -1 for the start
};
}  // namespace

std::vector<int> sippPath(const Grid& grid, const ReservationTable& table, int start, int goal,
                          const std::vector<int>& h, Clock::time_point deadline, bool* timed_out)
{
  if (timed_out) *timed_out = false;
  const auto& s0 = table.safeIntervals(start);
  if (s0.empty() || s0[0].start > 0 || h[start] < 0) return {};
  std::vector<Node> nodes{{start, 0, 0, -1}};
  // open: (f, -time, node); the earliest arrival per (cell, interval) wins
  using Entry = std::tuple<long, long, int>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<Entry>> open;
  std::unordered_map<uint64_t, int> best;
  const auto state = [](int cell, int interval) { return (static_cast<uint64_t>(cell) << 32) | interval; };
  open.emplace(h[start], 0, 0);
  best[state(start, 0)] = 0;
  long expansions = 0;
  while (!open.empty())
  {
    const int idx = std::get<2>(open.top());
    open.pop();
    const Node n = nodes[idx];
    if (best[state(n.cell, n.interval)] < n.time) continue;  // a stale entry
    if ((++expansions & 1023) == 0 && Clock::now() > deadline)
    {
      if (timed_out) *timed_out = true;
      return {};
    }
    const SafeInterval here = table.safeIntervals(n.cell)[n.interval];
    if (n.cell == goal && here.end == kForever)
    {
      std::vector<int> chain;
      for (int k = idx; k >= 0; k = nodes[k].parent) chain.push_back(k);
      std::reverse(chain.begin(), chain.end());
      std::vector<int> path{start};
      for (size_t k = 1; k < chain.size(); ++k)
      {
        const Node& m = nodes[chain[k]];
        while (static_cast<int>(path.size()) < m.time) path.push_back(path.back());  // wait
        path.push_back(m.cell);
      }
      return path;
    }
    // the latest departure is here.end, arriving one step later
    const long last_arrival = here.end == kForever ? static_cast<long>(kForever) : static_cast<long>(here.end) + 1;
    for (int u : grid.neighbours(n.cell))
    {
      if (h[u] < 0) continue;
      const auto& intervals = table.safeIntervals(u);
      for (size_t k = 0; k < intervals.size(); ++k)
      {
        const SafeInterval& iv = intervals[k];
        if (iv.end != kForever && iv.end < n.time + 1) continue;
        if (iv.start > last_arrival) break;
        long t = std::max<long>(n.time + 1, iv.start);
        const long latest = std::min<long>(iv.end, last_arrival);
        while (t <= latest && table.swapBlocked(n.cell, u, static_cast<int>(t))) ++t;
        if (t > latest) continue;
        const uint64_t st = state(u, static_cast<int>(k));
        auto it = best.find(st);
        if (it != best.end() && it->second <= t) continue;
        best[st] = static_cast<int>(t);
        nodes.push_back({u, static_cast<int>(k), static_cast<int>(t), idx});
        open.emplace(t + h[u], -t, static_cast<int>(nodes.size()) - 1);
      }
    }
  }
  return {};
}

}  // namespace mbot_coordination
