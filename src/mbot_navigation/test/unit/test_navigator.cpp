// The Navigator (navigator.h) through its LocalPlanner interface, with a scripted fake local
// planner instead of DWA: what it hands the local planner and what it does with the answers.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <string>
#include <vector>

#include "mbot_navigation/global_planner/astar_planner.h"
#include "mbot_navigation/local_planner/local_planner.h"
#include "mbot_navigation/navigator/navigator.h"

using namespace mbot_navigation;

namespace
{
/// What the fake was asked and what it answers; shared with the test (the Navigator owns the fake).
struct Script
{
  // answers
  bool fail = false;         ///< computeVelocityCommands fails with "boxed in"
  double reach_within = -1;  ///< isGoalReached within this distance of the plan's end [m]; < 0: never
  Twist2D cmd{0.3, 0.0, 0.1};
  // record
  int set_plan_calls = 0;
  int compute_calls = 0;
  std::vector<Pose2D> last_plan;
};

class FakeLocalPlanner : public LocalPlanner
{
public:
  explicit FakeLocalPlanner(Script& script) : s_(script) {}
  std::string name() const override { return "fake"; }
  void setPlan(const std::vector<Pose2D>& plan) override
  {
    ++s_.set_plan_calls;
    s_.last_plan = plan;
    plan_ = plan;
  }
  const std::vector<Pose2D>& plan() const override { return plan_; }
  LocalPlanResult computeVelocityCommands(const Pose2D&, const Twist2D&, const Costmap2D&, Twist2D& cmd) override
  {
    ++s_.compute_calls;
    LocalPlanResult r;
    if (s_.fail)
    {
      cmd = Twist2D{};
      r.error = "boxed in";
      return r;
    }
    cmd = s_.cmd;
    r.ok = true;
    return r;
  }
  bool isGoalReached(const Pose2D& pose, const Twist2D&) const override
  {
    return s_.reach_within >= 0.0 && !plan_.empty() &&
           std::hypot(pose.x - plan_.back().x, pose.y - plan_.back().y) <= s_.reach_within;
  }
  double footprintRadius() const override { return 0.15; }

private:
  Script& s_;
  std::vector<Pose2D> plan_;
};

/// A free 4 m x 4 m costmap (origin -2, -2).
Costmap2D freeCostmap() { return Costmap2D(80, 80, 0.05, -2.0, -2.0, cost::FREE); }

std::unique_ptr<Navigator> navigator(Script& script, const NavigatorConfig& config = NavigatorConfig())
{
  return std::make_unique<Navigator>(config, std::make_unique<FakeLocalPlanner>(script),
                                     std::make_unique<AStarPlanner>(AStarConfig()),
                                     std::vector<std::unique_ptr<RecoveryBehavior>>());
}
}  // namespace

TEST(NavigatorWithFakeLocalPlanner, HandsOverThePlanAndCommandsWhatTheLocalPlannerSays)
{
  Script script;
  auto nav = navigator(script);
  const Costmap2D map = freeCostmap();
  const Pose2D start{-1.0, -1.0, 0.0}, goal{1.0, 0.5, 0.0};
  nav->setGoal(goal, 0.0);
  const NavCycleResult r = nav->cycle(0.0, start, Twist2D{}, map, map);
  EXPECT_EQ(r.outcome, NavOutcome::ACTIVE);
  EXPECT_TRUE(r.plan_updated);
  EXPECT_EQ(nav->state(), NavState::CONTROLLING);
  // The global plan went to the local planner, start to goal.
  ASSERT_EQ(script.set_plan_calls, 1);
  ASSERT_GE(script.last_plan.size(), 2u);
  EXPECT_EQ(script.last_plan.size(), nav->globalPlan().size());
  EXPECT_NEAR(script.last_plan.back().x, goal.x, 0.05);
  EXPECT_NEAR(script.last_plan.back().y, goal.y, 0.05);
  // Its command is the cycle's command.
  EXPECT_EQ(script.compute_calls, 1);
  EXPECT_DOUBLE_EQ(r.cmd.vx, 0.3);
  EXPECT_DOUBLE_EQ(r.cmd.wz, 0.1);
  EXPECT_EQ(nav->localPlanner().name(), "fake");

  // No new plan while the plan stays free and planner_frequency is 0.
  nav->cycle(0.05, start, Twist2D{}, map, map);
  EXPECT_EQ(script.set_plan_calls, 1);
  EXPECT_EQ(script.compute_calls, 2);

  // The local planner says the goal is reached: SUCCEEDED, without asking it for a command.
  script.reach_within = 0.1;
  const NavCycleResult done = nav->cycle(0.1, script.last_plan.back(), Twist2D{}, map, map);
  EXPECT_EQ(done.outcome, NavOutcome::SUCCEEDED);
  EXPECT_EQ(script.compute_calls, 2);
  EXPECT_EQ(nav->state(), NavState::IDLE);
  EXPECT_DOUBLE_EQ(done.cmd.vx, 0.0);
}

TEST(NavigatorWithFakeLocalPlanner, AFailingLocalPlannerStopsTheRobotThenAbortsNamingIt)
{
  Script script;
  script.fail = true;
  NavigatorConfig config;
  config.controller_patience = 1.0;
  config.recovery_behavior_enabled = false;
  auto nav = navigator(script, config);
  const Costmap2D map = freeCostmap();
  const Pose2D start{-1.0, -1.0, 0.0};
  nav->setGoal(Pose2D{1.0, 0.5, 0.0}, 0.0);
  NavCycleResult r;
  double t = 0.0;
  for (; t < 5.0; t += 0.05)
  {
    r = nav->cycle(t, start, Twist2D{}, map, map);
    if (r.outcome != NavOutcome::ACTIVE) break;
    EXPECT_DOUBLE_EQ(r.cmd.vx, 0.0);  // no command: stand still
    EXPECT_DOUBLE_EQ(r.cmd.wz, 0.0);
  }
  ASSERT_EQ(r.outcome, NavOutcome::ABORTED);
  EXPECT_GT(t, 1.0);  // after controller_patience, not before
  EXPECT_LT(t, 1.2);
  EXPECT_GT(script.set_plan_calls, 1);  // as move_base: each failure plans again
  EXPECT_EQ(r.text.rfind("the local planner (fake) found no valid velocity command for 1.0 s: boxed in", 0), 0u)
      << r.text;
}

TEST(NavigatorWithFakeLocalPlanner, ANewLocalPlannerGetsTheCurrentPlan)
{
  Script first, second;
  auto nav = navigator(first);
  const Costmap2D map = freeCostmap();
  nav->setGoal(Pose2D{1.0, 0.5, 0.0}, 0.0);
  nav->cycle(0.0, Pose2D{-1.0, -1.0, 0.0}, Twist2D{}, map, map);
  second.cmd = Twist2D{0.1, 0.0, -0.2};
  nav->setLocalPlanner(std::make_unique<FakeLocalPlanner>(second));
  ASSERT_EQ(second.set_plan_calls, 1);
  EXPECT_EQ(second.last_plan.size(), nav->globalPlan().size());
  const NavCycleResult r = nav->cycle(0.05, Pose2D{-1.0, -1.0, 0.0}, Twist2D{}, map, map);
  EXPECT_DOUBLE_EQ(r.cmd.wz, -0.2);  // the new one drives
  EXPECT_EQ(second.compute_calls, 1);
  EXPECT_EQ(first.compute_calls, 1);
  EXPECT_THROW(nav->setLocalPlanner(nullptr), std::invalid_argument);
}

int main(int argc, char** argv)
{
  testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
