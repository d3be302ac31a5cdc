#!/usr/bin/env python3
"""Play a YAML file's trajectory on the simulated Atlas: traj_yaml.py YAML_FILE TRAJECTORY_NAME."""

import sys
from pathlib import Path

sys.path.append(str(Path(__file__).resolve().parent.parent / 'src'))  # a clone without catkin
from tutorial_atlas_control.cli.traj_yaml import main

if __name__ == '__main__':
    sys.exit(main())
