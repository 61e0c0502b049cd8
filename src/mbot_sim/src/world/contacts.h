/**
 * @file contacts.h
 * @brief (private to the world) Collisions: the contact joints of a physics step and the
 *        contact events (a pair of bodies starts touching), and overlap queries (would this
 *        outline overlap a body?) for placing bodies.
 */
#pragma once

#include "bodies.h"

namespace mbot_sim
{
namespace detail
{
/// Makes the contact joints of a step and reports pairs of bodies that start touching. A pair
/// counts as separated only after it has not touched for `release_steps` steps.
class ContactTracker
{
public:
  /// @param world, group where contact joints go (not owned)
  ContactTracker(dWorldID world, dJointGroupID group);

  /// Before collision detection: forget the last step's touching pairs.
  void beginStep() { hits_.clear(); }
  /// Contacts among the geoms of `space` (robots and moving obstacles).
  void collideWithin(dSpaceID space);
  /// Contacts of `geom` (a robot) with the geoms of `space` (walls and static obstacles).
  void collideWith(dGeomID geom, dSpaceID space);
  /// After the step: a ContactEvent to the listener (if any) for every pair that began touching.
  void report(long long step, long long release_steps, double now, SensorListener* listener);
  /// Forget every touching pair (after a reset): a pair still touching is reported again.
  void clear() { active_pairs_.clear(); }

private:
  static void nearCallback(void* data, dGeomID a, dGeomID b);
  void collide(dGeomID a, dGeomID b);

  struct Hit
  {
    uint64_t key;
    const BodyTag* a;
    const BodyTag* b;
    double x, y;
  };
  struct ActivePair
  {
    uint64_t key;
    long long last_step;
  };
  dWorldID world_;
  dJointGroupID group_;
  // reused every step (no allocation once warm)
  std::vector<Hit> hits_;
  std::vector<ActivePair> active_pairs_, merged_pairs_;
};

/// The first body in `space` whose geom overlaps `query` by more than the margins the geoms
/// were grown by (nullptr: none). `exclude` is never found.
/// @param query_margin [m] how much the query geom is grown
/// @param robot_margin [m] how much robot geoms are grown
const BodyTag* firstOverlap(dGeomID query, dSpaceID space, const BodyTag* exclude, double query_margin,
                            double robot_margin);

}  // namespace detail
}  // namespace mbot_sim
