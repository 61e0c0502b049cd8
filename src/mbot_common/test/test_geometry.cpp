/**
 * @file test_geometry.cpp
 * @brief geometry.h: angle wrapping, quaternion yaw, and SE(2) pose algebra checked against
 *        hand-computed poses and round trips (the same cases as test_common_geometry.py).
 */
#include "mbot_common/geometry.h"

#include <gtest/gtest.h>

#include <cmath>

using namespace mbot_common;

namespace
{
void expectPose(const Pose2D& p, double x, double y, double theta)
{
  EXPECT_NEAR(p.x, x, 1e-12);
  EXPECT_NEAR(p.y, y, 1e-12);
  EXPECT_NEAR(p.theta, theta, 1e-12);
}
}  // namespace

TEST(Geometry, NormalizeAngleWrapsToMinusPiExclusivePiInclusive)
{
  EXPECT_DOUBLE_EQ(normalizeAngle(0.0), 0.0);
  EXPECT_DOUBLE_EQ(normalizeAngle(kPi), kPi);
  EXPECT_DOUBLE_EQ(normalizeAngle(-kPi), kPi);
  EXPECT_NEAR(normalizeAngle(3.0 * kPi), kPi, 1e-12);
  EXPECT_NEAR(normalizeAngle(2.0 * kPi), 0.0, 1e-12);
  EXPECT_NEAR(normalizeAngle(7.0), 7.0 - 2.0 * kPi, 1e-12);
  EXPECT_NEAR(normalizeAngle(-7.0), -7.0 + 2.0 * kPi, 1e-12);
  EXPECT_TRUE(std::isnan(normalizeAngle(INFINITY)));
  EXPECT_NEAR(angleDiff(170.0 * kPi / 180.0, -170.0 * kPi / 180.0), -20.0 * kPi / 180.0, 1e-12);
}

TEST(Geometry, YawOfInvertsQuaternionFromYaw)
{
  for (double yaw : {0.0, 0.3, -1.2, 3.0, -3.0, kPi})
  {
    const auto q = quaternionFromYaw(yaw);
    EXPECT_NEAR(std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]), 1.0, 1e-12);
    EXPECT_NEAR(yawOf(q[0], q[1], q[2], q[3]), normalizeAngle(yaw), 1e-12) << yaw;
    EXPECT_NEAR(yawOf(2 * q[0], 2 * q[1], 2 * q[2], 2 * q[3]), normalizeAngle(yaw), 1e-12) << "scale-free";
  }
  // a half turn about x (roll pi), then yaw 0.5: the yaw is still 0.5
  const double cz = std::cos(0.25), sz = std::sin(0.25);
  EXPECT_NEAR(yawOf(cz, sz, 0.0, 0.0), 0.5, 1e-12);
  EXPECT_TRUE(std::isnan(yawOf(0.0, 0.0, 0.0, 0.0)));
}

TEST(Geometry, ComposeByHand)
{
  // a robot at (1, 2) facing +y; a point 1 m ahead and 0.5 m to its left is at (0.5, 3)
  const Pose2D a{1.0, 2.0, kPi / 2};
  expectPose(compose(a, Pose2D{1.0, 0.5, kPi / 2}), 0.5, 3.0, kPi);
  const Point2D p = transformPoint(a, 1.0, 0.5);
  EXPECT_NEAR(p.x, 0.5, 1e-12);
  EXPECT_NEAR(p.y, 3.0, 1e-12);
  // a slot 1 m behind and 1 m to the right of a leader at (3, 3) facing -x is at (4, 4)
  expectPose(compose(Pose2D{3.0, 3.0, kPi}, Pose2D{-1.0, -1.0, 0.0}), 4.0, 4.0, kPi);
}

TEST(Geometry, InverseAndRelativeRoundTrip)
{
  const Pose2D a{2.0, -1.0, 2.5};
  const Pose2D b{-0.3, 4.0, -2.9};
  expectPose(compose(a, inverse(a)), 0.0, 0.0, 0.0);
  expectPose(compose(inverse(a), a), 0.0, 0.0, 0.0);
  const Pose2D rel = relative(a, b);
  expectPose(compose(a, rel), b.x, b.y, b.theta);
  const double dx = b.x - a.x, dy = b.y - a.y, c = std::cos(a.theta), s = std::sin(a.theta);
  expectPose(rel, c * dx + s * dy, -s * dx + c * dy, normalizeAngle(b.theta - a.theta));
}
