/**
 * @file bodies.cpp
 * @brief Body outlines (circle or rectangle, from an obstacle's shape or a robot's footprint)
 *        and the ODE geoms made from them. See bodies.h.
 */
#include "bodies.h"

#include <algorithm>
#include <cmath>

namespace mbot_sim
{
namespace detail
{
using mbot_description::RobotModel;

std::string BodyTag::describe() const
{
  switch (kind)
  {
    case Kind::WALL: return "a wall";
    case Kind::OBSTACLE: return "obstacle " + name;
    case Kind::MOVING: return "moving obstacle " + name;
    case Kind::ROBOT: return "robot " + name;
  }
  return name;
}

Outline outlineOf(const ShapeConfig& shape)
{
  Outline o;
  o.is_box = shape.type == ShapeConfig::Type::BOX;
  o.radius = shape.radius;
  o.half_length = shape.length / 2.0;
  o.half_width = shape.width / 2.0;
  return o;
}

Outline outlineOf(const RobotModel& model)
{
  Outline o;
  const auto& fp = model.footprint;
  if (fp.size() == 4)
  {
    const double ex = fp[1].x - fp[0].x, ey = fp[1].y - fp[0].y;
    const double fx = fp[2].x - fp[1].x, fy = fp[2].y - fp[1].y;
    const double gx = fp[3].x - fp[2].x, gy = fp[3].y - fp[2].y;
    const double le = std::hypot(ex, ey), lf = std::hypot(fx, fy);
    const bool rectangle = le > 1e-6 && lf > 1e-6 && std::abs(ex * fx + ey * fy) < 1e-6 * le * lf &&
                           std::abs(ex + gx) < 1e-6 && std::abs(ey + gy) < 1e-6;
    if (rectangle)
    {
      o.is_box = true;
      o.half_length = le / 2.0;
      o.half_width = lf / 2.0;
      o.offset_yaw = std::atan2(ey, ex);
      o.offset_x = (fp[0].x + fp[2].x) / 2.0;
      o.offset_y = (fp[0].y + fp[2].y) / 2.0;
      return o;
    }
  }
  if (fp.empty())
  {
    o.radius = model.footprint_radius;
    return o;
  }
  for (const auto& p : fp)
  {
    o.offset_x += p.x / fp.size();
    o.offset_y += p.y / fp.size();
  }
  for (const auto& p : fp) o.radius = std::max(o.radius, std::hypot(p.x - o.offset_x, p.y - o.offset_y));
  return o;
}

double reachOf(const Outline& o) { return o.is_box ? std::hypot(o.half_length, o.half_width) : o.radius; }

Pose2D outlinePose(const Outline& o, const Pose2D& pose)
{
  const Point2D centre = mbot_common::transformPoint(pose, o.offset_x, o.offset_y);
  return Pose2D{centre.x, centre.y, pose.theta + o.offset_yaw};
}

// Round robots are spheres (their centre is at mid-height of every other body, so in the plane a
// sphere is the circle): sphere-sphere, sphere-box and sphere-cylinder tests are exact and fast,
// while ODE's cylinder-cylinder test is an approximate one.
GeomPtr makeGeom(const Outline& o, double margin, bool robot)
{
  if (o.is_box)
    return GeomPtr(dCreateBox(nullptr, 2.0 * (o.half_length + margin), 2.0 * (o.half_width + margin), kBodyHeight));
  if (robot) return GeomPtr(dCreateSphere(nullptr, o.radius + margin));
  return GeomPtr(dCreateCylinder(nullptr, o.radius + margin, kBodyHeight));
}

void setGeomPose(dGeomID geom, double x, double y, double yaw)
{
  dGeomSetPosition(geom, x, y, kBodyZ);
  dMatrix3 r;
  dRFromAxisAndAngle(r, 0, 0, 1, yaw);
  dGeomSetRotation(geom, r);
}

}  // namespace detail
}  // namespace mbot_sim
