#!/usr/bin/env python3
"""The MuJoCo Atlas simulator node (DRCSim's ROS interface); see atlas.launch."""

import sys

from tutorial_atlas_control.cli.atlas_sim import main

if __name__ == '__main__':
    sys.exit(main())
