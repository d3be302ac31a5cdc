#!/usr/bin/env python3
"""Plot numeric fields of ROS topics live, as rqt_plot did: see `plot_topics.py --help`."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.environment import run_script

if __name__ == '__main__':
    sys.exit(run_script('plot_topics.py', 'tutorial_atlas_control.cli.plot_topics'))
