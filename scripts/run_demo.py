#!/usr/bin/env python3
"""The tutorial end to end, headless: `run_demo.py [TRAJECTORY]` (see --help)."""

import sys

from tutorial_atlas_control.demo import main

if __name__ == '__main__':
    sys.exit(main())
