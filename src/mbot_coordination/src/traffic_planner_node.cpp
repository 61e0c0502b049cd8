// traffic_planner: goals for several robots in (action /fleet/goals or ~goals_file), timed plans out
// (/<ns>/timed_plan, /fleet/timed_plans) and executed by each robot's move_base through
// intermediate goals. A thin ROS wrapper around traffic.h and the MAPF planners (README).
#include <actionlib/client/simple_action_client.h>
#include <actionlib/server/simple_action_server.h>
#include <geometry_msgs/PoseStamped.h>
#include <mbot_msgs/FleetGoalsAction.h>
#include <mbot_msgs/RobotStates.h>
#include <move_base_msgs/MoveBaseAction.h>
#include <nav_msgs/OccupancyGrid.h>
#include <nav_msgs/Path.h>
#include <ros/ros.h>
#include <tf2/LinearMath/Quaternion.h>
#include <tf2/utils.h>
#include <tf2_ros/transform_listener.h>
#include <visualization_msgs/MarkerArray.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <map>
#include <memory>
#include <set>
#include <string>
#include <vector>

#include "mbot_coordination/traffic.h"

namespace mc = mbot_coordination;

namespace
{
using MoveBaseClient = actionlib::SimpleActionClient<move_base_msgs::MoveBaseAction>;
using GoalsServer = actionlib::SimpleActionServer<mbot_msgs::FleetGoalsAction>;

struct Pose
{
  double x = 0.0, y = 0.0, yaw = 0.0;
  ros::Time stamp;
};

// One robot's timed plan and where its execution stands.
struct Exec
{
  std::string name;
  mc::FleetGoal goal;
  int goal_cell = -1;
  std::vector<int> path;
  std::vector<mc::TimedPose> poses;
  std::vector<size_t> marked;
  size_t reached = 0;   // the path index of the last marked pose reached (0: the plan's start)
  long target = -1;     // the marked pose move_base drives to, -1: none
  size_t progress = 0;  // the path index the robot is nearest to (never decreases within a plan)
  int aborts = 0;
  enum State
  {
    ACTIVE,
    REACHED,
    FAILED
  } state = ACTIVE;
  std::string status = "waiting";
  std::string reason;
  double start_time = 0.0, arrival_time = 0.0, alone_s = 0.0;
  double moved_at = 0.0;  // [s] last time it moved 0.1 m or reached a marked pose
  Pose moved_from;
  double unseen_since = -1.0;
  std::shared_ptr<MoveBaseClient> client;
};

double now() { return ros::Time::now().toSec(); }
}  // namespace

