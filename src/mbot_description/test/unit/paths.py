"""Paths shared by the plain Python tests (no ROS master, no sourced workspace needed)."""
import os
import sys

PACKAGE_DIR = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
REPO_DIR = os.path.abspath(os.path.join(PACKAGE_DIR, "..", ".."))
MAPS_DIR = os.path.join(REPO_DIR, "maps")
URDF_DIR = os.path.join(PACKAGE_DIR, "urdf")
MODELS = ("mbot", "mbot_omni")

# Import mbot_description and mbot_common (maps, world files) from the source tree, as the devel
# space would.
sys.path.insert(0, os.path.join(PACKAGE_DIR, "src"))
sys.path.insert(0, os.path.join(REPO_DIR, "src", "mbot_common", "src"))
