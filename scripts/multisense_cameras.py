#!/usr/bin/env python3
"""The multisense_sl head's stereo cameras, rendered offscreen; see atlas.launch."""

import sys

from tutorial_atlas_control.cli.multisense_cameras import main

if __name__ == '__main__':
    sys.exit(main())
