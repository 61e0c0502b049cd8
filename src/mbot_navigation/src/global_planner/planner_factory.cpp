#include "mbot_navigation/global_planner/planner_factory.h"

#include <stdexcept>

namespace mbot_navigation
{
std::vector<std::string> globalPlannerNames() { return {"astar", "ompl"}; }

std::unique_ptr<GlobalPlanner> makeGlobalPlanner(const std::string& name, const GlobalPlannerParams& params)
{
  if (name == "astar") return std::make_unique<AStarPlanner>(params.astar);
  if (name == "ompl") return std::make_unique<OmplPlanner>(params.ompl);
  std::string known;
  for (const std::string& n : globalPlannerNames()) known += (known.empty() ? "" : ", ") + n;
  throw std::invalid_argument("unknown global planner '" + name + "' (expected one of: " + known + ")");
}

}  // namespace mbot_navigation
