#!/usr/bin/env python3
"""The VRC course walked over its variants x seeds, on Dask: see `course_sweep.py --help`."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.environment import run_script

if __name__ == '__main__':
    sys.exit(run_script('course_sweep.py', 'tutorial_atlas_control.cli.course_sweep'))
