"""DRCSim's score.log: the plugin's header and rows, its directory made, whole rows only."""

from __future__ import annotations

import time
from pathlib import Path

import pytest

from tutorial_atlas_control.course import CourseError, ScoreLog, ScoreRow

S = 1_000_000_000


def test_header_and_rows_as_the_plugin_wrote_them(tmp_path: Path) -> None:
    start_ns = 1_700_000_000_123_456_789
    directory = tmp_path / 'made' / 'vrc_task_2'
    with ScoreLog(directory, start_ns) as log:
        log.write(ScoreRow(1_500_000_000, 1 * S, 0, 0, 0, 0, ''))
        text = (directory / 'score.log').read_text()
        assert text.endswith('"\n')  # each row on disk whole, before the log is closed
        log.write(ScoreRow(41 * S, 20_001_000_000, 0, 0, 0, 0,
                           'Successfully passed through gate 1. Starting clock. '))
    lines = (directory / 'score.log').read_text().split('\n')
    assert lines[0] == '# Score data for world vrc_task_2'
    assert lines[1] == f'# Started at: 1700000000.123; {time.ctime(1_700_000_000)}'
    assert lines[2:4] == ['# Format: ', '# wallTime(sec),simTime(sec),wallTimeElapsed(sec),'
                          'simTimeElapsed(sec),completionScore(count),falls(count)']
    assert lines[4:] == ['1.500,1.000,0.000,0.000,0,0,""',
                         '41.000,20.001,0.000,0.000,0,0,'
                         '"Successfully passed through gate 1. Starting clock. "', '']


def test_a_new_run_starts_the_file_again(tmp_path: Path) -> None:
    with ScoreLog(tmp_path, 0) as log:
        log.write(ScoreRow(0, S, 0, 0, 3, 1, ''))
    with ScoreLog(tmp_path, 0):
        pass
    assert len((tmp_path / 'score.log').read_text().splitlines()) == 4


def test_an_unwritable_directory_is_one_line(tmp_path: Path) -> None:
    blocker = tmp_path / 'file'
    blocker.write_text('')
    with pytest.raises(CourseError, match=r'score log .*file/score.log cannot be written'):
        ScoreLog(blocker, 0)