class TrafficPlanner
{
public:
  TrafficPlanner() : pnh_("~"), server_(nh_, "/fleet/goals", false)
  {
    pnh_.param("algorithm", algorithm_, std::string("auto"));
    pnh_.param("time_limit", options_.time_limit_s, 5.0);
    pnh_.param("cell_size", cell_size_, 0.5);
    pnh_.param("robot_radius", robot_radius_, 0.15);
    pnh_.param("speed", speed_, 0.3);
    pnh_.param("replan_delay", replan_delay_, 3.0);
    pnh_.param("stuck_timeout", stuck_timeout_, 30.0);
    pnh_.param("lost_timeout", lost_timeout_, 2.0);
    pnh_.param("start_delay", start_delay_, 1.0);
    pnh_.param("lookahead", lookahead_, 0.25);
    pnh_.param("move_base_wait", move_base_wait_, 5.0);
    pnh_.param("following", options_.following, true);
    pnh_.param("pose_source", pose_source_, std::string("ground_truth"));
    pnh_.param("goals_file", goals_file_, std::string(""));
    pnh_.param("robots", robots_param_, std::vector<std::string>{});
    mc::makePlanner(algorithm_);  // an unknown name stops the node here, with the known ones listed
    if (options_.following && algorithm_ != "pp" && algorithm_ != "auto")
      throw std::invalid_argument("~following true needs ~algorithm pp or auto (" + algorithm_ +
                                  " does not support following conflicts); set ~following false to use it");
    if (pose_source_ != "ground_truth" && pose_source_ != "tf")
      throw std::invalid_argument("~pose_source must be ground_truth or tf, got '" + pose_source_ + "'");
    if (pose_source_ == "tf" && robots_param_.empty())
      throw std::invalid_argument("~pose_source tf needs ~robots (the robots' namespaces)");
    if (!(speed_ > 0.0) || !(replan_delay_ > 0.0) || !(options_.time_limit_s > 0.0))
      throw std::invalid_argument("~speed, ~replan_delay and ~time_limit must be > 0");
    map_sub_ = nh_.subscribe("/map", 1, &TrafficPlanner::onMap, this);
    if (pose_source_ == "ground_truth")
      truth_sub_ = nh_.subscribe("/stage/ground_truth", 5, &TrafficPlanner::onTruth, this);
    else
      tf_listener_ = std::make_unique<tf2_ros::TransformListener>(tf_buffer_);
    markers_pub_ = nh_.advertise<visualization_msgs::MarkerArray>("/fleet/timed_plans", 1, true);
    server_.registerGoalCallback([this] { onGoal(); });
    server_.registerPreemptCallback([this] { onPreempt(); });
    // the action server starts with the first usable map (onMap): a client's wait_for_server
    // then means the planner can take goals
    timer_ = nh_.createTimer(ros::Duration(0.1), [this](const ros::TimerEvent&) { step(); });
  }

private:
  // ---- inputs
  void onMap(const nav_msgs::OccupancyGrid& msg)
  {
    mbot_common::OccupancyMap map;
    map.width = msg.info.width;
    map.height = msg.info.height;
    map.resolution = msg.info.resolution;
    map.origin_x = msg.info.origin.position.x;
    map.origin_y = msg.info.origin.position.y;
    map.origin_yaw = tf2::getYaw(msg.info.origin.orientation);
    map.data = msg.data;
    try
    {
      grid_ = std::make_unique<mc::PlanningGrid>(mc::makePlanningGrid(map, cell_size_, robot_radius_));
      ROS_INFO("traffic_planner: planning grid %d x %d cells of %.2f m, %d free", grid_->grid.width(),
               grid_->grid.height(), cell_size_, grid_->grid.freeCount());
      if (!server_started_) server_.start();
      server_started_ = true;
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("traffic_planner: cannot plan on /map: %s", e.what());
      grid_.reset();
    }
  }

  void onTruth(const mbot_msgs::RobotStates& msg)
  {
    for (const auto& r : msg.robots) poses_[r.name] = {r.pose.x, r.pose.y, r.pose.theta, r.stamp};
    seen_.clear();
    for (const auto& r : msg.robots) seen_.insert(r.name);
  }

  std::vector<std::string> knownRobots() const
  {
    if (!robots_param_.empty()) return robots_param_;
    return std::vector<std::string>(seen_.begin(), seen_.end());
  }

  // The robot's pose now; false when there is none (not seen, or tf has no transform).
  bool pose(const std::string& name, Pose& out)
  {
    if (pose_source_ == "tf")
    {
      try
      {
        const auto t = tf_buffer_.lookupTransform("map", name + "/base_footprint", ros::Time(0));
        out = {t.transform.translation.x, t.transform.translation.y, tf2::getYaw(t.transform.rotation), t.header.stamp};
        return true;
      }
      catch (const tf2::TransformException&)
      {
        return false;
      }
    }
    auto it = poses_.find(name);
    if (it == poses_.end() || seen_.count(name) == 0) return false;
    out = it->second;
    return true;
  }

  // ---- goal sets
  void onGoal()
  {
    const auto goal = server_.acceptNewGoal();
    std::vector<mc::FleetGoal> goals;
    if (goal->robots.size() != goal->goals.size())
    {
      abortInput("robots and goals differ in number (" + std::to_string(goal->robots.size()) + " robots, " +
                 std::to_string(goal->goals.size()) + " goals)");
      return;
    }
    for (size_t i = 0; i < goal->robots.size(); ++i)
      goals.push_back({goal->robots[i], goal->goals[i].x, goal->goals[i].y, goal->goals[i].theta});
    std::string error = start(goals);
    if (!error.empty()) abortInput(error);
  }

  void abortInput(const std::string& error)
  {
    ROS_ERROR("traffic_planner: goal set refused: %s", error.c_str());
    mbot_msgs::FleetGoalsResult result;
    result.success = false;
    result.message = error;
    server_.setAborted(result, error);
  }

  void onPreempt()
  {
    stopAll();
    execs_.clear();
    mbot_msgs::FleetGoalsResult result;
    result.message = "preempted";
    server_.setPreempted(result, "preempted");
  }

