"""search.py: CMA-ES over offline runs; improves a toy objective, deterministically, resumes
exactly, writes files the tutorial's loaders read, refuses bad input in one line."""

from __future__ import annotations

import dataclasses
import json
from dataclasses import dataclass
from functools import partial
from pathlib import Path

import numpy as np
import pytest

from support.scripts import interrupt_script, run_script
from tutorial_atlas_control.cli import search as search_cli
from tutorial_atlas_control.search.cmaes import LATENCY_SEED, runs_per_candidate
from tutorial_atlas_control.search.sweep import SweepInputs, build_specs, run_sweep
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.trajectories.trajectory import load_trajectory

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

REPO = Path(__file__).resolve().parents[2]
_search = partial(run_script, 'search.py')
#: A squat held briefly: the toy problem is to end with the pelvis 0.80 m high (it starts
#: about 0.90 m), by bending knees twice as much as hips and ankles.
TINY = """\
bend:
  - [0.2, "0 0 0 0  0 0 -0.3 0.6 -0.3 0  0 0 -0.3 0.6 -0.3 0  0 0 0 0 0 0  0 0 0 0 0 0"]
"""
SQUAT = '0:2*l_leg_kny+2*r_leg_kny-l_leg_lhy-r_leg_lhy-l_leg_uay-r_leg_uay'
TOY = ['bend', '--objective', 'pelvis_height:z=0.8,settle=0.3', '--vary', SQUAT,
       '--popsize', '4', '--workers', '2', '--seed', '0']


@pytest.fixture(scope='module')
def tiny(tmp_path_factory: pytest.TempPathFactory) -> Path:
    path = tmp_path_factory.mktemp('tiny') / 'tiny.yaml'
    path.write_text(TINY)
    return path


def _records(log: Path) -> list[dict]:
    return [json.loads(line) for line in log.read_text().splitlines()]


@dataclass(frozen=True)
class Ran:
    """A search's outcome, as subprocess.CompletedProcess gives the script's."""

    returncode: int
    stdout: str
    stderr: str


def _search_here(capsys: pytest.CaptureFixture[str], *args: str) -> Ran:
    """search.py's main in this process, its output captured: each search without a new
    interpreter's imports (cma, scipy, dask: about 4 CPU s a start). The script itself, its
    start-up, exit status and one-line errors, is test_ctrl_c_keeps_the_finished_generations'
    and test_missing_file_and_unknown_name's."""
    capsys.readouterr()
    status = search_cli.main(list(args))
    captured = capsys.readouterr()
    return Ran(status, captured.out, captured.err)


def test_toy_search_improves_deterministically_and_resumes(
        tmp_path: Path, tiny: Path, capsys: pytest.CaptureFixture[str]) -> None:
    whole = tmp_path / 'whole'
    whole.mkdir()
    result = _search_here(capsys, str(tiny), *TOY, '--generations', '3',
                          '--log', str(whole / 'log.jsonl'), '--yaml', str(whole / 'found.yaml'))
    assert result.returncode == 0, result.stderr
    log = _records(whole / 'log.jsonl')
    start = log[1]['cost']
    best = min(min(r['cost']) for r in log if r['kind'] == 'generation')
    assert start > 0.05  # the squat starts ~0.1 m too high
    assert best < start / 2
    # Two generations in another search, then resumed to three: the same candidates, costs
    # and file as three in one go (same seed, same inputs: deterministic, and resumed exactly).
    # These two on one worker, in this process, against the whole run's Dask cluster of two:
    # the search does not depend on its workers either (and no cluster starts twice more).
    out = tmp_path / 'resumed'
    out.mkdir()
    first = _search_here(capsys, str(tiny), *TOY, '--generations', '2', '--workers', '1',
                         '--log', str(out / 'log.jsonl'), '--yaml', str(out / 'found.yaml'))
    assert first.returncode == 0, first.stderr
    resumed = _search_here(capsys, str(tiny), *TOY, '--generations', '3', '--resume',
                           '--workers', '1', '--log', str(out / 'log.jsonl'),
                           '--yaml', str(out / 'found.yaml'))
    assert resumed.returncode == 0, resumed.stderr
    assert 'resumed after generation 2' in resumed.stdout
    assert (out / 'log.jsonl').read_text() == (whole / 'log.jsonl').read_text()
    assert (out / 'found.yaml').read_text() == (whole / 'found.yaml').read_text()
    # The tutorial's loader reads the result, and playing it again gives the logged figures.
    found = whole / 'found.yaml'
    waypoints = load_trajectory(found, 'bend_found')
    assert len(waypoints) == 1 and waypoints[0].duration_s == 0.2
    knee = waypoints[0].positions[7]
    assert knee > 0.6  # a deeper squat than the start's
    rows = run_sweep(build_specs(SweepInputs([(str(found), 'bend_found')],
                                             [str(REPO / 'config' / 'atlas_controller.yaml')],
                                             settle_s=0.3)), workers=1, progress=False).rows
    assert abs(rows[0]['pelvis_z_end_m'] - 0.8) == pytest.approx(best, abs=1e-12)


