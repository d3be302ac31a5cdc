#!/usr/bin/env python3
"""Walk the VRC Task 2 course gate to gate: vrc_walker.py [--help]."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.vrc_walker import main

if __name__ == '__main__':
    sys.exit(main())