  void stopAll()
  {
    for (auto& e : execs_)
      if (e.client && e.target >= 0) e.client->cancelGoal();
  }

  // Checks and plans a goal set; "" when it runs, else the problem.
  std::string start(const std::vector<mc::FleetGoal>& goals)
  {
    stopAll();
    execs_.clear();
    replans_ = 0;
    if (!grid_) return "no map yet (waiting for /map) or the map cannot be planned on";
    std::vector<int> cells;
    try
    {
      cells = mc::checkGoals(goals, knownRobots(), *grid_);
    }
    catch (const std::exception& e)
    {
      return e.what();
    }
    std::vector<Exec> execs;
    for (size_t i = 0; i < goals.size(); ++i)
    {
      Exec e;
      e.name = goals[i].robot;
      e.goal = goals[i];
      e.goal_cell = cells[i];
      Pose p;
      if (!pose(e.name, p)) return e.name + ": no pose (" + pose_source_ + ")";
      e.moved_from = p;
      // (the client has its own spin thread: waiting here does not stop its connection)
      if (!client(e.name)->waitForServer(ros::Duration(move_base_wait_)))
        return e.name + ": no move_base action server (/" + e.name + "/move_base) within " +
               std::to_string(static_cast<int>(move_base_wait_)) + " s";
      execs.push_back(std::move(e));
    }
    // Robots without a goal stand still: their cells are blocked for this plan.
    mc::Grid grid = gridWithout(goals);
    mc::Instance inst;
    inst.grid = &grid;
    for (auto& e : execs)
    {
      Pose p;
      pose(e.name, p);
      inst.starts.push_back(nearestFree(grid, p));
      inst.goals.push_back(e.goal_cell);
    }
    mc::PlanResult r;
    try
    {
      r = mc::makePlanner(algorithm_)->solve(inst, options_);
    }
    catch (const std::exception& e)
    {
      return std::string("cannot plan: ") + e.what();
    }
    if (!r.solved) return "no plan found (" + algorithm_ + "): " + r.message;
    const double t0 = now() + start_delay_;
    const double step = cell_size_ / speed_;
    for (size_t i = 0; i < execs.size(); ++i)
    {
      Exec& e = execs[i];
      e.start_time = t0;
      e.moved_at = now();
      e.alone_s = step * grid.distancesTo(inst.goals[i])[inst.starts[i]];
      e.client = client(e.name);
      setPath(e, r.paths[i], t0);
    }
    execs_ = std::move(execs);
    remark();
    publishPlans();
    ROS_INFO("traffic_planner: %zu robots planned by %s in %.3f s, sum of costs %ld steps of %.2f s", execs_.size(),
             r.algorithm.c_str(), r.runtime_s, mc::sumOfCosts(r.paths), step);
    return "";
  }

  // The planning grid with the cells of robots that take no part blocked (idle or failed robots).
  mc::Grid gridWithout(const std::vector<mc::FleetGoal>& goals)
  {
    std::set<std::string> planned;
    for (const auto& g : goals) planned.insert(g.robot);
    std::vector<uint8_t> free(grid_->grid.size());
    for (int v = 0; v < grid_->grid.size(); ++v) free[v] = grid_->grid.isFree(v) ? 1 : 0;
    for (const auto& name : knownRobots())
    {
      Pose p;
      if (planned.count(name) || !pose(name, p)) continue;
      const int c = grid_->cellAt(p.x, p.y);
      if (c >= 0) free[c] = 0;
    }
    return mc::Grid(grid_->grid.width(), grid_->grid.height(), std::move(free));
  }

  int nearestFree(const mc::Grid& grid, const Pose& p) const
  {
    int best = -1;
    double best_d = 0.0;
    for (int v = 0; v < grid.size(); ++v)
      if (grid.isFree(v))
      {
        const auto c = grid_->centre(v);
        const double d = std::hypot(c.x - p.x, c.y - p.y);
        if (best < 0 || d < best_d) best = v, best_d = d;
      }
    return best;
  }

  std::shared_ptr<MoveBaseClient> client(const std::string& name)
  {
    auto& c = clients_[name];
    if (!c) c = std::make_shared<MoveBaseClient>("/" + name + "/move_base", true);
    return c;
  }

