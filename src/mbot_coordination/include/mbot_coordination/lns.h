// Improving a solution by large neighbourhood search (as in MAPF-LNS, Li et al. 2021): free a few
// agents' paths, re-plan them one after another with SIPP around all the others' paths, keep the
// new paths when their sum of costs is lower. The solution stays valid at every step.
#pragma once

#include "mbot_coordination/instance.h"
#include "mbot_coordination/sipp.h"

namespace mbot_coordination
{
struct LnsStats
{
  long iterations = 0;
  long improvements = 0;
};

// `paths` must solve `instance`; it is changed only by improvements. Stops at the deadline or
// when the sum of costs reaches the lower bound, or after max_iterations (< 0: no limit).
// neighbourhood: agents re-planned at a time. following: keep the solution free of following
// conflicts too (it must be so already).
LnsStats refineLns(const Instance& instance, Paths& paths, Clock::time_point deadline, unsigned seed,
                   int neighbourhood = 8, long max_iterations = -1, bool following = false);

}  // namespace mbot_coordination
