"""course_sweep.py: the course walked over its variants x seeds (one short run here: the
rearranged rubble's world from the mud start, to gate_1, about a metre ahead), its table
printed and written with every run's row, as the README's table is made. About 20 s of CPU
(the course's physics). The table's arithmetic: test/unit/search/test_course_sweep_table.py;
the script's start and its refusals: test_cli_convention.py."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from tutorial_atlas_control.cli import course_sweep

pytestmark = pytest.mark.offline


def test_one_run_gives_its_row_and_its_variant_s_line(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / 'sweep'
    status = course_sweep.main(['--variants', 'finals_rubble', '--seeds', 'none',
                                '--world', 'vrc_task_2_mud_start', '--to', 'gate_1',
                                '--workers', '1', '--no-progress', '--out', str(out)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    (run,) = json.loads((tmp_path / 'sweep.json').read_text())
    assert run['variant'] == 'finals_rubble' and run['seed'] is None
    assert run['through'] is True and run['fell_at_s'] is None, run
    assert run['completion'] == 0  # gate_1 before gate_0 is no gate (DRCSim's order)
    assert run['pelvis_y_m'] > -22.0  # past gate_1's line
    assert 0.75 < run['lowest_pelvis_m'] < 0.95 and run['lowest_leg'] == 'gate_1'
    table = (tmp_path / 'sweep.md').read_text()
    assert table.splitlines()[2].startswith('| finals_rubble | 1 of 1 | 0 | 0 | 0 | ')
    assert table in captured.out
    assert f'table: {tmp_path / "sweep.md"}' in captured.out
    assert len((tmp_path / 'sweep.csv').read_text().splitlines()) == 2
