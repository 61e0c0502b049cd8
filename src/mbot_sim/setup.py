# Installs the Python package src/mbot_sim (catkin_python_setup); not for pip.
from setuptools import setup

from catkin_pkg.python_setup import generate_distutils_setup

setup(**generate_distutils_setup(packages=["mbot_sim"], package_dir={"": "src"}))