def test_gain_search_writes_a_gains_file(tmp_path: Path, tiny: Path,
                                        capsys: pytest.CaptureFixture[str]) -> None:
    result = _search_here(capsys, str(tiny), 'bend', '--objective',
                          'pelvis_height:z=0.8,settle=0.3', '--vary-gain', 'l_leg_kny+r_leg_kny',
                          '--popsize', '3', '--generations', '1', '--workers', '1',
                          '--log', str(tmp_path / 'log.jsonl'),
                          '--yaml', str(tmp_path / 'found.yaml'))
    assert result.returncode == 0, result.stderr
    gains = load_gains_yaml(tmp_path / 'found_gains.yaml')
    base = load_gains_yaml(REPO / 'config' / 'atlas_controller.yaml')
    changed = np.flatnonzero(gains.p != base.p)
    assert set(changed) <= {7, 13}  # l_leg_kny, r_leg_kny only
    assert 'gains_file:=' in (tmp_path / 'found.yaml').read_text()


def _generations_logged(log: Path) -> int:
    try:
        text = log.read_text()
    except FileNotFoundError:
        return 0
    return text.count('"kind": "generation"')


def test_ctrl_c_keeps_the_finished_generations(tmp_path: Path, tiny: Path) -> None:
    """Ctrl-C after two generations of a search that would run 1000: exit 130, one line, the
    log whole (every line JSON) and resumable, the best so far written."""
    log, found = tmp_path / 'log.jsonl', tmp_path / 'found.yaml'
    args = [str(tiny), *TOY, '--log', str(log), '--yaml', str(found)]
    result = interrupt_script('search.py', *args, '--generations', '1000',
                              ready=lambda _err: _generations_logged(log) >= 2, cwd=tmp_path)
    assert result.returncode == 130, result
    generations = [r for r in _records(log) if r['kind'] == 'generation']
    assert [r['gen'] for r in generations] == list(range(1, len(generations) + 1))
    lines = result.stderr.splitlines()
    assert len(lines) == 1, result.stderr
    # The signal lands while a generation runs (then its number is said), or, rarely, in the
    # moment between two, which the log alone then tells.
    assert lines[0] in (
        f'search.py: interrupted after generation {len(generations)}; --resume continues it; '
        f'best so far in {found}',
        f'search.py: interrupted; the log {log} keeps the finished generations'), lines
    assert load_trajectory(found, 'bend_found')
    # Resumed on one worker: the Ctrl-C above is the cluster's test.
    resumed = _search(*args, '--generations', str(len(generations) + 1), '--resume',
                      '--workers', '1')
    assert resumed.returncode == 0, resumed.stderr
    assert f'resumed after generation {len(generations)}' in resumed.stdout


@pytest.mark.parametrize('args, message', [
    (['--objective', 'fly'], "unknown objective 'fly'; known: pelvis_height, stay_up"),
    (['--objective', 'step_forward:dx=far'], "objective 'step_forward:dx=far': dx='far' is not"),
    (['--objective', 'step_forward:height=1'], "'height=1' is not KEY=VALUE"),
    (['--objective', 'stay_up', '--vary', '0:l_leg_knee'], "unknown joint 'l_leg_knee'"),
    (['--objective', 'stay_up', '--vary', '4:l_leg_kny'], 'waypoint 4 does not exist'),
    (['--objective', 'stay_up', '--vary', '0:l_leg_kny', '--resume'], 'cannot resume from'),
    (['--objective', 'stay_up'], 'nothing to search'),
    (['--objective', 'stay_up', '--vary', '0:l_leg_kny', '--latency-ms', '0:20'],
     'give --latency-ms LO:HI and --latency-draws N (N >= 1) together'),
    (['--objective', 'stay_up', '--vary', '0:l_leg_kny', '--latency-ms', 'x',
      '--latency-draws', '2'], "latency 'x' is not LO:HI"),
])
def test_bad_input_one_line_exit_1_nothing_written(tmp_path: Path, tiny: Path,
                                                    args: list[str], message: str,
                                                    capsys: pytest.CaptureFixture[str]) -> None:
    """The command line's main in this process (each refusal comes before any run; the
    script's wrapper and exit status are test_missing_file_and_unknown_name's)."""
    out = tmp_path / 'out'
    out.mkdir()
    status = search_cli.main([str(tiny), 'bend', *args, '--log', str(out / 'log.jsonl'),
                              '--yaml', str(out / 'found.yaml'), '--workers', '1'])
    captured = capsys.readouterr()
    assert (status, captured.out) == (1, '')
    lines = captured.err.splitlines()
    assert len(lines) == 1, captured.err
    assert lines[0].startswith('search.py: error: ') and message in lines[0]
    assert list(out.iterdir()) == []


