"""One robot_state_publisher per simulated robot, for any world file and for robots spawned or
removed at run time.

stage_node keeps the list of its robots in the parameter ``/stage/robots`` (``[{name, model}]``).
This helper watches that list; for each new robot it sets ``/<name>/robot_description`` to the
robot's URDF with every link and joint prefixed ``<name>/`` (mbot_description's prefix_urdf, the
same text description.launch sets) and starts ``robot_state_publisher`` in the namespace
``/<name>``, which then publishes ``<name>/base_footprint -> <name>/base_link -> <name>/base_laser``
(and the wheels, from ``/<name>/joint_states``). For a removed robot it stops that process and
deletes the parameter.
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
    """Node: poll ``/stage/robots`` every ``~poll_period`` wall seconds (default 0.5)."""
    import time

    import roslaunch
    import rospkg
    import rospy

    rospy.init_node("robot_state_publishers")
    poll_period = float(rospy.get_param("~poll_period", 0.5))  # [s wall]
    publish_frequency = float(rospy.get_param("~publish_frequency", 50.0))  # [Hz]
    description_dir = rospkg.RosPack().get_path("mbot_description")

    launcher = roslaunch.scriptapi.ROSLaunch()
    launcher.start()
    publishers = RobotStatePublishers(launcher, rospy.set_param, rospy.delete_param,
                                      description_dir, publish_frequency)
    rospy.on_shutdown(publishers.stop_all)
    while not rospy.is_shutdown():
        try:
            wanted = robot_set(rospy.get_param("/stage/robots", []))
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
