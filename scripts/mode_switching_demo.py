#!/usr/bin/env python3
"""DRCSim's mode-switching demo against the simulator: mode_switching_demo.py [--help]."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.mode_switching import main

if __name__ == '__main__':
    sys.exit(main())
