/**
 * @file contacts.cpp
 * @brief Contact joints (frictionless, normals kept in the plane), contact events, and overlap
 *        queries. See contacts.h.
 */
#include "contacts.h"

#include <algorithm>
#include <cmath>
#include <utility>

namespace mbot_sim
{
namespace detail
{
ContactTracker::ContactTracker(dWorldID world, dJointGroupID group) : world_(world), group_(group)
{
  hits_.reserve(256);
  active_pairs_.reserve(256);
  merged_pairs_.reserve(256);
}

void ContactTracker::nearCallback(void* data, dGeomID a, dGeomID b)
{
  static_cast<ContactTracker*>(data)->collide(a, b);
}

void ContactTracker::collideWithin(dSpaceID space) { dSpaceCollide(space, this, &nearCallback); }

void ContactTracker::collideWith(dGeomID geom, dSpaceID space)
{
  dSpaceCollide2(geom, reinterpret_cast<dGeomID>(space), this, &nearCallback);
}

void ContactTracker::collide(dGeomID a, dGeomID b)
{
  dContactGeom contacts[kMaxContacts];
  const int n = dCollide(a, b, kMaxContacts, contacts, sizeof(dContactGeom));
  if (n == 0) return;
  const dBodyID body_a = dGeomGetBody(a), body_b = dGeomGetBody(b);
  for (int i = 0; i < n; ++i)
  {
    dContact contact;
    contact.surface.mode = 0;  // frictionless: bodies slide along walls
    contact.surface.mu = 0.0;
    contact.geom = contacts[i];
    // Keep the normal in the plane (bodies are on the ground).
    dReal* nrm = contact.geom.normal;
    const double len = std::hypot(nrm[0], nrm[1]);
    if (len < 1e-9) continue;
    nrm[0] /= len;
    nrm[1] /= len;
    nrm[2] = 0.0;
    const dJointID joint = dJointCreateContact(world_, group_, &contact);
    dJointAttach(joint, body_a, body_b);
  }
  const auto* ta = static_cast<const BodyTag*>(dGeomGetData(a));
  const auto* tb = static_cast<const BodyTag*>(dGeomGetData(b));
  if (ta->uid > tb->uid) std::swap(ta, tb);
  hits_.push_back(
      Hit{(static_cast<uint64_t>(ta->uid) << 32) | tb->uid, ta, tb, contacts[0].pos[0], contacts[0].pos[1]});
}

void ContactTracker::report(long long step, long long release_steps, double now, SensorListener* listener)
{
  // Merge this step's hits (sorted by pair) with the pairs touching recently (sorted too).
  std::sort(hits_.begin(), hits_.end(), [](const Hit& a, const Hit& b) { return a.key < b.key; });
  merged_pairs_.clear();
  size_t i = 0, j = 0;
  while (i < active_pairs_.size() || j < hits_.size())
  {
    if (j < hits_.size() && j > 0 && hits_[j].key == hits_[j - 1].key)
    {
      ++j;  // the same pair again (several geoms): counted once
      continue;
    }
    if (j >= hits_.size() || (i < active_pairs_.size() && active_pairs_[i].key < hits_[j].key))
    {
      if (step - active_pairs_[i].last_step < release_steps) merged_pairs_.push_back(active_pairs_[i]);
      ++i;
    }
    else if (i >= active_pairs_.size() || hits_[j].key < active_pairs_[i].key)
    {
      merged_pairs_.push_back(ActivePair{hits_[j].key, step});
      if (listener)
      {
        ContactEvent e;
        e.stamp = now;
        e.body_a = hits_[j].a->name;
        e.body_b = hits_[j].b->name;
        e.x = hits_[j].x;
        e.y = hits_[j].y;
        listener->onContact(e);
      }
      ++j;
    }
    else
    {
      merged_pairs_.push_back(ActivePair{hits_[j].key, step});
      ++i;
      ++j;
    }
  }
  std::swap(active_pairs_, merged_pairs_);
}

// ---- overlap queries (placement checks; no contact joints) ------------------------------------
namespace
{
struct OverlapQuery
{
  dGeomID query = nullptr;
  const BodyTag* exclude = nullptr;
  double query_margin = 0.0;
  double robot_margin = 0.0;
  const BodyTag* found = nullptr;
};

void overlapCallback(void* data, dGeomID a, dGeomID b)
{
  auto* q = static_cast<OverlapQuery*>(data);
  if (q->found) return;
  if (dGeomIsSpace(a) || dGeomIsSpace(b))
  {
    dSpaceCollide2(a, b, data, &overlapCallback);
    return;
  }
  const dGeomID other = a == q->query ? b : a;
  const auto* tag = static_cast<const BodyTag*>(dGeomGetData(other));
  if (!tag || tag == q->exclude) return;
  dContactGeom contacts[kMaxContacts];
  const int n = dCollide(q->query, other, kMaxContacts, contacts, sizeof(dContactGeom));
  // Geoms are grown by margins; only overlap beyond them is a real overlap of outlines.
  const double allowed = q->query_margin + (tag->kind == BodyTag::Kind::ROBOT ? q->robot_margin : 0.0) + 1e-6;
  for (int i = 0; i < n; ++i)
    if (contacts[i].depth > allowed)
    {
      q->found = tag;
      return;
    }
}
}  // namespace

const BodyTag* firstOverlap(dGeomID query, dSpaceID space, const BodyTag* exclude, double query_margin,
                            double robot_margin)
{
  OverlapQuery q;
  q.query = query;
  q.exclude = exclude;
  q.query_margin = query_margin;
  q.robot_margin = robot_margin;
  dSpaceCollide2(query, reinterpret_cast<dGeomID>(space), &q, &overlapCallback);
  return q.found;
}

}  // namespace detail
}  // namespace mbot_sim
