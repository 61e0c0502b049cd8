// The validator every reported solution passes: it must catch each kind of wrong solution.
#include <gtest/gtest.h>

#include "mbot_coordination/instance.h"

using namespace mbot_coordination;

namespace
{
// 4 x 3, all free except (1,1):
//   ....
//   .@..
//   ....
Grid smallGrid() { return parseMap("type octile\nheight 3\nwidth 4\nmap\n....\n.@..\n....\n", "v.map"); }
}  // namespace

class Validator : public ::testing::Test
{
protected:
  Grid g = smallGrid();
  Instance inst;
  void SetUp() override
  {
    inst.grid = &g;
    inst.starts = {g.id(0, 0), g.id(3, 0)};
    inst.goals = {g.id(2, 0), g.id(3, 2)};
  }
  int c(int x, int y) const { return g.id(x, y); }
};

TEST_F(Validator, GoodSolutionAndCosts)
{
  const Paths p = {{c(0, 0), c(1, 0), c(2, 0)}, {c(3, 0), c(3, 1), c(3, 2), c(3, 2)}};
  EXPECT_EQ(validate(inst, p), "");
  EXPECT_EQ(agentCost(p[1]), 2);  // waiting at the goal at the end is free
  EXPECT_EQ(sumOfCosts(p), 4);
  EXPECT_EQ(makespan(p), 2);
  EXPECT_EQ(lowerBound(inst), 4);
}

TEST_F(Validator, WrongEnds)
{
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0), c(2, 0)}}), "1 paths for 2 agents");
  EXPECT_EQ(validate(inst, {{c(1, 0), c(2, 0)}, {c(3, 0), c(3, 1), c(3, 2)}}),
            "agent 0: path starts at (1,0), not its start");
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0)}, {c(3, 0), c(3, 1), c(3, 2)}}),
            "agent 0: path ends at (1,0), not its goal");
  EXPECT_EQ(validate(inst, {{}, {c(3, 0), c(3, 1), c(3, 2)}}), "agent 0: empty path");
}

TEST_F(Validator, BadMoves)
{
  EXPECT_EQ(validate(inst, {{c(0, 0), c(2, 0)}, {c(3, 0), c(3, 1), c(3, 2)}}),
            "agent 0: jumps from (0,0) to (2,0) at t=1");
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0), c(2, 0)}, {c(3, 0), c(2, 1), c(3, 2)}}),
            "agent 1: jumps from (3,0) to (2,1) at t=1");  // diagonal
  inst.starts[0] = c(0, 1);
  EXPECT_EQ(validate(inst, {{c(0, 1), c(1, 1), c(2, 1), c(2, 0)}, {c(3, 0), c(3, 1), c(3, 2)}}),
            "agent 0: blocked or outside cell (1,1) at t=1");
}

TEST_F(Validator, VertexConflict)
{
  // both in (3,0)... agent 0 reaches (2,0) at t=2 while agent 1 passes it at t=2
  inst.starts[1] = c(3, 1);
  inst.goals[1] = c(1, 0);
  inst.goals[0] = c(0, 2);
  EXPECT_EQ(validate(inst, {{c(0, 0), c(0, 1), c(0, 2)}, {c(3, 1), c(3, 0), c(2, 0), c(1, 0)}}), "");
  inst.goals[0] = c(2, 0);
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0), c(2, 0)}, {c(3, 1), c(3, 0), c(2, 0), c(1, 0)}}),
            "vertex conflict: agents 0 and 1 at (2,0) at t=2");
}

TEST_F(Validator, ConflictWithAnAgentWaitingAtItsGoal)
{
  // agent 0 arrives at (2,0) at t=2 and stays; agent 1 passes (2,0) at t=4
  inst.starts[1] = c(3, 2);
  inst.goals[1] = c(1, 0);
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0), c(2, 0)}, {c(3, 2), c(3, 1), c(3, 0), c(2, 0), c(1, 0)}}),
            "vertex conflict: agents 0 and 1 at (2,0) at t=3");
}

TEST_F(Validator, EdgeConflict)
{
  inst.starts = {c(0, 0), c(1, 0)};
  inst.goals = {c(1, 0), c(0, 0)};
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0)}, {c(1, 0), c(0, 0)}}),
            "edge conflict: agents 0 and 1 swap (0,0) and (1,0) at t=1");
  // following (a train) is allowed: 1 moves (1,0)->(2,0) while 0 moves (0,0)->(1,0)
  inst.goals = {c(1, 0), c(2, 0)};
  EXPECT_EQ(validate(inst, {{c(0, 0), c(1, 0)}, {c(1, 0), c(2, 0)}}), "");
}

TEST_F(Validator, CheckInstance)
{
  EXPECT_NO_THROW(checkInstance(inst));
  Instance bad = inst;
  bad.goals[1] = bad.goals[0];
  try
  {
    checkInstance(bad);
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_STREQ(e.what(), "agents 0 and 1 have the same goal (2,0)");
  }
  bad = inst;
  bad.goals[0] = c(1, 1);
  EXPECT_THROW(checkInstance(bad), std::invalid_argument);
  bad = inst;
  bad.starts[1] = bad.starts[0];
  EXPECT_THROW(checkInstance(bad), std::invalid_argument);
  // an island: goal unreachable
  const Grid island = parseMap("type octile\nheight 1\nwidth 3\nmap\n.@.\n", "i.map");
  Instance cut{&island, {island.id(0, 0)}, {island.id(2, 0)}};
  try
  {
    checkInstance(cut);
    FAIL();
  }
  catch (const std::invalid_argument& e)
  {
    EXPECT_STREQ(e.what(), "agent 0: goal (2,0) is not reachable from its start (0,0)");
  }
}

int main(int argc, char** argv)
{
  ::testing::InitGoogleTest(&argc, argv);
  return RUN_ALL_TESTS();
}
