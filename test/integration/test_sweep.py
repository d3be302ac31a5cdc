"""sweep.py: many offline runs on Dask; the table, its determinism, the tutorial's outcomes,
and the refusals (one line, exit 1, nothing written)."""

from __future__ import annotations

import json
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import pytest

from support.scripts import interrupt_script, run_script
from tutorial_atlas_control.cli import sweep as sweep_cli
from tutorial_atlas_control.search.sweep import (
    SweepEngine,
    SweepInputs,
    build_specs,
    table_texts,
)

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

REPO = Path(__file__).resolve().parents[2]
_sweep = partial(run_script, 'sweep.py')
TRAJ_DATA2 = REPO / 'trajectories' / 'Traj_data2.yaml'
#: The tutorial's falls offline, s after the first command, to the README's printed precision
#: (10 ms: "1.83 s offline"): a sweep's run is run_offline.py's, deterministic, so no live
#: tolerance.
FALL_AFTER_FIRST_COMMAND_S = {'step_and_fall': 1.83, 'touchdown_exhausted': 6.81}
FALL_TIME_DECIMALS = 2
UPRIGHT_ABOVE_M = 0.7
#: Short trajectories: a fifth of a second each, so that a determinism sweep costs seconds.
TINY = """\
bend:
  - [0.2, "0 0 0 0  0 0 -0.3 0.6 -0.3 0  0 0 -0.3 0.6 -0.3 0  0 0 0 0 0 0  0 0 0 0 0 0"]
arms:
  - [0.2, "0 0 0 0  0 0 0 0 0 0  0 0 0 0 0 0  0 -0.5 0 1 0 0  0 0.5 0 -1 0 0"]
"""


@dataclass(frozen=True)
class Ran:
    """A sweep's outcome, as subprocess.CompletedProcess gives the script's."""

    returncode: int
    stdout: str
    stderr: str


def _sweep_here(capsys: pytest.CaptureFixture[str], *args: str) -> Ran:
    """sweep.py's main in this process, its output captured: no new interpreter's imports
    (1.5-2 CPU s a start) for what is the sweep's, not the script's. The script itself, its
    start-up, exit status and one-line errors, is test_ctrl_c_keeps_the_finished_rows' and
    the missing file's case of test_bad_input_one_line_exit_1_nothing_written."""
    capsys.readouterr()
    status = sweep_cli.main(list(args))
    captured = capsys.readouterr()
    return Ran(status, captured.out, captured.err)


