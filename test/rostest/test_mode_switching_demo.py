#!/usr/bin/env python3
"""rostest: DRCSim's mode-switching demo (scripts/mode_switching_demo.py) on the default
launch runs through without a fall: its cues said one line each, the walk walked, and the
robot standing under the user's PID at the end."""

from __future__ import annotations

import re
import subprocess
import sys
import unittest
from pathlib import Path

import rostest

PKG = 'tutorial_atlas_control'
DEMO = Path(__file__).resolve().parents[2] / 'scripts' / 'mode_switching_demo.py'
#: Wall-time bound of the demo (s): 21 s of sim time, a loaded host at a third of real time.
DEMO_TIMEOUT_S = 150.0
#: The pelvis stays above this (m); the four 0.25 m steps take it at least this far (m).
PELVIS_ABOVE_M = 0.8
WALKED_AT_LEAST_M = 0.6


class ModeSwitchingDemoTest(unittest.TestCase):
    def test_the_demo_runs_through_without_a_fall(self) -> None:
        done = subprocess.run([sys.executable, str(DEMO)], capture_output=True, text=True,
                              timeout=DEMO_TIMEOUT_S, check=False)
        print(done.stdout, done.stderr)
        self.assertEqual(done.returncode, 0, done.stdout + done.stderr)
        cues = [line for line in done.stdout.splitlines() if ' s  ' in line]
        self.assertEqual([line.split(' s  ')[1].split(':')[0] for line in cues], [
            'zeros', 'stand-prep pose', 'STAND_PREP', 'STAND',
            'STAND, arms and neck to the PID', 'WALK', 'USER, zeros'])
        found = re.search(r'no fall \(lowest pelvis ([0-9.]+) m\); walked ([0-9.]+) m; '
                          r'ended in USER', done.stdout)
        self.assertIsNotNone(found, done.stdout)
        self.assertGreater(float(found.group(1)), PELVIS_ABOVE_M)
        self.assertGreater(float(found.group(2)), WALKED_AT_LEAST_M)


if __name__ == '__main__':
    rostest.rosrun(PKG, 'mode_switching', ModeSwitchingDemoTest)