  void setPath(Exec& e, const std::vector<int>& path, double t0)
  {
    e.path = path;
    e.poses = mc::timedWaypoints(*grid_, path, t0, speed_, e.goal.yaw);
    // the last pose is the goal itself, not its cell's centre
    e.poses.back().x = e.goal.x;
    e.poses.back().y = e.goal.y;
    e.reached = 0;
    e.progress = 0;
    e.target = -1;
  }

  // Marked poses: before every cell another active robot's plan visits earlier, the robot is held
  // (it goes on when that robot has left it: the plan's order of visits per cell).
  void remark()
  {
    for (auto& e : execs_)
    {
      std::vector<bool> hold(e.path.size(), false);
      for (size_t k = 1; k < e.path.size(); ++k)
        for (const auto& o : execs_)
          if (&o != &e && o.state == Exec::ACTIVE)
            for (size_t j = o.progress; j < o.path.size() && !hold[k]; ++j)
              hold[k] = o.path[j] == e.path[k] && o.poses[j].t < e.poses[k].t;
      e.marked = mc::markedPoses(e.path, hold);
    }
  }

  // The first marked pose after path index k (the last pose when none).
  static size_t nextMarked(const Exec& e, size_t k)
  {
    for (size_t m : e.marked)
      if (m > k) return m;
    return e.path.size() - 1;
  }

  // ---- execution
  // True when o has left its visit of a cell (path indices up to `end`) far enough for another robot
  // to enter it: o is nearest to a pose two cells on (a robot that reached its goal is done).
  static bool passed(const Exec& o, size_t end)
  {
    if (o.state != Exec::ACTIVE) return true;
    return o.progress >= end + 2;
  }

  // The robot may drive from `reached` to pose `next` when every other robot planned into those
  // cells earlier has left them (the plan's order of visits per cell, kept whatever the delays).
  std::string heldBy(const Exec& e, size_t from, size_t next) const
  {
    for (size_t k = from + 1; k <= next; ++k)
      for (const auto& o : execs_)
      {
        if (&o == &e || o.state != Exec::ACTIVE) continue;
        for (size_t j = o.progress; j < o.path.size(); ++j)
          if (o.path[j] == e.path[k] && o.poses[j].t < e.poses[k].t)
          {
            const size_t end = mc::waitEnd(o.path, j);
            if (!passed(o, end)) return o.name;
            j = end;
          }
      }
    return "";
  }

  void fail(Exec& e, const std::string& why)
  {
    if (e.client && e.target >= 0) e.client->cancelGoal();
    e.state = Exec::FAILED;
    e.status = "failed";
    e.reason = why;
    ROS_WARN("traffic_planner: %s failed: %s; re-planning the others without it", e.name.c_str(), why.c_str());
    std::vector<size_t> others;
    for (size_t i = 0; i < execs_.size(); ++i)
      if (execs_[i].state == Exec::ACTIVE) others.push_back(i);
    replan(others);
  }

