"""Stopping the simulator with the MuJoCo viewer open (atlas.launch gui:=true), under Xvfb.

Each way a user stops it must end the node with exit status 0: no segfault (the window's
thread destroying its window while the interpreter's exit terminates GLFW, see
node/viewer.py), no hang, no traceback. The status is the one roslaunch reports: on its
screen when the (required) node ends by itself ("process has finished cleanly", or
"process has died [pid N, exit code -11, ...]"), and in its log file when it stopped the
node on Ctrl-C ("process[atlas_sim-2]: SIGINT killed with return value -11").

Needs Xvfb, xdotool and ImageMagick (tools/setup.sh installs them) and `source ./env.sh`.
"""

from __future__ import annotations

import os
import re
import signal
from collections.abc import Callable
from pathlib import Path

import pytest

from support import xdisplay
from support.launch import TestLaunch

xdisplay.skip_module_unless_launchable()

WINDOW_NAME = 'MuJoCo'
NODE = '/atlas_sim'
#: Sim time (s) the viewer has drawn for before the stop: well past its first frames.
STOP_AT_S = 2.0
#: Fresh launches stopped per way: the segfault is a race between two threads at the
#: node's exit, which a single stop often misses.
ROUNDS = 2
#: roslaunch's report of the node's end, on its screen (the required node ended by itself;
#: no exit code: "finished cleanly") ...
DIED = re.compile(r'REQUIRED process \[atlas_sim-\d+\] has died!\s*process has '
                  r'(?:died \[pid \d+, exit code (-?\d+)|finished cleanly)')
#: ... and in its log file (roslaunch stopped it, after SIGINT or an escalation).
STOPPED = re.compile(r'process\[atlas_sim-\d+\]: SIG\w+ killed with return value (-?\d+)')
#: Signs of a crash in the node's output (it runs with output="screen").
CRASH_SIGNS = ('Traceback', 'Fatal Python error', 'Segmentation fault', 'X Error')


def use_display(monkeypatch: pytest.MonkeyPatch, display: str) -> None:
    """This process's environment, which TestLaunch passes on, as xdisplay.display_env's."""
    wanted = xdisplay.display_env(display)
    for name in set(os.environ) - set(wanted):
        monkeypatch.delenv(name)
    for name, value in wanted.items():
        monkeypatch.setenv(name, value)


def node_exit_status(launch: TestLaunch) -> int | None:
    """The simulator node's exit status as roslaunch reported it; None if it did not."""
    output = launch.output()
    if (died := DIED.search(output)) is not None:
        return int(died.group(1) or 0)
    for log in sorted((launch.log_path.parent / 'ros_log').rglob('roslaunch-*.log')):
        if (stopped := STOPPED.search(log.read_text(errors='replace'))) is not None:
            return int(stopped.group(1))
    return None


def wait_for_viewer(display: str, launch: TestLaunch) -> None:
    """Until the viewer's window exists; failing, with what the launch printed."""
    try:
        xdisplay.find_window(display, WINDOW_NAME)
    except pytest.fail.Exception as failure:
        pytest.fail(f'{failure.msg}; the launch ({launch.log_path}) said:\n{launch.output()}')


def rosnode_kill(launch: TestLaunch) -> None:
    result = launch.run('rosnode', 'kill', NODE)
    assert result.returncode == 0, result.stdout + result.stderr


def sigint_to_the_node(launch: TestLaunch) -> None:
    os.kill(launch.pid_of('atlas_sim_node.py'), signal.SIGINT)


def ctrl_c_to_the_launch(launch: TestLaunch) -> None:
    launch.interrupt()


@pytest.mark.parametrize('stop', [rosnode_kill, sigint_to_the_node, ctrl_c_to_the_launch],
                         ids=['rosnode kill', 'SIGINT to the node', 'Ctrl-C to the launch'])
def test_stopping_with_the_viewer_open_exits_cleanly(
        stop: Callable[[TestLaunch], None], tmp_path: Path,
        monkeypatch: pytest.MonkeyPatch) -> None:
    with xdisplay.xvfb(tmp_path / 'xvfb.log') as display:
        use_display(monkeypatch, display)
        for round_ in range(ROUNDS):
            launch = TestLaunch(tmp_path / f'round{round_}', 'gui:=true', 'record:=false')
            try:
                wait_for_viewer(display, launch)
                launch.wait_sim_until(STOP_AT_S)
                stop(launch)
                launch.wait_exit()
            finally:
                launch.close()
            output = launch.output()
            status = node_exit_status(launch)
            print(f'round {round_}: {NODE} exit status after {stop.__name__}: {status}')
            assert status == 0, (f'{NODE} ended with status {status} in round {round_}; see '
                                 f'{launch.log_path}:\n{output}')
            for sign in CRASH_SIGNS:
                assert sign not in output, f'{sign!r} in {launch.log_path}:\n{output}'
            assert 'cannot open the MuJoCo viewer' not in output
