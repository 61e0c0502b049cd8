# Installs the Python package src/mbot_navigation (catkin_python_setup in CMakeLists.txt);
# not for pip. Other modules of this package go into the same src/mbot_navigation folder.
from setuptools import setup

from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["mbot_navigation"], package_dir={"": "src"}))
