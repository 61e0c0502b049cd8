"""Find the robots of a running simulation from the topics it publishes."""
import rospy


def discover_robots(suffix="/scan"):
    """Sorted robot namespaces (without slashes) that publish `/<ns><suffix>`."""
    names = set()
    for topic, _type in rospy.get_published_topics():
        if topic.endswith(suffix):
            ns = topic[: -len(suffix)].strip("/")
            if ns and "/" not in ns:
                names.add(ns)
    return sorted(names)
