"""Ctrl-C ends every script with exit status 130 and no traceback (docs/troubleshooting.md,
Script conventions).

Each script's main is called with the work it hands to the library replaced by a function
that raises KeyboardInterrupt, as Ctrl-C does in the middle of it; one script is also
interrupted for real, with SIGINT, while it simulates.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
from collections.abc import Callable
from pathlib import Path

import pytest

from tutorial_atlas_control.cli import (
    analyze_bag,
    plot_topics,
    replay_bag,
    run_demo,
    run_offline,
    state_publisher,
    traj_yaml,
)
from tutorial_atlas_control.cli.convention import EXIT_INTERRUPTED
from tutorial_atlas_control.demo import demo_node as demo
from tutorial_atlas_control.plotting import plot_topics_node as plot_node
from tutorial_atlas_control.processes import default_sigint

REPO = Path(__file__).resolve().parents[3]
TRAJECTORY_FILE = REPO / 'trajectories' / 'Traj_data2.yaml'
#: Long enough (s of sim time) that the run is still simulating when the signal comes.
LONG_SETTLE_S = '10000'
#: Wall-clock bounds (s): for the run to start simulating, and to end after the signal.
START_TIMEOUT_S = 60.0
EXIT_TIMEOUT_S = 30.0


def interrupt(*_args: object, **_kwargs: object) -> None:
    raise KeyboardInterrupt


@pytest.mark.parametrize(('main', 'target', 'argv'), [
    (analyze_bag.main, (analyze_bag, 'read_bag'), ['run.bag']),
    (analyze_bag.main, (analyze_bag, 'read_bag'), ['a.bag', '--compare', 'b.bag']),
    (replay_bag.main, (replay_bag, 'replay_bag'), ['run.bag']),
    (run_offline.main, (run_offline, 'run_offline'), [str(TRAJECTORY_FILE), 'touchdown']),
    (run_demo.main, (demo, 'run_demo'), ['touchdown']),
    (traj_yaml.main, (traj_yaml, 'load_trajectory'), [str(TRAJECTORY_FILE), 'touchdown']),
    (state_publisher.main, (state_publisher, 'matching_urdf'),
     ['state_publisher.py', str(REPO / 'sim' / 'atlas_v1.xml')]),
    (plot_topics.main, (plot_node, 'require_master'), ['/atlas/joint_states/position[19]']),
], ids=['analyze_bag', 'analyze_bag --compare', 'replay_bag', 'run_offline', 'run_demo',
        'traj_yaml', 'state_publisher', 'plot_topics'])
def test_ctrl_c_exits_130_quietly(main: Callable[[list[str]], int], target: tuple[object, str],
                                  argv: list[str], monkeypatch: pytest.MonkeyPatch,
                                  capsys: pytest.CaptureFixture[str]) -> None:
    monkeypatch.setattr(*target, interrupt)
    try:
        status = main(argv)
    except KeyboardInterrupt:
        pytest.fail('Ctrl-C escaped main: the user gets a traceback, not exit 130')
    assert status == EXIT_INTERRUPTED
    captured = capsys.readouterr()
    assert captured.err == '' and captured.out == ''


def sigint_blocked(pid: int, tid: str) -> bool:
    """Whether thread `tid` of process `pid` blocks SIGINT (its SigBlk in /proc)."""
    status = Path(f'/proc/{pid}/task/{tid}/status').read_text()
    mask = int(next(line.split()[1] for line in status.splitlines()
                    if line.startswith('SigBlk:')), 16)
    return bool(mask >> (signal.SIGINT - 1) & 1)


def signal_masks(pid: int) -> str:
    """Each thread's pending, blocked, ignored and caught signal masks (/proc), one line
    each: what a SIGINT that was not acted on became."""
    lines = []
    for tid in sorted(os.listdir(f'/proc/{pid}/task')):
        try:
            status = Path(f'/proc/{pid}/task/{tid}/status').read_text()
        except OSError:
            continue
        fields = dict(line.split(':', 1) for line in status.splitlines() if ':' in line)
        lines.append(f'{tid} {fields.get("Name", "").strip()}: ' + ' '.join(
            f'{key} {fields.get(key, "").strip()}'
            for key in ('SigPnd', 'ShdPnd', 'SigBlk', 'SigIgn', 'SigCgt')))
    return '\n'.join(lines)


def test_sigint_stops_run_offline_with_130_and_leaves_no_bag(tmp_path: Path) -> None:
    """A real Ctrl-C while the offline run simulates: exit 130, no traceback, no bag left;
    only the main thread can take it."""
    bag = tmp_path / 'run.bag'
    process = subprocess.Popen(
        # -X faulthandler: if it does not exit, SIGABRT makes it print where it hangs.
        [sys.executable, '-X', 'faulthandler', str(REPO / 'scripts' / 'run_offline.py'),
         str(TRAJECTORY_FILE),
         'touchdown', '--settle', LONG_SETTLE_S, '--bag', str(bag)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=dict(os.environ),
        preexec_fn=default_sigint)
    try:
        deadline = time.monotonic() + START_TIMEOUT_S
        # The partial bag appears once the run has started simulating.
        while not list(tmp_path.glob('.run.bag.*.partial')):
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, 'run_offline.py did not start simulating'
            time.sleep(0.05)
        # The kernel gives a process's SIGINT to any thread not blocking it; Python 3.11 acts
        # on it only in its main thread: numpy's OpenBLAS thread must block it.
        blocking = {tid: sigint_blocked(process.pid, tid)
                    for tid in os.listdir(f'/proc/{process.pid}/task')}
        assert blocking.pop(str(process.pid)) is False, 'the main thread blocks SIGINT'
        assert all(blocking.values()), f'threads taking SIGINT besides the main one: {blocking}'
        process.send_signal(signal.SIGINT)
        try:
            out, err = process.communicate(timeout=EXIT_TIMEOUT_S)
        except subprocess.TimeoutExpired:  # the masks and stacks say where it went
            masks = signal_masks(process.pid)
            process.send_signal(signal.SIGABRT)
            _out, err = process.communicate(timeout=EXIT_TIMEOUT_S)
            pytest.fail(f'run_offline.py did not exit within {EXIT_TIMEOUT_S:g} s of SIGINT; '
                        f'its threads\' signal masks (SIGINT is 0x2):\n{masks}\nits threads:'
                        f'\n{err}')
    finally:
        if process.poll() is None:
            process.kill()
            process.communicate()
    assert process.returncode == EXIT_INTERRUPTED, err
    assert 'Traceback' not in err and err == '', err
    assert out == ''
    assert list(tmp_path.iterdir()) == [], 'a partial or complete bag was left behind'


#: Run in a fresh interpreter: the compiled modules (extension files) that run_offline's main
#: imports only once it runs.
LATE_EXTENSIONS = """
import json, sys
from tutorial_atlas_control.cli import run_offline
before = set(sys.modules)
status = run_offline.main(sys.argv[1:])
late = sorted(name for name in set(sys.modules) - before
              if str(getattr(sys.modules[name], '__file__', '') or '').endswith('.so'))
