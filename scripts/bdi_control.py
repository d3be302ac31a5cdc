#!/usr/bin/env python3
"""DRCSim's actionlib server atlas/bdi_control for the ASI: bdi_control.py [--help]."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.bdi_control import main

if __name__ == '__main__':
    sys.exit(main())