  void step()
  {
    for (const auto& name : knownRobots()) client(name);  // connect early: the first goal set starts at once
    if (execs_.empty())
    {
      if (!goals_file_.empty() && grid_ && !knownRobots().empty()) runGoalsFile();
      return;
    }
    const double t = now();
    const double step_s = cell_size_ / speed_;
    std::vector<size_t> late;
    for (size_t i = 0; i < execs_.size(); ++i)
    {
      Exec& e = execs_[i];
      if (e.state != Exec::ACTIVE) continue;
      Pose p;
      if (!pose(e.name, p))
      {
        if (e.unseen_since < 0) e.unseen_since = t;
        if (t - e.unseen_since > lost_timeout_)
        {
          char why[64];
          std::snprintf(why, sizeof(why), "killed (no pose for %.1f s)", lost_timeout_);
          fail(e, why);
        }
        continue;
      }
      e.unseen_since = -1.0;
      if (std::hypot(p.x - e.moved_from.x, p.y - e.moved_from.y) > 0.1)
      {
        e.moved_from = p;
        e.moved_at = t;
      }
      if (e.target >= 0)
      {
        // progress: the nearest pose between the last marked one and the target
        double best = 1e9;
        for (size_t k = e.reached; k <= static_cast<size_t>(e.target); ++k)
        {
          const double d = std::hypot(e.poses[k].x - p.x, e.poses[k].y - p.y);
          if (d <= best) best = d, e.progress = std::max(e.progress, k);
        }
        // Near a marked pose whose time has come, with the next cells its turn: go on without
        // stopping there (move_base would stop and turn to the pose's yaw).
        const size_t tgt = static_cast<size_t>(e.target);
        if (tgt + 1 < e.path.size() && std::hypot(e.poses[tgt].x - p.x, e.poses[tgt].y - p.y) < lookahead_ &&
            t >= e.poses[mc::waitEnd(e.path, tgt)].t && heldBy(e, tgt, nextMarked(e, tgt)).empty())
        {
          e.reached = e.progress = tgt;
          send(e, nextMarked(e, tgt));
          continue;
        }
        const auto st = e.client->getState();
        if (st == actionlib::SimpleClientGoalState::SUCCEEDED)
        {
          e.reached = e.progress = static_cast<size_t>(e.target);
          e.target = -1;
          e.moved_at = t;
          if (e.reached + 1 == e.path.size())
          {
            e.state = Exec::REACHED;
            e.status = "reached";
            e.arrival_time = t;
            ROS_INFO("traffic_planner: %s reached its goal after %.1f s (alone: %.1f s planned)", e.name.c_str(),
                     t - e.start_time, e.alone_s);
            continue;
          }
        }
        else if (st.isDone())
        {
          if (++e.aborts >= 2)
          {
            fail(e, "move_base " + st.toString() + " twice: " + st.getText());
            continue;
          }
          ROS_WARN("traffic_planner: %s: move_base %s (%s), sending the goal again", e.name.c_str(),
                   st.toString().c_str(), st.getText().c_str());
          send(e, static_cast<size_t>(e.target));
        }
        else if (t - e.moved_at > stuck_timeout_)
        {
          fail(e, "no progress for " + std::to_string(static_cast<int>(stuck_timeout_)) + " s");
          continue;
        }
      }
      if (e.target < 0)
      {
        // the next marked pose, sent when the robot's time has come and the cells are its turn
        const size_t next = nextMarked(e, e.reached);
        const double depart = e.poses[mc::waitEnd(e.path, e.reached)].t;
        if (t < depart)
          e.status = "waiting";
        else
        {
          const std::string by = heldBy(e, e.reached, next);
          if (by.empty())
            send(e, next);
          else
          {
            e.status = "held (" + by + " first)";
            e.moved_at = t;  // held is not stuck
          }
        }
      }
      const double delay = t - e.poses[mc::waitEnd(e.path, e.progress)].t - step_s;
      if (delay > replan_delay_ && t - last_replan_ > replan_delay_) late.push_back(i);
    }
    if (!late.empty()) replanLate(late);
    feedback();
    finishIfDone();
  }

  void send(Exec& e, size_t k)
  {
    if (!e.client->isServerConnected())
    {
      e.status = "no move_base";
      if (e.moved_at < now() - stuck_timeout_) fail(e, "killed (its move_base is gone)");
      return;
    }
    move_base_msgs::MoveBaseGoal goal;
    goal.target_pose.header.frame_id = "map";
    goal.target_pose.header.stamp = ros::Time::now();
    goal.target_pose.pose.position.x = e.poses[k].x;
    goal.target_pose.pose.position.y = e.poses[k].y;
    tf2::Quaternion q;
    q.setRPY(0, 0, e.poses[k].yaw);
    goal.target_pose.pose.orientation.x = q.x();
    goal.target_pose.pose.orientation.y = q.y();
    goal.target_pose.pose.orientation.z = q.z();
    goal.target_pose.pose.orientation.w = q.w();
    e.client->sendGoal(goal);
    e.target = static_cast<long>(k);
    e.status = "driving";
  }

  // Late robots: re-plan them and the robots whose remaining plans share a cell with theirs.
  void replanLate(const std::vector<size_t>& late)
  {
    std::set<size_t> group;
    for (size_t i : late)
      for (size_t j = 0; j < execs_.size(); ++j)
      {
        const Exec &a = execs_[i], &b = execs_[j];
        if (j == i || b.state != Exec::ACTIVE) continue;
        for (size_t k = a.progress; k < a.path.size() && !group.count(j); ++k)
          if (std::find(b.path.begin() + b.progress, b.path.end(), a.path[k]) != b.path.end())
          {
            group.insert(i);
            group.insert(j);
          }
      }
    // A late robot whose remaining cells no other robot visits delays nobody: it drives on (a
    // re-plan would only stop it).
    if (group.empty()) return;
    std::string names;
    for (size_t i : group) names += (names.empty() ? "" : ", ") + execs_[i].name;
    const Exec& first = execs_[late[0]];
    ROS_WARN("traffic_planner: %s late by %.1f s (> %.1f s) at pose %zu of %zu (%s): re-planning %s",
             first.name.c_str(), now() - first.poses[mc::waitEnd(first.path, first.progress)].t, replan_delay_,
             first.progress, first.path.size(), first.status.c_str(), names.c_str());
    replan(std::vector<size_t>(group.begin(), group.end()));
  }

