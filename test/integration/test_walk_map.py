"""walk_map.py: real walks on a tiny grid (2 strides x 1 duration x 2 seeds, 2 steps each)
on a local Dask cluster, the map written as CSV and PNG; the refusals (one line; exit 1 and
nothing written, or argparse's exit 2). The map's arithmetic: test/unit/search/."""

from __future__ import annotations

import csv
from functools import partial
from pathlib import Path

import pytest

from support.scripts import run_script
from tutorial_atlas_control.cli import walk_map as walk_map_cli

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

_walk_map = partial(run_script, 'walk_map.py')


def test_a_tiny_map_of_real_walks(tmp_path: Path) -> None:
    """Through the script: its start-up and exit status with the map's figures."""
    result = _walk_map('--strides', '0.2', '0.25', '--durations', '0.6', '--seeds', '2',
                       '--first-seed', '5', '--steps', '2', '--workers', '1', '--no-progress',
                       '--out', str(tmp_path / 'map'))
    assert result.returncode == 0, result.stderr
    cells = list(csv.DictReader((tmp_path / 'map.csv').open()))
    assert [(c['stride_m'], c['duration_s'], c['seeds'], c['walked']) for c in cells] == [
        ('0.2', '0.6', '2', '2'), ('0.25', '0.6', '2', '2')]
    runs = list(csv.DictReader((tmp_path / 'map_runs.csv').open()))
    assert [(r['stride_m'], r['seed'], r['walked']) for r in runs] == [
        ('0.2', '5', 'True'), ('0.2', '6', 'True'), ('0.25', '5', 'True'), ('0.25', '6', 'True')]
    assert all(float(r['worst_landing_m']) < 0.05 for r in runs)
    assert len({r['worst_landing_m'] for r in runs}) == 4  # each seed its own walk
    assert (tmp_path / 'map.png').read_bytes()[:8] == b'\x89PNG\r\n\x1a\n'
    assert result.stdout.strip().endswith(f'runs: {tmp_path / "map_runs.csv"}')
    assert 'fastest where 2 of 2 seeds walk: 0.25 m every 0.6 s (0.42 m/s)' in result.stdout


@pytest.mark.parametrize(('args', 'message'), [
    (['--strides', '0.5'], 'strides must be in (0, 0.40] m'),
    (['--out', 'no_such_dir/map'], 'does not exist'),
    (['--scheduler', 'tcp://127.0.0.1:9'], 'cannot reach the Dask scheduler at tcp://127.0.0.1:9'),
])
def test_bad_input_one_line_exit_1_nothing_written(tmp_path: Path, args: list[str],
                                                    message: str,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """The first through the script (its wrapper's exit status and line), the others through
    main in this process: no new interpreter's imports (about 1.5 CPU s a start) each."""
    args = [arg.replace('no_such_dir', str(tmp_path / 'no_such_dir')) for arg in args]
    if '--out' not in args:
        args += ['--out', str(tmp_path / 'map')]
    args += ['--steps', '1', '--seeds', '1', '--no-progress']
    if '--strides' in args:
        result = _walk_map(*args)
        status, stderr = result.returncode, result.stderr
    else:
        capsys.readouterr()
        status, stderr = walk_map_cli.main(args), capsys.readouterr().err
    assert status == 1
    lines = stderr.splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith('walk_map.py: error: ') and message in lines[0]
    assert list(tmp_path.iterdir()) == []


def test_a_wrong_command_line_is_argparses_exit_2(tmp_path: Path) -> None:
    result = _walk_map('--seeds', '0', '--out', str(tmp_path / 'map'))
    assert result.returncode == 2
    assert 'walk_map.py: error: argument --seeds' in result.stderr
    assert list(tmp_path.iterdir()) == []