def test_missing_file_and_unknown_name(tmp_path: Path, tiny: Path,
                                      capsys: pytest.CaptureFixture[str]) -> None:
    """The script (its wrapper's exit status) for the missing file, main in this process for
    the unknown name."""
    for search, trajectory, name, message in (
            (_search, tmp_path / 'none.yaml', 'bend', 'none.yaml'),
            (partial(_search_here, capsys), tiny, 'walk', 'walk')):
        result = search(str(trajectory), name, '--objective', 'stay_up', '--vary',
                        '0:l_leg_kny', '--log', str(tmp_path / 'log.jsonl'),
                        '--yaml', str(tmp_path / 'found.yaml'))
        assert result.returncode == 1 and len(result.stderr.splitlines()) == 1
        assert message in result.stderr
        assert not (tmp_path / 'log.jsonl').exists() and not (tmp_path / 'found.yaml').exists()


def test_robust_cost_is_the_mean_over_variants(tmp_path: Path, tiny: Path,
                                               capsys: pytest.CaptureFixture[str]) -> None:
    """--robust GAIN:TIME plays each candidate again with those scales; its cost is the mean."""
    result = _search_here(capsys, str(tiny), 'bend', '--objective',
                          'pelvis_height:z=0.8,settle=0.3', '--vary', SQUAT,
                          '--robust', '0.5:1.5', '--popsize', '2', '--generations', '1',
                          '--workers', '1', '--log', str(tmp_path / 'log.jsonl'),
                          '--yaml', str(tmp_path / 'found.yaml'))
    assert result.returncode == 0, result.stderr
    header, start, generation = _records(tmp_path / 'log.jsonl')
    assert header['config']['variants'] == [[0.5, 1.5]]
    assert runs_per_candidate(header['config']) == 2  # what bench/search_time counts
    assert len(generation['rows']) == 2  # the nominal rows only, one per candidate
    inputs = SweepInputs([(str(tiny), 'bend')], [str(REPO / 'config' / 'atlas_controller.yaml')],
                         gain_scales=(1.0, 0.5), time_scales=(1.0, 1.5), settle_s=0.3)
    rows = run_sweep(build_specs(inputs), workers=1, progress=False).rows
    by_scale = {(row['gain_scale'], row['time_scale']): row for row in rows}
    costs = [abs(by_scale[key]['pelvis_z_end_m'] - 0.8) + float(by_scale[key]['fell'])
             for key in ((1.0, 1.0), (0.5, 1.5))]
    assert costs[0] != costs[1]
    assert start['cost'] == pytest.approx(sum(costs) / 2, abs=1e-12)


def test_latency_draws_are_the_same_for_every_candidate(
        tmp_path: Path, tiny: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """--latency-ms/--latency-draws: each candidate is played again N times with its commands
    delayed, the same N draws for all (seeds fixed), and its cost is the mean."""
    result = _search_here(capsys, str(tiny), 'bend', '--objective',
                          'pelvis_height:z=0.8,settle=0.3', '--vary', SQUAT,
                          '--latency-ms', '0:20', '--latency-draws', '2', '--popsize', '2',
                          '--generations', '1', '--workers', '1',
                          '--log', str(tmp_path / 'log.jsonl'),
                          '--yaml', str(tmp_path / 'found.yaml'))
    assert result.returncode == 0, result.stderr
    header, start, generation = _records(tmp_path / 'log.jsonl')
    assert header['config']['latency'] == [0, 20, 2]
    assert runs_per_candidate(header['config']) == 3
    assert len(generation['rows']) == 2
    base = build_specs(SweepInputs([(str(tiny), 'bend')],
                                   [str(REPO / 'config' / 'atlas_controller.yaml')],
                                   settle_s=0.3))[0]
    specs = [base] + [dataclasses.replace(base, index=j, latency_steps=(0, 20),
                                          seed=LATENCY_SEED + j - 1) for j in (1, 2)]
    rows = run_sweep(specs, workers=1, progress=False).rows
    costs = [abs(row['pelvis_z_end_m'] - 0.8) + float(row['fell']) for row in rows]
    assert len(set(costs)) > 1  # the delays change the run
    assert start['cost'] == pytest.approx(sum(costs) / 3, abs=1e-12)
