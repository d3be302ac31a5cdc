#!/usr/bin/env python3
"""Where the robot walks, over stride x step duration x seed, on Dask: see `walk_map.py --help`."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.environment import run_script

if __name__ == '__main__':
    sys.exit(run_script('walk_map.py', 'tutorial_atlas_control.cli.walk_map'))
