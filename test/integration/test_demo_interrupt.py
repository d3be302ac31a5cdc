"""Ctrl-C in the middle of `run_demo.py`: exit 130, no traceback, launch stopped, bag closed.

The demo's Ctrl-C path is the one that must clean up after itself: the signal arrives while
traj_yaml.py plays, and run_demo must still stop atlas.launch (its master, simulator and
recorder) before it exits.
"""

from __future__ import annotations

import os
import queue
import re
import signal
import socket
import subprocess
import sys
import threading
from pathlib import Path
from typing import IO

import pytest

from tutorial_atlas_control.processes import default_sigint

REPO = Path(__file__).resolve().parents[2]
RUN_DEMO = REPO / 'scripts' / 'run_demo.py'
#: Exit status on Ctrl-C (docs/troubleshooting.md, Script conventions).
EXIT_INTERRUPTED = 130
#: Wall-clock bounds (s): until traj_yaml.py starts (atlas.launch up, torso unpinned), and
#: from the signal to the demo's exit (it stops roslaunch, which waits for its nodes).
START_TIMEOUT_S = 300.0
EXIT_TIMEOUT_S = 120.0
#: The progress line run_demo prints when it starts traj_yaml.py, and the one naming the port.
PLAYING = 'demo: rosrun tutorial_atlas_control traj_yaml.py'
MASTER_PORT = re.compile(r'master on port (\d+)')


def lines_of(stream: IO[str]) -> queue.Queue[str | None]:
    """The stream's lines, read by a thread (None at its end), so waits can have deadlines."""
    lines: queue.Queue[str | None] = queue.Queue()

    def read() -> None:
        for line in stream:
            lines.put(line)
        lines.put(None)

    threading.Thread(target=read, daemon=True).start()
    return lines


def test_ctrl_c_while_playing_stops_everything_and_exits_130(tmp_path: Path) -> None:
    pytest.importorskip('osrf_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
    env = dict(os.environ, ROS_LOG_DIR=str(tmp_path / 'ros_log'))
    process = subprocess.Popen(
        [sys.executable, '-u', str(RUN_DEMO), 'touchdown', '--video-fps', '0',
         '--bag-dir', str(tmp_path)],
        env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=default_sigint)
    try:
        assert process.stdout is not None
        lines = lines_of(process.stdout)
        seen: list[str] = []
        while not seen or not seen[-1].startswith(PLAYING):
            line = lines.get(timeout=START_TIMEOUT_S)
            assert line is not None, 'run_demo.py ended before playing:\n' + ''.join(seen)
            seen.append(line)
        process.send_signal(signal.SIGINT)
        status = process.wait(timeout=EXIT_TIMEOUT_S)
        stderr = process.stderr.read() if process.stderr else ''
    finally:
        if process.poll() is None:
            process.kill()
            process.wait()
    assert status == EXIT_INTERRUPTED, stderr
    assert 'Traceback' not in stderr, stderr
    port = MASTER_PORT.search(seen[0])
    assert port, seen[0]
    with pytest.raises(OSError), socket.create_connection(('127.0.0.1', int(port[1])), 1.0):
        pass  # the demo's master is gone with its launch
    assert not list(tmp_path.glob('atlas_*.bag.active')), 'the recorder did not close its bag'
    bag, = tmp_path.glob('atlas_*.bag')
    assert stderr.splitlines()[-1] == (f'run_demo.py: interrupted; the run so far is in {bag} '
                                       f'(analyze_bag.py {bag})'), stderr
