"""The robots' fixed frames (robot_state_publisher's work), for any world file and for robots
spawned or removed at run time.

stage_node keeps the list of its robots in the parameter ``/stage/robots`` (``[{name, model}]``).
This helper watches that list; for each new robot it sets ``/<name>/robot_description`` to the
robot's URDF with every link and joint prefixed ``<name>/`` (mbot_description's prefix_urdf, the
same text description.launch sets; rviz's RobotModel reads it). The wheels' transforms come from
stage_node itself (``~wheel_tf_rate``, as Gazebo's diff drive plugin's ``publishWheelTF``), so
what is left to publish never moves: the fixed joints,
``<name>/base_footprint -> <name>/base_link -> <name>/base_laser``. This node publishes them for
every robot on ``/tf_static`` (one latched message holding all robots' fixed joints, sent again
when a robot comes or goes), as robot_state_publisher would, once. One process for the fleet: a
robot_state_publisher per robot costs a process that idles on ``/clock`` (about 1 % of a core
each, 40 of them at 40 robots) for a message sent once.

With ``~use_joint_states: true`` (stage_node's ``wheel_tf_rate: 0``: the wheels from
``/<name>/joint_states``, the usual way) it starts one ``robot_state_publisher`` per robot in the
namespace ``/<name>`` instead, and stops it when the robot is removed.
"""
import math
import os
import xml.etree.ElementTree as ET


def robot_set(robot_list):
    """``{name: model}`` from the ``/stage/robots`` parameter value (a list of dicts)."""
    robots = {}
    for entry in robot_list or []:
        robots[str(entry["name"])] = str(entry.get("model", "mbot"))
    return robots


def plan_changes(running, wanted):
    """What to start and stop so that ``running`` (``{name: model}``) becomes ``wanted``.

    A robot whose model changed (removed and spawned again under the same name) is restarted.
    :return: (names to start, names to stop), each sorted
    """
    stop = sorted(n for n in running if n not in wanted or wanted[n] != running[n])
    start = sorted(n for n in wanted if n not in running or wanted[n] != running[n])
    return start, stop


def prefixed_description(description_dir, model, name):
    """The robot's URDF with every link and joint name prefixed ``name/``."""
    from mbot_description.urdf_prefix import prefix_urdf

    path = os.path.join(description_dir, "urdf", model + ".urdf")
    with open(path) as urdf_file:
        return prefix_urdf(urdf_file.read(), name)


def _floats(text, default, what):
    values = (text or default).split()
    if len(values) != 3:
        raise ValueError("%s: expected three numbers, got %r" % (what, text))
    return [float(v) for v in values]


def quaternion_from_rpy(roll, pitch, yaw):
    """(x, y, z, w) of URDF's fixed-axis roll, pitch, yaw (R = Rz(yaw) Ry(pitch) Rx(roll))."""
    cr, sr = math.cos(roll / 2), math.sin(roll / 2)
    cp, sp = math.cos(pitch / 2), math.sin(pitch / 2)
    cy, sy = math.cos(yaw / 2), math.sin(yaw / 2)
    return (sr * cp * cy - cr * sp * sy, cr * sp * cy + sr * cp * sy,
            cr * cp * sy - sr * sp * cy, cr * cp * cy + sr * sp * sy)


def fixed_joints(urdf_text):
    """[(parent, child, (x, y, z), (qx, qy, qz, qw))] of the URDF's fixed joints, in file order.

    :raises ValueError: a fixed joint without parent or child, or a bad origin
    """
    out = []
    for joint in ET.fromstring(urdf_text).findall("joint"):
        if joint.get("type") != "fixed":
            continue
        name = joint.get("name")
        parent, child = joint.find("parent"), joint.find("child")
        if parent is None or child is None:
            raise ValueError("joint %s: a fixed joint needs <parent link> and <child link>" % name)
        origin = joint.find("origin")
        xyz = _floats(origin.get("xyz") if origin is not None else None, "0 0 0", "joint %s origin xyz" % name)
        rpy = _floats(origin.get("rpy") if origin is not None else None, "0 0 0", "joint %s origin rpy" % name)
        out.append((parent.get("link"), child.get("link"), tuple(xyz), quaternion_from_rpy(*rpy)))
    return out


class FixedFramesPublisher(object):
    """Every robot's fixed joints in one latched ``/tf_static`` message (module docstring)."""

    def __init__(self, publish, set_param, delete_param, description_dir, stamp):
        self._publish = publish            # takes a list of (parent, child, xyz, quaternion, stamp)
        self._set_param = set_param
        self._delete_param = delete_param
        self._description_dir = description_dir
        self._stamp = stamp                # () -> the time to stamp new transforms with
        self._running = {}                 # name -> model
        self._frames = {}                  # name -> [(parent, child, xyz, quaternion, stamp)]

    def update(self, wanted):
        """Publish the fixed frames of ``wanted`` (``{name: model}``); returns (started, stopped)."""
        start, stop = plan_changes(self._running, wanted)
        for name in stop:
            self._running.pop(name, None)
            self._frames.pop(name, None)
            try:
                self._delete_param("/%s/robot_description" % name)
            except KeyError:
                pass
        for name in start:
            description = prefixed_description(self._description_dir, wanted[name], name)
            self._set_param("/%s/robot_description" % name, description)
            stamp = self._stamp()
            self._frames[name] = [joint + (stamp,) for joint in fixed_joints(description)]
            self._running[name] = wanted[name]
        if start or stop:
            self._publish([t for name in sorted(self._frames) for t in self._frames[name]])
        return start, stop

    def stop_all(self):
        pass  # latched transforms stay valid for listeners, as robot_state_publisher's do