  // Re-plans `which` (active robots) from where they stand now, around the others' remaining plans.
  void replan(const std::vector<size_t>& which)
  {
    last_replan_ = now();
    if (which.empty()) return;
    ++replans_;
    const double t = now();
    std::vector<mc::FleetGoal> in_plan;
    for (const auto& e : execs_)
      if (e.state != Exec::FAILED) in_plan.push_back(e.goal);
    mc::Grid grid = gridWithout(in_plan);  // failed and idle robots are obstacles
    mc::Paths fixed;
    std::set<size_t> group(which.begin(), which.end());
    for (size_t i = 0; i < execs_.size(); ++i)
    {
      const Exec& e = execs_[i];
      if (group.count(i) || e.state == Exec::FAILED) continue;
      if (e.state == Exec::REACHED)
      {
        fixed.push_back({e.goal_cell});
        continue;
      }
      // its remaining path from now on, at its planned times (from its progress when it is late)
      size_t q = e.progress;
      while (q + 1 < e.path.size() && e.poses[q + 1].t <= t) ++q;
      q = std::max(q, e.progress);
      fixed.emplace_back(e.path.begin() + q, e.path.end());
    }
    std::vector<int> starts, goals;
    for (size_t i : which)
    {
      Pose p;
      pose(execs_[i].name, p);
      starts.push_back(nearestFree(grid, p));
      goals.push_back(execs_[i].goal_cell);
    }
    std::string why;
    mc::Paths paths;
    try
    {
      paths = mc::planAround(grid, fixed, starts, goals, options_, &why);
    }
    catch (const std::exception& ex)
    {
      why = ex.what();
    }
    if (paths.empty())
    {
      ROS_WARN("traffic_planner: re-plan failed (%s); the robots keep their plans", why.c_str());
      return;
    }
    for (size_t k = 0; k < which.size(); ++k)
    {
      Exec& e = execs_[which[k]];
      if (e.client && e.target >= 0) e.client->cancelGoal();
      setPath(e, paths[k], t);
      e.moved_at = t;
    }
    remark();
    publishPlans();
  }

  void runGoalsFile()
  {
    const std::string file = goals_file_;
    goals_file_.clear();  // once
    try
    {
      const std::string error = start(mc::readGoalsFile(file));
      if (!error.empty()) ROS_ERROR("traffic_planner: ~goals_file %s refused: %s", file.c_str(), error.c_str());
    }
    catch (const std::exception& e)
    {
      ROS_ERROR("traffic_planner: ~goals_file refused: %s", e.what());
    }
  }

