"""Installs the package's Python logic (src/tutorial_atlas_control) for catkin."""

from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=['tutorial_atlas_control'],
    package_dir={'': 'src'},
))
