#!/usr/bin/env python3
"""CMA-ES over a trajectory, through sweep: see `search.py --help`."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.environment import run_script

if __name__ == '__main__':
    sys.exit(run_script('search.py', 'tutorial_atlas_control.cli.search'))
