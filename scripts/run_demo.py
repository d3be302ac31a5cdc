#!/usr/bin/env python3
"""The tutorial end to end, headless: `run_demo.py [TRAJECTORY]` (see --help)."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.run_demo import main

if __name__ == '__main__':
    sys.exit(main())
