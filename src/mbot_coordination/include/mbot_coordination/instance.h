// A MAPF problem and its solution, with the checks every reported solution passes.
#pragma once

#include <string>
#include <vector>

#include "mbot_coordination/grid.h"
#include "mbot_coordination/movingai.h"

namespace mbot_coordination
{
struct Instance
{
  const Grid* grid = nullptr;
  std::vector<int> starts;  // vertex ids, one per agent
  std::vector<int> goals;
};

// The first `agents` rows of a scenario as an instance on `grid`; std::invalid_argument when the
// scenario has fewer rows.
Instance instanceFromScen(const Grid& grid, const std::vector<ScenRow>& rows, int agents);

// Throws std::invalid_argument naming the problem: no grid, sizes differ, a start or goal outside
// the grid or blocked, two agents with one start or one goal, a goal unreachable from its start.
void checkInstance(const Instance& instance);

// paths[i][t]: agent i's cell at time t (unit steps). After its last entry an agent stays there.
using Paths = std::vector<std::vector<int>>;

// "" when the paths solve the instance: one path per agent, starting at its start, ending at its
// goal, every step a wait or a move to a free 4-neighbour, no two agents in one cell at one time
// (agents stay at their goals after their paths end), no two agents swapping cells in one step.
// Otherwise the first problem found, e.g. "vertex conflict: agents 3 and 7 at (4,5) at t=12".
// following: also "following conflict: agent 2 enters (4,5) at t=9, left by agent 5 at t=9"
// (one agent in a cell one step after another was there).
std::string validate(const Instance& instance, const Paths& paths, bool following = false);

// An agent's cost: the time it reaches its goal for the last time (waiting there at the end is
// free). Sum of costs and makespan as in the MAPF literature.
int agentCost(const std::vector<int>& path);
long sumOfCosts(const Paths& paths);
int makespan(const Paths& paths);
// Sum of each agent's own shortest path length (4-connected): a lower bound on the sum of costs.
long lowerBound(const Instance& instance);

}  // namespace mbot_coordination
