#!/usr/bin/env python3
"""Play a trajectory offline (no ROS), deterministically, to a bag: see `run_offline.py --help`."""

import sys
from pathlib import Path

try:
    import tutorial_atlas_control  # noqa: F401
except ImportError:  # running from a source checkout without catkin
    sys.path.insert(0, str(Path(__file__).resolve().parent.parent / 'src'))

from tutorial_atlas_control.offline_run import main

if __name__ == '__main__':
    sys.exit(main())
