"""The VRC course's score over a recorded run: the bag's /vrc_score (atlas_msgs/VRCScore, a
row every 1 s of sim time and at each gate or fall) as a timeline of its events and the
final score."""

from __future__ import annotations

from dataclasses import dataclass

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags.reader import BagData
from tutorial_atlas_control.bags.records import open_bag
from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.errors import BagAnalysisError

__all__ = ['ScoreEntry', 'read_scores', 'score_lines']

_SCORE_TYPE = 'atlas_msgs/msg/VRCScore'


def _seconds(stamp: object) -> float:
    return int(stamp.sec) + int(stamp.nanosec) * 1e-9  # type: ignore[attr-defined]


@dataclass(frozen=True)
class ScoreEntry:
    """One /vrc_score message: its sim time (s), the score, the falls, the sim and wall
    time since gate_0 (s) and the events it reports ('' for a periodic one)."""

    sim_time_s: float
    completion: int
    falls: int
    sim_elapsed_s: float
    wall_elapsed_s: float
    message: str

    def line(self) -> str:
        return (f'  {self.sim_time_s:9.3f} s  score {self.completion}  falls {self.falls}  '
                f'{self.sim_elapsed_s:8.3f} s since gate 1 (wall {self.wall_elapsed_s:.3f})'
                + (f'  {self.message.strip()}' if self.message else ''))


def read_scores(data: BagData) -> list[ScoreEntry] | None:
    """Every /vrc_score message in `data`'s bag, in order; None when the bag has none
    (an unscored run: then the bag is not opened again)."""
    if not getattr(data.topics.get(topics.VRC_SCORE), 'count', 0):
        return None
    records = open_bag(data.path)
    try:
        connections = [c for c in records.connections if c.topic == topics.VRC_SCORE]
        if not connections:
            return None
        typestore = load_typestore(records.connections)
        _bag_ns, raws = records.raw_messages(connections)
        entries = []
        for raw in raws:
            score = typestore.deserialize_ros1(raw, _SCORE_TYPE)
            entries.append(ScoreEntry(
                _seconds(score.sim_time), int(score.completion_score), int(score.falls),
                _seconds(score.sim_time_elapsed), _seconds(score.wall_time_elapsed),
                str(score.message)))
    except (KeyError, ValueError, AttributeError) as err:
        raise BagAnalysisError(f'Could not read {topics.VRC_SCORE} of {data.path}: '
                               f'{err}') from err
    finally:
        records.close()
    return entries or None


def score_lines(entries: list[ScoreEntry]) -> list[str]:
    """The report's section: each event (a gate, a fall) and the last score, by sim time."""
    events = [entry for entry in entries if entry.message]
    if entries[-1] not in events:
        events.append(entries[-1])
    last = entries[-1]
    return ([f'VRC score ({topics.VRC_SCORE}; sim time): completion {last.completion}, '
             f'falls {last.falls}, {last.sim_elapsed_s:.3f} s since gate 1']
            + [entry.line() for entry in events])