print(json.dumps([status, late]))
"""


def test_run_offline_imports_no_compiled_module_once_it_runs(tmp_path: Path) -> None:
    """A Ctrl-C landing in a compiled module's import can be lost there (numpy 2.x imports
    numpy.random at its first use, and its Cython part swallowed the KeyboardInterrupt: the
    run went on simulating). The script imports them all before it runs, with SIGINT
    blocked (cli/environment.py)."""
    result = subprocess.run(
        [sys.executable, '-c', LATE_EXTENSIONS, str(TRAJECTORY_FILE), 'touchdown',
         '--settle', '0.1', '--bag', str(tmp_path / 'run.bag')],
        capture_output=True, text=True, check=True, timeout=START_TIMEOUT_S)
    status, late = json.loads(result.stdout.splitlines()[-1])
    assert status == 0
    assert late == [], f'imported while running: {late}'


def test_ctrl_c_during_the_demo_names_the_bag_recorded_so_far(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch,
        capsys: pytest.CaptureFixture[str]) -> None:
    def record_then_interrupt(*_args: object, **_kwargs: object) -> None:
        (tmp_path / 'atlas_2026-01-01-00-00-00.bag').write_bytes(b'')  # closed by the launch
        raise KeyboardInterrupt

    monkeypatch.setattr(demo, 'run_demo', record_then_interrupt)
    assert run_demo.main(['touchdown', '--bag-dir', str(tmp_path)]) == EXIT_INTERRUPTED
    bag = tmp_path / 'atlas_2026-01-01-00-00-00.bag'
    assert capsys.readouterr().err == (f'run_demo.py: interrupted; the run so far is in {bag} '
                                       f'(analyze_bag.py {bag})\n')
