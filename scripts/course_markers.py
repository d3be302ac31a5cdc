#!/usr/bin/env python3
"""The VRC course's terrain, gates, pen and mud as rviz markers; see vrc_task_2.launch."""

import sys

from tutorial_atlas_control.cli.course_markers import main

if __name__ == '__main__':
    sys.exit(main())
