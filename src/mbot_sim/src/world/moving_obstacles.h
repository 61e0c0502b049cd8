/**
 * @file moving_obstacles.h
 * @brief (private to the world) Moving obstacles: a blind one follows its route at its speed
 *        (Mover::moveTo); a walker (yielding > 0) walks from waypoint to waypoint and gives way
 *        to robots and other movers, social-force style, never walking into anyone or into a
 *        wall (planWalk).
 */
#pragma once

#include "bodies.h"

namespace mbot_sim
{
namespace detail
{
/// A body a walker keeps its distance from: the circle around its outline.
struct BodyCircle
{
  double x, y, radius;
  const Mover* mover;  ///< nullptr for a robot
};

/// The circles of every robot and mover at the start of a step (into `out`, reused).
void collectBodies(const std::vector<std::unique_ptr<Robot>>& robots, const std::vector<std::unique_ptr<Mover>>& movers,
                   std::vector<BodyCircle>& out);

/// A walker's velocity for this step (m.vx, m.vy), given the bodies around it and the static
/// space (walls and static obstacles) it must not enter.
void planWalk(Mover& m, const std::vector<BodyCircle>& bodies, dSpaceID static_space, double dt);

/// Put a mover's kinematic body at its pose, with its velocity.
void placeMover(Mover& m);

}  // namespace detail
}  // namespace mbot_sim
