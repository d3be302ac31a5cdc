"""A replay's VRC score: the course's scoring run again on the replayed steps and compared
with the bag's /vrc_score, row for row (sim time, completion, falls, message; the wall-time
columns are the run's own and are not compared).

The scorer keeps its state over a whole run and does not restart on a reset, as DRCSim's
plugin did not: only a replay from the run's start (one try, the reset at 0) can be scored
again; another is not compared.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from tutorial_atlas_control.bags import ScoreEntry
from tutorial_atlas_control.course import ScoreRow
from tutorial_atlas_control.sim import AtlasSimulator
from tutorial_atlas_control.stepping import CourseScoring
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['ScoreComparison', 'ScoreReplay']

#: (sim time ns, completion, falls, message): what a row says, without its wall times.
RowKey = tuple[int, int, int, str]


@dataclass(frozen=True)
class ScoreComparison:
    """The replayed score against the recorded one, over the recorded rows' span."""

    recorded_rows: int
    replayed_rows: int
    completion: int
    falls: int
    first_difference: str | None  # None: the same rows

    @property
    def same(self) -> bool:
        return self.first_difference is None

    def line(self) -> str:
        head = (f'  {"VRC score":<20} {self.recorded_rows} rows recorded, '
                f'{self.replayed_rows} replayed (completion {self.completion}, '
                f'falls {self.falls})')
        return head + (': the same' if self.same else f': DIFFERS, {self.first_difference}')

    def to_dict(self) -> dict[str, Any]:
        return {'recorded_rows': self.recorded_rows, 'replayed_rows': self.replayed_rows,
                'completion': self.completion, 'falls': self.falls,
                'first_difference': self.first_difference}


class ScoreReplay:
    """The replay's scorer: call it after every replayed step, from the run's start."""

    def __init__(self, sim: AtlasSimulator, recorded: list[ScoreEntry]) -> None:
        self.recorded = [(round(entry.sim_time_s * NS_PER_S), entry.completion, entry.falls,
                          entry.message) for entry in recorded]
        self.rows: list[ScoreRow] = []
        self.scoring = CourseScoring(sim, None, self.rows.append,
                                     wall_clock=lambda: sim.sim_time_ns)

    def __call__(self) -> None:
        self.scoring()

    def compare(self, end_ns: int) -> ScoreComparison:
        """The replayed rows up to `end_ns` (the replay's end) against the recorded ones."""
        recorded = [row for row in self.recorded if row[0] <= end_ns]
        # The recorder may have subscribed after the first rows (it then got the latest,
        # latched): the rows compared begin with the first recorded one.
        start_ns = recorded[0][0] if recorded else end_ns + 1
        replayed: list[RowKey] = [(row.sim_time_ns, row.completion, row.falls, row.message)
                                  for row in self.rows if row.sim_time_ns >= start_ns]
        difference = None
        for index, (was, now) in enumerate(zip(recorded, replayed)):
            if was != now:
                difference = f'row {index + 1}: recorded {_text(was)}, replayed {_text(now)}'
                break
        else:
            if len(recorded) != len(replayed):
                longer = recorded if len(recorded) > len(replayed) else replayed
                which = 'recorded' if longer is recorded else 'replayed'
                extra = longer[min(len(recorded), len(replayed))]
                difference = f'a row only {which}: {_text(extra)}'
        last = self.rows[-1] if self.rows else None
        return ScoreComparison(len(recorded), len(replayed), last.completion if last else 0,
                               last.falls if last else 0, difference)


def _text(row: RowKey) -> str:
    t_ns, completion, falls, message = row
    return f'{t_ns / NS_PER_S:.3f} s completion {completion} falls {falls} {message!r}'
