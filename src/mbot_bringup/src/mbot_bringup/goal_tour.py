"""goal_tour node: send each robot its list of goals through its move_base action, one after the
other, and exit when every robot has finished its list (mark it required to end a demo).

Parameters: ~goals (dict robot -> [[x, y, yaw], ...]) or ~goals_file + ~world (a key of the file).
"""

import rospy
from actionlib_msgs.msg import GoalStatus
from mbot_common.strict_yaml import ConfigError, convert, describe, load_yaml

from mbot_navigation.move_base_client import connect_move_base, make_goal


# actionlib_msgs/GoalStatus values by name, for messages a person reads.
STATUS_NAMES = {GoalStatus.PENDING: "PENDING", GoalStatus.ACTIVE: "ACTIVE", GoalStatus.PREEMPTED: "PREEMPTED",
                GoalStatus.SUCCEEDED: "SUCCEEDED", GoalStatus.ABORTED: "ABORTED", GoalStatus.REJECTED: "REJECTED",
                GoalStatus.PREEMPTING: "PREEMPTING", GoalStatus.RECALLING: "RECALLING",
                GoalStatus.RECALLED: "RECALLED", GoalStatus.LOST: "LOST"}


def check_goals(goals, where):
    """The goal table {robot: [[x, y, yaw], ...]} checked: a map of robot names to non-empty lists
    of three finite numbers each; a ConfigError names `where`, the robot and the goal otherwise."""
    if not isinstance(goals, dict) or not goals:
        raise ConfigError("%s: expected a map robot -> list of goals [x, y, yaw], got %s" % (where, describe(goals)))
    table = {}
    for robot, items in goals.items():
        if not isinstance(items, list) or not items:
            raise ConfigError("%s: %s: expected a non-empty list of goals [x, y, yaw], got %s"
                              % (where, robot, describe(items)))
        table[str(robot)] = []
        for i, goal in enumerate(items):
            numbers = goal if isinstance(goal, list) and len(goal) == 3 else None
            values = [convert(v, float) for v in numbers] if numbers is not None else None  # None: not finite
            if values is None or None in values:
                raise ConfigError("%s: %s[%d]: expected [x, y, yaw] (three finite numbers: m, m, rad), got %s"
                                  % (where, robot, i, describe(goal)))
            table[str(robot)].append(values)
    return table


def load_goals(goals_file, world):
    """Goals of `world` (a name or a world file path: its base name is the key) from the file,
    checked (check_goals). ConfigError for a missing file, bad YAML, an unknown world or a bad goal."""
    table = load_yaml(goals_file)
    if not isinstance(table, dict):
        raise ConfigError("%s: expected a map world -> goals, got %s" % (goals_file, describe(table)))
    key = world.split("/")[-1].replace(".world.yaml", "")
    if key not in table:
        raise ConfigError("%s: no goals for world '%s' (worlds with goals: %s)"
                          % (goals_file, key, ", ".join(sorted(table))))
    return check_goals(table[key], "%s: %s" % (goals_file, key))


class Tour(object):
    """One robot working through its goals."""

    def __init__(self, robot, goals):
        self.robot = robot
        self.goals = list(goals)
        self.next = 0
        self.results = []   # (goal, state name, status text, sim seconds taken)
        self.client = None  # connected in main()
        self.sent_at = None

    def done(self):
        return self.next >= len(self.goals) and self.sent_at is None

    def idle(self):
        return self.sent_at is None

    def send_next(self):
        x, y, yaw = self.goals[self.next]
        self.next += 1
        self.sent_at = rospy.Time.now()
        rospy.loginfo("goal_tour: %s -> (%.2f, %.2f, %.2f)", self.robot, x, y, yaw)
        self.client.send_goal(make_goal(x, y, yaw), done_cb=self.on_done)

    def on_done(self, state, _result):
        taken = (rospy.Time.now() - self.sent_at).to_sec()
        goal = self.goals[self.next - 1]
        name = STATUS_NAMES.get(state, str(state))
        text = self.client.get_goal_status_text()
        self.results.append((goal, name, text, taken))
        rospy.loginfo("goal_tour: %s finished (%.2f, %.2f): %s %s after %.1f s", self.robot,
                      goal[0], goal[1], name, text, taken)
        # The next goal is sent from the main loop: a SimpleActionClient must not be given a new
        # goal from inside its own done callback.
        self.sent_at = None


def main():
    rospy.init_node("goal_tour")
    try:
        goals = rospy.get_param("~goals", None)
        if goals is not None:
            goals = check_goals(goals, rospy.resolve_name("~goals"))
        else:
            goals = load_goals(rospy.get_param("~goals_file"), rospy.get_param("~world"))
    except (ConfigError, KeyError) as e:  # KeyError: neither ~goals nor ~goals_file and ~world
        rospy.logfatal("goal_tour: %s", e if isinstance(e, ConfigError) else "missing parameter %s" % e)
        return 1
    tours = [Tour(robot, goals[robot]) for robot in sorted(goals)]
    for tour in tours:
        try:
            tour.client = connect_move_base(tour.robot, wall_timeout=60.0)
        except RuntimeError as e:
            rospy.logfatal("goal_tour: %s", e)
            return 1
    rate = rospy.Rate(5)
    try:
        while not rospy.is_shutdown() and not all(t.done() for t in tours):
            for tour in tours:
                if tour.idle() and not tour.done():
                    tour.send_next()
            rate.sleep()
    except rospy.ROSInterruptException:
        pass  # the launch is shutting down: report what finished
    for tour in tours:
        for goal, state, text, taken in tour.results:
            print("%-10s goal (%6.2f, %6.2f): %-10s %5.1f s  %s" % (tour.robot, goal[0], goal[1], state, taken, text))
    return 0
