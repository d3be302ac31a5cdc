"""tools/course_walk.py's arguments: a bad seed, waypoint, gate, stride, world or mud damping
is one line and exit status 2, before any physics runs."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

TOOL = Path(__file__).resolve().parents[2] / 'tools' / 'course_walk.py'


@pytest.mark.parametrize('args, line', [
    (['x'], "course_walk.py: error: argument SEED: seed 'x' is not an integer or none"),
    (['--waypoints', '1;2', '1'],
     "course_walk.py: error: argument --waypoints: waypoint '1;2' is not X,Y"),
    (['--to', 'gate_5', '1'], "course_walk.py: error: argument --to: invalid choice: "
     "'gate_5' (choose from 'gate_0', 'gate_1', 'gate_2', 'gate_3', 'gate_4')"),
    (['--world', 'nowhere', 'none'],
     "course_walk.py: unknown world 'nowhere'; the VRC Task 2 worlds are vrc_task_2, "
     'vrc_task_2_mud_start, vrc_task_2_uneven_start, vrc_task_2_rubble_start'),
    (['--mud-damping', 'forty', '1'], "course_walk.py: error: argument --mud-damping: mud "
     "damping must be a finite number >= 0 (N s/m), got 'forty'"),
    (['--mud-damping=-1', '1'], "course_walk.py: error: argument --mud-damping: mud damping "
     "must be a finite number >= 0 (N s/m), got '-1'"),
    (['--stride', '-1', '1'], 'course_walk.py: error: a route gait needs positive finite '
     'numbers (a turning stride of 0 turns in place): RouteGait(stride_m=-1.0, '
     'turn_step_rad=0.2, turn_stride_m=0.08, width_m=0.24, duration_s=0.63, fit_ground=True, '
     'ground_flat_m=0.01, start_in_place=False, inside_in_place=False, turn_slowdown_m=0.0)')])
def test_bad_arguments_are_one_line_and_exit_2(args: list[str], line: str) -> None:
    done = subprocess.run([sys.executable, str(TOOL), *args], capture_output=True, text=True,
                          timeout=60, check=False)
    assert done.returncode == 2
    assert done.stdout == ''
    assert done.stderr.splitlines()[-1] == line
    assert 'Traceback' not in done.stderr