class RobotStatePublishers(object):
    """Starts and stops one robot_state_publisher process per robot (roslaunch's scriptapi), which
    reads the robot's joint_states."""

    def __init__(self, launcher, set_param, delete_param, description_dir, publish_frequency=50.0):
        self._launcher = launcher          # roslaunch.scriptapi.ROSLaunch, started
        self._set_param = set_param
        self._delete_param = delete_param
        self._description_dir = description_dir
        self._publish_frequency = publish_frequency
        self._running = {}                 # name -> model
        self._processes = {}               # name -> roslaunch process

    def update(self, wanted):
        """Make the running publishers match ``wanted`` (``{name: model}``)."""
        import roslaunch

        start, stop = plan_changes(self._running, wanted)
        for name in stop:
            process = self._processes.pop(name, None)
            if process is not None:
                process.stop()
            self._running.pop(name, None)
            try:
                self._delete_param("/%s/robot_description" % name)
            except KeyError:
                pass
        for name in start:
            model = wanted[name]
            self._set_param("/%s/robot_description" % name,
                            prefixed_description(self._description_dir, model, name))
            node = roslaunch.core.Node(
                "robot_state_publisher", "robot_state_publisher", name="robot_state_publisher",
                namespace="/" + name, output="log",
                args="_publish_frequency:=%g" % self._publish_frequency)
            self._processes[name] = self._launcher.launch(node)
            self._running[name] = model
        return start, stop

    def stop_all(self):
        self.update({})


def main():
    """Node: look at ``/stage/robots`` every ``~poll_period`` wall seconds (default 0.5), from
    rospy's parameter cache (the master calls back when stage_node changes it)."""
    import time

    import roslaunch
    import rospkg
    import rospy

    rospy.init_node("robot_state_publishers")
    poll_period = float(rospy.get_param("~poll_period", 0.5))  # [s wall]
    publish_frequency = float(rospy.get_param("~publish_frequency", 50.0))  # [Hz]
    use_joint_states = bool(rospy.get_param("~use_joint_states", False))
    description_dir = rospkg.RosPack().get_path("mbot_description")

    launcher = None
    if use_joint_states:
        launcher = roslaunch.scriptapi.ROSLaunch()
        launcher.start()
        publishers = RobotStatePublishers(launcher, rospy.set_param, rospy.delete_param,
                                          description_dir, publish_frequency)
    else:
        publishers = FixedFramesPublisher(static_tf_publisher(), rospy.set_param, rospy.delete_param,
                                          description_dir, rospy.Time.now)
    rospy.on_shutdown(publishers.stop_all)
    while not rospy.is_shutdown():
        try:
            wanted = robot_set(rospy.get_param_cached("/stage/robots", []))
        except (KeyError, TypeError) as error:
            rospy.logerr_throttle(10.0, "robot_state_publishers: bad /stage/robots: %s" % error)
            wanted = None
        if wanted is not None:
            start, stop = publishers.update(wanted)
            what = "robot_state_publisher" if use_joint_states else "fixed frames"
            for name in start:
                rospy.loginfo("robot_state_publishers: %s of /%s up", what, name)
            for name in stop:
                rospy.loginfo("robot_state_publishers: %s of /%s gone", what, name)
        time.sleep(poll_period)  # wall time: works while sim time is paused or not started
    if launcher is not None:
        launcher.stop()


def static_tf_publisher():
    """A function that publishes [(parent, child, xyz, quaternion, stamp)] as one latched message
    on /tf_static (replacing the one before, which held the same frames and fewer robots')."""
    import rospy
    from geometry_msgs.msg import TransformStamped
    from tf2_msgs.msg import TFMessage

    pub = rospy.Publisher("/tf_static", TFMessage, queue_size=1, latch=True)

    def publish(frames):
        msg = TFMessage()
        for parent, child, xyz, q, stamp in frames:
            t = TransformStamped()
            t.header.stamp = stamp
            t.header.frame_id, t.child_frame_id = parent, child
            t.transform.translation.x, t.transform.translation.y, t.transform.translation.z = xyz
            (t.transform.rotation.x, t.transform.rotation.y, t.transform.rotation.z,
             t.transform.rotation.w) = q
            msg.transforms.append(t)
        pub.publish(msg)
    return publish
