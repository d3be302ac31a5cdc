"""DRCSim's score.log: VRCScoringPlugin's header and rows, written as the plugin wrote them.

The file is truncated at the start of a run, as the plugin's was. Each row goes to the file
in one write of the whole line, so that a reader (or a run killed mid-way) never sees half
a row.
"""

from __future__ import annotations

import os
import time
from pathlib import Path

from tutorial_atlas_control.course.errors import CourseError
from tutorial_atlas_control.course.scoring import ScoreRow, seconds
from tutorial_atlas_control.course.vrc_task_2 import WORLD_NAME

__all__ = ['DEFAULT_SCORE_DIR', 'SCORE_FILE_NAME', 'ScoreLog', 'header']

#: The VRC worlds' <score_file>: /tmp/vrc_task_2/score.log.
DEFAULT_SCORE_DIR = Path('/tmp/vrc_task_2')
SCORE_FILE_NAME = 'score.log'


def header(world_name: str, wall_start_ns: int) -> str:
    """The plugin's header: the world, the start (wall seconds and ctime's local date, whose
    newline ends the line), and the format lines (the first with its trailing space)."""
    return (f'# Score data for world {world_name}\n'
            f'# Started at: {seconds(wall_start_ns):.3f}; '
            f'{time.ctime(wall_start_ns // 1_000_000_000)}\n'
            '# Format: \n'
            '# wallTime(sec),simTime(sec),wallTimeElapsed(sec),simTimeElapsed(sec),'
            'completionScore(count),falls(count)\n')


class ScoreLog:
    """score.log in `directory` (created if missing), its header written at once.

    Raises:
        CourseError: the directory or the file cannot be made (one line naming it).
    """

    def __init__(self, directory: Path, wall_start_ns: int, world_name: str = WORLD_NAME
                 ) -> None:
        self.path = Path(directory) / SCORE_FILE_NAME
        try:
            self.path.parent.mkdir(parents=True, exist_ok=True)
            self._fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_TRUNC | os.O_APPEND,
                               0o644)
        except FileExistsError:
            raise CourseError(f'score log {self.path} cannot be written: {self.path.parent} '
                              'is not a directory') from None
        except OSError as err:
            raise CourseError(f'score log {self.path} cannot be written: '
                              f'{err.strerror or err}') from None
        self._write(header(world_name, wall_start_ns))

    def write(self, row: ScoreRow) -> None:
        """One row, whole."""
        self._write(row.log_line())

    def _write(self, text: str) -> None:
        data = text.encode()
        while data:  # a regular file takes it in one write; a short write is finished
            data = data[os.write(self._fd, data):]

    def close(self) -> None:
        if self._fd >= 0:
            os.close(self._fd)
            self._fd = -1

    def __enter__(self) -> ScoreLog:
        return self

    def __exit__(self, *_exc: object) -> None:
        self.close()
