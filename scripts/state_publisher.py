#!/usr/bin/env python3
"""Debian's robot_state_publisher on the simulated model's URDF; see atlas.launch."""

import sys

from tutorial_atlas_control.cli.state_publisher import main

if __name__ == '__main__':
    sys.exit(main())
