"""keyboard_teleop.py as a person uses it: in a terminal (tmux), against a running
atlas.launch with DRCSim's actionlib server (bdi_control:=true, the default start). Keys are
sent and the screen is read: in the tutorial's hold `i` aborts and the screen says to press
S, which stands; then 2 steps, a longer stride, `i` walks them forward (the
robot's x on the screen grows), a capital steps the same two steps statically, one STEP goal
each (the x grows again), `Q` quits with status 0. Wall time about 50 s."""

from __future__ import annotations

import os
import re
import shutil
import subprocess
import sys
import time
from pathlib import Path

import pytest

pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace: source ./env.sh')
if shutil.which('roslaunch') is None or shutil.which('tmux') is None:
    pytest.skip('roslaunch or tmux is not on PATH (source env.sh)', allow_module_level=True)

from support.launch import TestLaunch
from tutorial_atlas_control import topics

pytestmark = pytest.mark.filterwarnings('ignore::DeprecationWarning')

SIM = '/atlas_sim'
TELEOP = Path(__file__).resolve().parents[2] / 'scripts' / 'keyboard_teleop.py'
SCREEN_TIMEOUT_S = 90.0
#: The terminal's width: the longest status line fits.
COLUMNS = 140


class Terminal:
    """A tmux session of its own (its own server socket) running one command."""

    def __init__(self, command: str, env: dict[str, str]) -> None:
        self.socket = f'tac_teleop_{os.getpid()}'
        # With $COLUMNS and $LINES in its environment (a fresh clone's CI run had
        # COLUMNS=80), the teleop still sizes its screen by the window.
        self.env = {**env, 'COLUMNS': '80', 'LINES': '24'}
        self._tmux('new-session', '-d', '-s', 'teleop', '-x', str(COLUMNS), '-y', '20',
                   f'{command}; echo EXITED $?; sleep 600')

    def _tmux(self, *args: str) -> str:
        return subprocess.run(['tmux', '-L', self.socket, *args], env=self.env, check=True,
                              capture_output=True, text=True, timeout=10).stdout

    def screen(self) -> str:
        return self._tmux('capture-pane', '-p', '-t', 'teleop')

    def keys(self, keys: str) -> None:
        self._tmux('send-keys', '-t', 'teleop', '-l', keys)

    def wait_for(self, text: str) -> str:
        """Until the screen shows `text`; the screen then."""
        deadline = time.monotonic() + SCREEN_TIMEOUT_S
        while text not in (screen := self.screen()):
            if time.monotonic() > deadline:
                pytest.fail(f'the screen did not show {text!r} within {SCREEN_TIMEOUT_S} s:\n'
                            f'{screen}')
            time.sleep(0.2)
        return screen

    def close(self) -> None:
        subprocess.run(['tmux', '-L', self.socket, 'kill-server'], env=self.env,
                       capture_output=True, timeout=10, check=False)


def robot_x(screen: str) -> float:
    match = re.search(r'robot: x\s+(-?[\d.]+)', screen)
    assert match, screen
    return float(match.group(1))


def test_keys_walk_the_robot_and_the_screen_says_how_it_went(tmp_path: Path) -> None:
    with TestLaunch(tmp_path, 'bdi_control:=true', 'record:=false') as launch:
        launch.wait(lambda: SIM in launch.subscribers(topics.ASI_COMMAND), 120.0,
                    f'{SIM} did not subscribe to {topics.ASI_COMMAND}')
        launch.wait_sim_until(1.5)  # the default start: the tutorial's hold, past the pin
        terminal = Terminal(f'{sys.executable} {TELEOP}', dict(launch.env))
        try:
            terminal.wait_for('last: ready')
            terminal.wait_for('behaviour USER')
            terminal.keys('i')  # in the hold: the goal aborts, and the screen says what to do
            terminal.wait_for('the robot is in USER: press S for Stand first')
            # Past the refusal's report (0.05 s): DRCSim's server would abort a goal on it.
            launch.wait_sim_until(launch.sim_time_s() + 0.1)
            terminal.keys('S')
            terminal.wait_for('stand: succeeded')
            start = robot_x(terminal.wait_for('behaviour STAND'))
            terminal.keys('2')
            terminal.wait_for('1-9 steps: 2')
            terminal.keys('=')
            terminal.wait_for('stride: 0.25 m')
            terminal.keys('i')
            walked = terminal.wait_for('forward, 2 steps: succeeded')
            assert robot_x(walked) - start > 0.15, walked
            terminal.keys('I')
            stepped = terminal.wait_for('forward step by step, step 2 of 2: succeeded')
            assert robot_x(stepped) - robot_x(walked) > 0.15, stepped
            terminal.keys('Q')
            terminal.wait_for('EXITED 0')
        finally:
            terminal.close()


def test_help_and_a_wrong_argument() -> None:
    done = subprocess.run([sys.executable, str(TELEOP), '--help'], capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 0 and 'u i o / j l / m , .' in done.stdout
    done = subprocess.run([sys.executable, str(TELEOP), 'forward'], capture_output=True,
                          text=True, timeout=60, check=False)
    assert done.returncode == 2
    assert done.stderr.strip() == ("keyboard_teleop.py: error: unexpected argument 'forward' "
                                   '(see --help)')


def test_without_a_terminal_one_line_and_status_1() -> None:
    """Through a pipe (no tty) curses cannot start: one line, before any ROS connection."""
    done = subprocess.run([sys.executable, str(TELEOP)], capture_output=True, text=True,
                          stdin=subprocess.DEVNULL, timeout=60, check=False)
    assert (done.returncode, done.stdout) == (1, '')
    assert done.stderr.strip() == (
        'keyboard_teleop.py: error: needs a terminal: its standard input and output must be a '
        'tty (run it in a terminal, not through a pipe or roslaunch)')
