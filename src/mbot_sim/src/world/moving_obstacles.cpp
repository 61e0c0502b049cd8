/**
 * @file moving_obstacles.cpp
 * @brief Moving obstacles along their routes, and walkers that give way. See moving_obstacles.h
 *        and WORLD_FORMAT.md ("How moving obstacles walk").
 */
#include "moving_obstacles.h"

#include "contacts.h"

#include <algorithm>
#include <cmath>

namespace mbot_sim
{
namespace detail
{
void Mover::moveTo(double t)
{
  const double length = cumulative.back();
  double d = std::fmod(config.speed * std::max(0.0, t - start_time), length);
  if (d < cumulative[segment]) segment = 0;
  while (segment + 2 < cumulative.size() && d > cumulative[segment + 1]) ++segment;
  const Point2D& a = route[segment];
  const Point2D& b = route[segment + 1];
  const double seg_len = cumulative[segment + 1] - cumulative[segment];
  const double ux = (b.x - a.x) / seg_len, uy = (b.y - a.y) / seg_len;
  d -= cumulative[segment];
  pose = Pose2D{a.x + ux * d, a.y + uy * d, std::atan2(uy, ux)};
  vx = ux * config.speed;
  vy = uy * config.speed;
}

void placeMover(Mover& m)
{
  dBodySetPosition(m.body.get(), m.pose.x, m.pose.y, kBodyZ);
  dQuaternion q = {std::cos(m.pose.theta / 2.0), 0.0, 0.0, std::sin(m.pose.theta / 2.0)};
  dBodySetQuaternion(m.body.get(), q);
  dBodySetLinearVel(m.body.get(), m.vx, m.vy, 0.0);
  dBodySetAngularVel(m.body.get(), 0, 0, 0);
}

void collectBodies(const std::vector<std::unique_ptr<Robot>>& robots, const std::vector<std::unique_ptr<Mover>>& movers,
                   std::vector<BodyCircle>& out)
{
  out.clear();
  for (const auto& r : robots)
  {
    const Pose2D c = outlinePose(r->outline, r->pose);
    out.push_back(BodyCircle{c.x, c.y, reachOf(r->outline), nullptr});
  }
  for (const auto& m : movers) out.push_back(BodyCircle{m->pose.x, m->pose.y, m->reach, m.get()});
}

namespace
{
/// True when the mover's outline at (x, y, yaw) overlaps a wall or a static obstacle.
bool hitsStatic(Mover& m, dSpaceID static_space, double x, double y, double yaw)
{
  setGeomPose(m.probe.get(), x, y, yaw);
  return firstOverlap(m.probe.get(), static_space, nullptr, 0.0, 0.0) != nullptr;
}

/// A step with velocity (vx, vy) is allowed when it brings the walker no closer than kMinGap
/// to any body it is not already closer to, and into no wall it is not already in.
bool stepAllowed(Mover& m, const std::vector<BodyCircle>& bodies, dSpaceID static_space, double vx, double vy,
                 double dt, bool in_wall)
{
  constexpr double kMinGap = 0.05;  // [m] between outlines; contacts begin at the 0.01 m margin
  const double x = m.pose.x + vx * dt, y = m.pose.y + vy * dt;
  for (const BodyCircle& b : bodies)
  {
    if (b.mover == &m) continue;
    const double gap_now = std::hypot(m.pose.x - b.x, m.pose.y - b.y) - m.reach - b.radius;
    const double gap_next = std::hypot(x - b.x, y - b.y) - m.reach - b.radius;
    if (gap_next < kMinGap && gap_next < gap_now - 1e-12) return false;
  }
  if (in_wall || (vx == 0.0 && vy == 0.0)) return true;
  const double yaw = std::hypot(vx, vy) > 1e-9 ? std::atan2(vy, vx) : m.pose.theta;
  return !hitsStatic(m, static_space, x, y, yaw);
}
}  // namespace

/// Social-force style: it heads for its next waypoint at its speed; robots and other movers
/// within personal_radius of its outline push it away and, when they are ahead, steer it around
/// them (to its right when head-on), both scaled by `yielding`; then the step is checked: it
/// never closes in on a body nearer than kMinGap (it stops instead: it cannot be pushed, so it
/// must not walk into anyone) and never enters a wall (it slides along, or waits).
void planWalk(Mover& m, const std::vector<BodyCircle>& bodies, dSpaceID static_space, double dt)
{
  const MovingObstacleConfig& c = m.config;
  // 1. The waypoint: reached when within one step, or when a body stands on it and the
  //    walker is next to it (it would wait there for ever).
  Point2D target;
  double dist = 0.0;
  for (size_t guard = 0; guard < m.route.size(); ++guard)
  {
    target = m.route[m.next];
    dist = std::hypot(target.x - m.pose.x, target.y - m.pose.y);
    bool reached = dist <= std::max(c.speed * dt, 1e-3);
    if (!reached && dist <= m.reach + c.personal_radius)
      for (const BodyCircle& b : bodies)
        reached = reached || (b.mover != &m && std::hypot(target.x - b.x, target.y - b.y) < b.radius + m.reach);
    if (!reached) break;
    m.next = m.next + 1 < m.route.size() ? m.next + 1 : 1;  // route.back() == route.front()
  }
  const double ex = dist > 1e-9 ? (target.x - m.pose.x) / dist : 0.0;
  const double ey = dist > 1e-9 ? (target.y - m.pose.y) / dist : 0.0;

  // 2. Social forces, in units of its speed.
  double fx = 0.0, fy = 0.0;
  for (const BodyCircle& b : bodies)
  {
    if (b.mover == &m) continue;
    double nx = m.pose.x - b.x, ny = m.pose.y - b.y;  // from the body to the walker
    const double d = std::hypot(nx, ny);
    if (d < 1e-9) continue;
    nx /= d;
    ny /= d;
    const double gap = d - m.reach - b.radius;
    if (gap >= c.personal_radius) continue;
    const double s = std::min(1.0, (c.personal_radius - gap) / c.personal_radius);  // 0 at the edge
    const double ahead = -(nx * ex + ny * ey);                                      // 1: straight ahead, -1: behind
    const double weight = 0.5 + 0.5 * std::max(0.0, ahead);                         // what is ahead matters more
    fx += 2.0 * s * s * weight * nx;
    fy += 2.0 * s * s * weight * ny;
    if (ahead > 0.0)
    {
      // Around it: the tangent that goes on forwards, preferably on its side (right, as
      // people keep right; the left after it got stuck, e.g. with a wall on its right).
      double tx = -ny, ty = nx;
      if (tx * ex + ty * ey + 0.3 * m.side * (tx * ey - ty * ex) < 0.0)
      {
        tx = -tx;
        ty = -ty;
      }
      fx += 1.5 * s * ahead * tx;
      fy += 1.5 * s * ahead * ty;
    }
  }
  double vx = c.speed * (ex + c.yielding * fx), vy = c.speed * (ey + c.yielding * fy);
  const double v = std::hypot(vx, vy);
  if (v > c.speed)
  {
    vx *= c.speed / v;
    vy *= c.speed / v;
  }

  // 3. The step it may take: as wished; without the part towards bodies it is close to;
  //    sliding along a wall; or none.
  const bool in_wall = hitsStatic(m, static_space, m.pose.x, m.pose.y, m.pose.theta);
  double px = vx, py = vy;
  for (const BodyCircle& b : bodies)
  {
    if (b.mover == &m) continue;
    double nx = m.pose.x - b.x, ny = m.pose.y - b.y;
    const double d = std::hypot(nx, ny);
    if (d < 1e-9 || d - m.reach - b.radius > c.personal_radius) continue;
    nx /= d;
    ny /= d;
    const double towards = px * nx + py * ny;  // < 0: closing in
    if (towards < 0.0)
    {
      px -= towards * nx;
      py -= towards * ny;
    }
  }
  const double candidates[5][2] = {{vx, vy}, {px, py}, {px, 0.0}, {0.0, py}, {0.0, 0.0}};
  for (const auto& cand : candidates)
    if (stepAllowed(m, bodies, static_space, cand[0], cand[1], dt, in_wall))
    {
      m.vx = cand[0];
      m.vy = cand[1];
      break;
    }

  // 4. No headway for a second (a body ahead and no way past on this side): try the other.
  const bool headway = m.vx * ex + m.vy * ey > 0.1 * c.speed;
  m.stuck_time = headway ? 0.0 : m.stuck_time + dt;
  if (m.stuck_time > 1.0)
  {
    m.side = -m.side;
    m.stuck_time = 0.0;
  }
}

}  // namespace detail
}  // namespace mbot_sim
