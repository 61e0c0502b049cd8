"""/fleet/markers as rviz gets them (markers.fleet_markers), from a coordinator driven with
made-up poses: slots, the line to a slot not yet reached, a lost robot's label, the state text."""
import math

from mbot_common.geometry import Pose2D
from mbot_follower.coordinator import CoordinatorConfig, FleetCoordinator
from mbot_follower.markers import fleet_markers
from test_coordinator import formed_and_navigating, heard, make

ROBOTS = ["leader", "follower_1", "follower_2"]


def by_ns(array):
    found = {}
    for m in array.markers:
        found.setdefault(m.ns, []).append(m)
    return found


def stamp():
    import rospy
    return rospy.Time(1, 0)


def started():
    core = FleetCoordinator(ROBOTS, "leader", "triangle", 2.5, CoordinatorConfig())
    poses = {"leader": Pose2D(0.0, 0.0, 0.0), "follower_1": Pose2D(-1.0, 3.0, 0.0),
             "follower_2": Pose2D(-1.5, -2.0, 0.5)}
    core.set_goal(Pose2D(5.0, 0.0, 0.0), 0.0, poses)
    core.update(0.1, poses, {r: 0.1 for r in ROBOTS})
    return core, poses


def test_each_follower_off_its_slot_has_a_line_to_it():
    core, poses = started()
    found = by_ns(fleet_markers(core, poses, stamp()))
    assert len(found["slots"]) == 2
    slots = core.slot_poses(poses)
    lines = found["to_slots"][0].points
    ends = sorted(((a.x, a.y), (b.x, b.y)) for a, b in zip(lines[::2], lines[1::2]))
    assert ends == sorted(((poses[r].x, poses[r].y), (slots[r].x, slots[r].y)) for r in ("follower_1", "follower_2"))
    # on their slots: no lines
    on_slots = {r: Pose2D(s.x, s.y, 0.0) for r, s in slots.items()}
    assert "to_slots" not in by_ns(fleet_markers(core, on_slots, stamp()))


def test_a_lost_robot_is_labelled_and_named_in_the_state():
    core, poses = started()
    t = 0.1
    for _ in range(15):  # follower_1 silent for 1.5 s: lost
        t += 0.1
        core.update(t, poses, {"leader": t, "follower_2": t, "follower_1": 0.1})
    assert core.lost == ["follower_1"]
    found = by_ns(fleet_markers(core, poses, stamp()))
    lost = found["lost"]
    assert len(lost) == 1 and lost[0].text == "lost"
    assert math.hypot(lost[0].pose.position.x - poses["follower_1"].x,
                      lost[0].pose.position.y - poses["follower_1"].y) < 0.5
    assert found["state"][0].text.endswith("(lost: follower_1)")
    # removed from the simulator (no pose): nothing to label
    gone = {r: p for r, p in poses.items() if r != "follower_1"}
    assert "lost" not in by_ns(fleet_markers(core, gone, stamp()))


def test_the_state_is_written_above_every_robot():
    core, poses = started()
    state = by_ns(fleet_markers(core, poses, stamp()))["state"][0]
    assert state.pose.position.y > max(p.y for p in poses.values()) + 0.5
    xs = [p.x for p in poses.values()]
    assert min(xs) <= state.pose.position.x <= max(xs)


def test_a_paused_fleet_shows_a_red_cylinder_in_front_of_the_leader():
    core = make()
    t, poses, _ = formed_and_navigating(core)
    leader = poses["leader"]
    assert "pause" not in by_ns(fleet_markers(core, poses, stamp()))
    core.update(t + 0.1, poses, heard(t + 0.1), leader_nav="ACTIVE", obstacle_ahead=True)
    assert core.paused
    found = by_ns(fleet_markers(core, poses, stamp()))
    warn = found["pause"][0]
    assert (warn.color.r, warn.color.g < 0.3, warn.color.b < 0.3) == (1.0, True, True)
    ahead = (warn.pose.position.x - leader.x, warn.pose.position.y - leader.y)
    assert ahead[0] * math.cos(leader.theta) + ahead[1] * math.sin(leader.theta) > 0.5
    assert "PAUSED" in found["state"][0].text and found["state"][0].color.g < 0.3
