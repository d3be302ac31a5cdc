#!/usr/bin/env python3
"""The tutorial end to end, headless: `run_demo.py [TRAJECTORY]` (see --help)."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.environment import run_script

if __name__ == '__main__':
    sys.exit(run_script('run_demo.py', 'tutorial_atlas_control.cli.run_demo'))
