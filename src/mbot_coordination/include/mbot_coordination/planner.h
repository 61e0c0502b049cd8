// One interface for the MAPF algorithms, picked by name (the live planner's parameter):
//   "pp"     prioritized planning with SIPP per agent, re-prioritised restarts (fast, incomplete)
//   "lacam"  LaCAM (complete: finds a solution when one exists, given the time)
//   "auto"   pp for part of the time limit, then lacam on what pp could not solve
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "mbot_coordination/instance.h"

namespace mbot_coordination
{
struct PlannerOptions
{
  double time_limit_s = 60.0;
  unsigned seed = 0;
  // auto: the share of the time limit pp gets before lacam takes over
  double pp_share = 0.25;
};

struct PlanResult
{
  bool solved = false;
  Paths paths;
  double runtime_s = 0.0;
  std::string algorithm;  // which algorithm produced the paths (auto: pp or lacam)
  std::string message;    // why it failed (time limit, no solution, ...)
  long attempts = 0;      // pp: orders tried; lacam: high-level nodes generated
};

class Planner
{
public:
  virtual ~Planner() = default;
  // checkInstance first (std::invalid_argument on bad input); then the search.
  virtual PlanResult solve(const Instance& instance, const PlannerOptions& options) = 0;
  virtual std::string name() const = 0;
};

// std::invalid_argument for an unknown name, listing the known ones.
std::unique_ptr<Planner> makePlanner(const std::string& name);
std::vector<std::string> plannerNames();

}  // namespace mbot_coordination
