#!/usr/bin/env python3
"""Play a trajectory offline (no ROS), deterministically, to a bag: see `run_offline.py --help`."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.environment import run_script

if __name__ == '__main__':
    sys.exit(run_script('run_offline.py', 'tutorial_atlas_control.cli.run_offline'))
