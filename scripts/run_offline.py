#!/usr/bin/env python3
"""Play a trajectory offline (no ROS), deterministically, to a bag: see `run_offline.py --help`."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.run_offline import main

if __name__ == '__main__':
    sys.exit(main())
