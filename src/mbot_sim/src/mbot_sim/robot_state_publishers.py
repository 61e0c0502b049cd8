"""One robot_state_publisher per simulated robot, for any world file and for robots spawned or
removed at run time.

stage_node keeps the list of its robots in the parameter ``/stage/robots`` (``[{name, model}]``).
This helper watches that list; for each new robot it sets ``/<name>/robot_description`` to the
robot's URDF with every link and joint prefixed ``<name>/`` (mbot_description's prefix_urdf, the
same text description.launch sets) and starts ``robot_state_publisher`` in the namespace
``/<name>``, which then publishes ``<name>/base_footprint -> <name>/base_link -> <name>/base_laser``
on ``/tf_static``, once. The wheels' transforms come from stage_node itself (``~wheel_tf_rate``,
as Gazebo's diff drive plugin's ``publishWheelTF``), so each robot_state_publisher is started
with ``joint_states`` remapped to an unused name: robot_state_publisher 1.15 asks the master for
``tf_prefix`` on every joint_states message, and at 50 Hz per robot those calls were all of the
master's steady load. With ``~use_joint_states: true`` (stage_node's ``wheel_tf_rate: 0``) the
publishers read ``/<name>/joint_states`` and publish the wheels, the usual way. For a removed
robot it stops that process and deletes the parameter.
"""
import os


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


class RobotStatePublishers(object):
    """Starts and stops the robot_state_publisher processes (roslaunch's scriptapi)."""

    #: where joint_states goes when the simulator publishes the wheels (nobody publishes there)
    UNUSED_JOINT_STATES = "robot_state_publisher/joint_states_unused"

    def __init__(self, launcher, set_param, delete_param, description_dir, publish_frequency=50.0,
                 use_joint_states=False):
        self._launcher = launcher          # roslaunch.scriptapi.ROSLaunch, started
        self._use_joint_states = use_joint_states
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
            remaps = [] if self._use_joint_states else [("joint_states", self.UNUSED_JOINT_STATES)]
            node = roslaunch.core.Node(
                "robot_state_publisher", "robot_state_publisher", name="robot_state_publisher",
                namespace="/" + name, output="log", remap_args=remaps,
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

    launcher = roslaunch.scriptapi.ROSLaunch()
    launcher.start()
    publishers = RobotStatePublishers(launcher, rospy.set_param, rospy.delete_param,
                                      description_dir, publish_frequency, use_joint_states)
    rospy.on_shutdown(publishers.stop_all)
    while not rospy.is_shutdown():
        try:
            wanted = robot_set(rospy.get_param_cached("/stage/robots", []))
        except (KeyError, TypeError) as error:
            rospy.logerr_throttle(10.0, "robot_state_publishers: bad /stage/robots: %s" % error)
            wanted = None
        if wanted is not None:
            start, stop = publishers.update(wanted)
            for name in start:
                rospy.loginfo("robot_state_publishers: started /%s/robot_state_publisher", name)
            for name in stop:
                rospy.loginfo("robot_state_publishers: stopped /%s/robot_state_publisher", name)
        time.sleep(poll_period)  # wall time: works while sim time is paused or not started
    launcher.stop()
