#!/usr/bin/env python3
"""DRCSim's keyboard teleop for Atlas, in a terminal: keyboard_teleop.py [--help]."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.keyboard_teleop import main

if __name__ == '__main__':
    sys.exit(main())
