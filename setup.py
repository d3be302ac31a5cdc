"""Installs the package's Python logic (src/tutorial_atlas_control) for catkin."""

from catkin_pkg.python_setup import generate_distutils_setup
from setuptools import setup

setup(**generate_distutils_setup(
    packages=[
        'tutorial_atlas_control',
        'tutorial_atlas_control.asi',
        'tutorial_atlas_control.balance',
        'tutorial_atlas_control.bags',
        'tutorial_atlas_control.cli',
        'tutorial_atlas_control.command',
        'tutorial_atlas_control.course',
        'tutorial_atlas_control.demo',
        'tutorial_atlas_control.msgs',
        'tutorial_atlas_control.node',
        'tutorial_atlas_control.offline',
        'tutorial_atlas_control.plotting',
        'tutorial_atlas_control.search',
        'tutorial_atlas_control.sensors',
        'tutorial_atlas_control.sim',
        'tutorial_atlas_control.stepping',
        'tutorial_atlas_control.stereo',
        'tutorial_atlas_control.trajectories',
        'tutorial_atlas_control.walking',
    ],
    package_dir={'': 'src'},
))