  // ---- outputs
  void publishPlans()
  {
    visualization_msgs::MarkerArray markers;
    int id = 0;
    for (const auto& e : execs_)
    {
      nav_msgs::Path path;
      path.header.frame_id = "map";
      path.header.stamp = ros::Time(e.poses.front().t);
      for (const auto& p : e.poses)
      {
        geometry_msgs::PoseStamped ps;
        ps.header.frame_id = "map";
        ps.header.stamp = ros::Time(p.t);
        ps.pose.position.x = p.x;
        ps.pose.position.y = p.y;
        ps.pose.orientation.z = std::sin(p.yaw / 2);
        ps.pose.orientation.w = std::cos(p.yaw / 2);
        path.poses.push_back(ps);
      }
      auto& pub = plan_pubs_[e.name];
      if (!pub) pub = nh_.advertise<nav_msgs::Path>("/" + e.name + "/timed_plan", 1, true);
      pub.publish(path);

      visualization_msgs::Marker line, marks;
      line.header.frame_id = marks.header.frame_id = "map";
      line.ns = marks.ns = e.name;
      line.id = id++;
      marks.id = id++;
      line.type = visualization_msgs::Marker::LINE_STRIP;
      marks.type = visualization_msgs::Marker::SPHERE_LIST;
      line.scale.x = 0.05;
      marks.scale.x = marks.scale.y = marks.scale.z = 0.15;
      const double hue = std::fmod(0.37 * (id / 2), 1.0);
      line.color.r = marks.color.r = static_cast<float>(hue);
      line.color.g = marks.color.g = static_cast<float>(1.0 - hue);
      line.color.b = marks.color.b = 0.5f;
      line.color.a = marks.color.a = 1.0f;
      line.pose.orientation.w = marks.pose.orientation.w = 1.0;
      for (const auto& p : e.poses)
      {
        geometry_msgs::Point pt;
        pt.x = p.x;
        pt.y = p.y;
        line.points.push_back(pt);
      }
      for (size_t m : e.marked)
      {
        geometry_msgs::Point pt;
        pt.x = e.poses[m].x;
        pt.y = e.poses[m].y;
        marks.points.push_back(pt);
      }
      markers.markers.push_back(line);
      markers.markers.push_back(marks);
    }
    markers_pub_.publish(markers);
  }

  void feedback()
  {
    if (!server_.isActive()) return;
    mbot_msgs::FleetGoalsFeedback fb;
    const double t = now();
    for (const auto& e : execs_)
    {
      fb.robots.push_back(e.name);
      fb.states.push_back(e.status);
      fb.delays.push_back(e.state == Exec::ACTIVE ? t - e.poses[mc::waitEnd(e.path, e.progress)].t : 0.0);
    }
    fb.replans = replans_;
    server_.publishFeedback(fb);
  }

  void finishIfDone()
  {
    for (const auto& e : execs_)
      if (e.state == Exec::ACTIVE) return;
    mbot_msgs::FleetGoalsResult result;
    result.success = true;
    std::string failed;
    for (const auto& e : execs_)
    {
      result.robots.push_back(e.name);
      result.reached.push_back(e.state == Exec::REACHED);
      result.reasons.push_back(e.reason);
      result.durations.push_back(e.state == Exec::REACHED ? e.arrival_time - e.start_time : 0.0);
      result.alone_durations.push_back(e.alone_s);
      if (e.state != Exec::REACHED)
      {
        result.success = false;
        failed += (failed.empty() ? "" : "; ") + e.name + ": " + e.reason;
      }
    }
    result.replans = replans_;
    result.message = result.success ? "all robots reached their goals" : "failed: " + failed;
    ROS_INFO("traffic_planner: goal set done: %s (%d re-plans)", result.message.c_str(), replans_);
    execs_.clear();
    if (server_.isActive())
    {
      if (result.success)
        server_.setSucceeded(result, result.message);
      else
        server_.setAborted(result, result.message);
    }
  }

  ros::NodeHandle nh_, pnh_;
  GoalsServer server_;
  ros::Subscriber map_sub_, truth_sub_;
  ros::Publisher markers_pub_;
  std::map<std::string, ros::Publisher> plan_pubs_;
  std::map<std::string, std::shared_ptr<MoveBaseClient>> clients_;
  ros::Timer timer_;
  tf2_ros::Buffer tf_buffer_;
  std::unique_ptr<tf2_ros::TransformListener> tf_listener_;

  std::string algorithm_, pose_source_, goals_file_;
  std::vector<std::string> robots_param_;
  mc::PlannerOptions options_;
  double cell_size_ = 0.5, robot_radius_ = 0.15, speed_ = 0.3, replan_delay_ = 3.0, stuck_timeout_ = 30.0;
  double lost_timeout_ = 2.0, start_delay_ = 1.0, lookahead_ = 0.25, move_base_wait_ = 5.0;
  double last_replan_ = -1e9;
  int replans_ = 0;
  bool server_started_ = false;

  std::unique_ptr<mc::PlanningGrid> grid_;
  std::map<std::string, Pose> poses_;
  std::set<std::string> seen_;
  std::vector<Exec> execs_;
};

int main(int argc, char** argv)
{
  ros::init(argc, argv, "traffic_planner");
  try
  {
    TrafficPlanner node;
    ros::spin();
  }
  catch (const std::exception& e)
  {
    ROS_FATAL("traffic_planner: %s", e.what());
    return 1;
  }
  return 0;
}
