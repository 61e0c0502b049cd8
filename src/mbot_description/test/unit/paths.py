"""Paths shared by the plain Python tests (no ROS master, no sourced workspace needed)."""
import os
import sys

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
REPO_DIR = os.path.abspath(os.path.join(PACKAGE_DIR, "..", ".."))
URDF_DIR = os.path.join(PACKAGE_DIR, "urdf")
MODELS = ("mbot", "mbot_omni")

# Import mbot_description and mbot_common (maps, world files) from the source tree, as the devel
# space would.
sys.path.insert(0, os.path.join(PACKAGE_DIR, "src"))
sys.path.insert(0, os.path.join(REPO_DIR, "src", "mbot_common", "src"))

from mbot_common.paths import find_maps_directory  # noqa: E402 (needs the path above)

MAPS_DIR = find_maps_directory(PACKAGE_DIR)  # the workspace's maps/, as the nodes find it
