"""Network helpers without ROS."""
import socket


def free_port():
    """A TCP port on this machine that nothing listens on now: for a ROS master of one's own
    (tests, benchmarks, a scenario run), so that two runs side by side never share a master."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]
