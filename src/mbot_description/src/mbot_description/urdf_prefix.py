"""Per-robot URDF prefixing.

ROS Noetic's robot_state_publisher has no ``tf_prefix``: it names each frame after its URDF link.
So every robot gets its own copy of the URDF in which each link and joint name carries the
robot's name, ``base_link`` -> ``robot_3/base_link``, and robot_state_publisher then publishes
``robot_3/base_footprint -> robot_3/base_link -> robot_3/base_laser`` as docs/ARCHITECTURE.md lists.

What is renamed (everything that names a link or a joint):
  <link name>, <joint name>, <joint><parent link> and <child link>, <joint><mimic joint>,
  <transmission><joint name>, <gazebo reference>.
What is not: materials, the robot's name, geometry, anything else.
"""
import re
import sys
import xml.etree.ElementTree as ET

# A ROS graph name segment path: robot_3, fleet/robot_3. No leading slash (tf2 rejects it).
_PREFIX_RE = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*(/[A-Za-z_][A-Za-z0-9_]*)*$")


def normalize_prefix(prefix):
    """Return ``prefix`` without leading or trailing slashes; raise ValueError if it is no name."""
    name = prefix.strip("/")
    if not _PREFIX_RE.match(name):
        raise ValueError(
            "prefix: expected a robot name such as robot_3 (letters, digits, _ and /), got %r"
            % prefix
        )
    return name


def _prefixed(name, prefix):
    """``prefix/name``; a name that already carries the prefix is left alone (idempotent)."""
    if name.startswith(prefix + "/"):
        return name
    return prefix + "/" + name


def prefix_urdf(xml_text, prefix):
    """Return the URDF ``xml_text`` with every link and joint name prefixed with ``prefix/``.

    :param xml_text: a URDF document (str)
    :param prefix: the robot name, e.g. ``robot_3`` (leading/trailing slashes are dropped)
    :raises ValueError: the prefix is no valid name, or the text is not a URDF
    """
    prefix = normalize_prefix(prefix)
    # Keep the comments, they document the numbers (insert_comments needs Python >= 3.8).
    parser = ET.XMLParser(target=ET.TreeBuilder(insert_comments=True))
    try:
        robot = ET.fromstring(xml_text, parser=parser)
    except ET.ParseError as error:
        raise ValueError("not valid XML: %s" % error)
    if robot.tag != "robot":
        raise ValueError("expected a <robot> root element, got <%s>" % robot.tag)

    def rename(element, attribute):
        value = element.get(attribute)
        if value is not None:
            element.set(attribute, _prefixed(value, prefix))

    names = set()
    for link in robot.findall("link"):
        names.add(link.get("name"))
        rename(link, "name")
    for joint in robot.findall("joint"):
        names.add(joint.get("name"))
        rename(joint, "name")
        for tag in ("parent", "child"):
            for end in joint.findall(tag):
                rename(end, "link")
        for mimic in joint.findall("mimic"):
            rename(mimic, "joint")
    for transmission in robot.findall("transmission"):
        for joint in transmission.findall("joint"):
            rename(joint, "name")
    for gazebo in robot.findall("gazebo"):
        if gazebo.get("reference") in names:
            rename(gazebo, "reference")
    return '<?xml version="1.0"?>\n' + ET.tostring(robot, encoding="unicode") + "\n"


def main(argv=None):
    """Command line: ``prefix_urdf URDF_PATH PREFIX`` prints the prefixed URDF to stdout."""
    argv = sys.argv[1:] if argv is None else argv
    if len(argv) != 2:
        sys.stderr.write("usage: prefix_urdf URDF_PATH PREFIX\n")
        return 2
    path, prefix = argv
    try:
        with open(path) as urdf_file:
            text = urdf_file.read()
    except OSError as error:
        sys.stderr.write("prefix_urdf: %s: cannot read the URDF: %s\n" % (path, error.strerror))
        return 1
    try:
        sys.stdout.write(prefix_urdf(text, prefix))
    except ValueError as error:
        sys.stderr.write("prefix_urdf: %s: %s\n" % (path, error))
        return 1
    return 0
