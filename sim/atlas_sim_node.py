#!/usr/bin/env python3
"""The MuJoCo Atlas simulator node (DRCSim's ROS interface); see atlas.launch."""

import sys

from tutorial_atlas_control.node.sim_node import main

if __name__ == '__main__':
    sys.exit(main())