@pytest.fixture(scope='module')
def tiny_file(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp('tiny') / 'tiny.yaml'
    path.write_text(TINY)
    return path


def test_same_table_on_one_and_two_workers(tiny_file: Path) -> None:
    inputs = SweepInputs([(str(tiny_file), 'bend'), (str(tiny_file), 'arms')],
                         [str(REPO / 'config' / 'atlas_controller.yaml')],
                         gain_scales=(0.5, 1.0), time_scales=(1.0,), settle_s=0.3, seed=7)
    specs = build_specs(inputs)
    tables = []
    for workers in (1, 2):
        with SweepEngine(workers) as engine:
            outcome = engine.run(specs, progress=False)
        assert not outcome.interrupted
        tables.append(table_texts(outcome.rows))
    assert tables[0] == tables[1]
    rows = json.loads(tables[0][1])
    assert [row['index'] for row in rows] == [0, 1, 2, 3]
    assert [row['seed'] for row in rows] == [7, 8, 9, 10]
    assert [(row['name'], row['gain_scale']) for row in rows] == [
        ('bend', 0.5), ('bend', 1.0), ('arms', 0.5), ('arms', 1.0)]
    # The runs differ (half gains sag more): the table is not one row copied.
    assert rows[0]['tracking_rms_rad'] != rows[1]['tracking_rms_rad']


def test_tutorial_trajectories_classified(tmp_path: Path,
                                          capsys: pytest.CaptureFixture[str]) -> None:
    """In this process, on one worker (the cluster of two: test_same_table_on_one_and_two_
    workers, test_ctrl_c_keeps_the_finished_rows)."""
    out = tmp_path / 'tutorial'
    result = _sweep_here(capsys, str(TRAJ_DATA2), 'step_and_fall', 'touchdown',
                         'touchdown_exhausted', '--workers', '1', '--out', str(out),
                         '--no-progress')
    assert result.returncode == 0, result.stderr
    assert result.stdout.splitlines()[-1].startswith('sweep: 3 runs, 1 stayed up; table: ')
    rows = {row['name']: row for row in json.loads((tmp_path / 'tutorial.json').read_text())}
    for name, expected_s in FALL_AFTER_FIRST_COMMAND_S.items():
        assert rows[name]['fell'] is True
        assert round(rows[name]['fall_time_s'], FALL_TIME_DECIMALS) == expected_s, name
        assert rows[name]['pelvis_z_end_m'] < 0.5
    touchdown = rows['touchdown']
    assert touchdown['fell'] is False and touchdown['fall_time_s'] is None
    assert touchdown['pelvis_z_min_m'] > UPRIGHT_ABOVE_M
    assert touchdown['stood_after_s'] == pytest.approx(3.0)
    assert abs(touchdown['r_foot_dx_m']) < 0.01 and abs(touchdown['l_foot_dx_m']) < 0.01
    # step_and_fall lifts its right foot (its first waypoint) before it falls.
    assert rows['step_and_fall']['r_foot_lift_max_m'] > 0.03
    header = (tmp_path / 'tutorial.csv').read_text().splitlines()[0]
    assert header.startswith('index,trajectory,name,gains,gain_scale,time_scale,push,'
                             'latency_ms,seed,played_s,fell,fall_time_s,')


def test_push_topples_touchdown(tmp_path: Path, tiny_file: Path,
                                capsys: pytest.CaptureFixture[str]) -> None:
    """A 0.2 s, 300 N forward shove 1 s into touchdown fells it; the same run unpushed stands."""
    out = tmp_path / 'push'
    result = _sweep_here(capsys, str(TRAJ_DATA2), 'touchdown', '--push', 'none',
                         '--push', '1:300,0,0:0.2', '--workers', '1', '--out', str(out),
                         '--no-progress', '--settle', '1')
    assert result.returncode == 0, result.stderr
    rows = json.loads((tmp_path / 'push.json').read_text())
    assert [row['push'] for row in rows] == ['', '1:300,0,0:0.2']
    assert rows[0]['fell'] is False
    assert rows[1]['fell'] is True and rows[1]['pelvis_dx_m'] > 0.3  # forward, the push's way


def test_ctrl_c_keeps_the_finished_rows(tmp_path: Path, tiny_file: Path) -> None:
    """Ctrl-C once the first of two runs has finished (the second plays 10000 times slower):
    exit 130, one line saying how many rows were kept, and the table holds that row."""
    result = interrupt_script('sweep.py', str(tiny_file), 'bend', '--time-scale', '1', '10000',
                              '--settle', '0.3', '--workers', '2', '--out', 'table',
                              ready=lambda err: '1/2' in err, cwd=tmp_path)
    assert result.returncode == 130, result
    assert 'Traceback' not in result.stderr
    last = result.stderr.replace('\r', '\n').strip().splitlines()[-1]
    assert last == ('sweep.py: interrupted: kept the 1 of 2 runs that finished in table.csv '
                    'and table.json'), result.stderr
    rows = json.loads((tmp_path / 'table.json').read_text())
    assert [(row['index'], row['time_scale']) for row in rows] == [(0, 1.0)]
    assert len((tmp_path / 'table.csv').read_text().splitlines()) == 2  # header, one row


@pytest.mark.parametrize('args, message', [
    (['missing.yaml', 'bend'], 'missing.yaml'),
    (['{tiny}', 'nope'], 'nope'),
    (['{tiny}', 'bend', '--push', '1:300,0:0.2'], "push '1:300,0:0.2' is not AT_S:FX,FY,FZ"),
    (['{tiny}', 'bend', '--gains', 'no_gains.yaml'], 'gains file no_gains.yaml does not exist'),
    (['{tiny}', 'bend', '--latency-ms', '20:5'], "latency '20:5' is not LO:HI whole milliseconds"),
    (['{tiny}', 'bend', '--scheduler', 'tcp://127.0.0.1:9'],
     'cannot reach the Dask scheduler at tcp://127.0.0.1:9'),
])
def test_bad_input_one_line_exit_1_nothing_written(tmp_path: Path, tiny_file: Path,
                                                    args: list[str], message: str,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """The missing file through the script (its wrapper's exit status), the rest through
    main in this process."""
    args = [arg.replace('{tiny}', str(tiny_file)) for arg in args]
    sweep = _sweep if args[0] == 'missing.yaml' else partial(_sweep_here, capsys)
    result = sweep(*args, '--out', str(tmp_path / 'table'), '--no-progress')
    assert result.returncode == 1
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    assert lines[0].startswith('sweep.py: error: ') and message in lines[0]
    assert list(tmp_path.iterdir()) == []
