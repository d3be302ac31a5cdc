#!/usr/bin/env python3
"""Walk the simulated Atlas through the AtlasSimInterface: walk_client.py [--help]."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.walk_client import main

if __name__ == '__main__':
    sys.exit(main())
