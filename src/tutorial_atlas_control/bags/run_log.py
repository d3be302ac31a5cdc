"""What a bag's /rosout says about the run: the trajectory a player logged at its start.

traj_yaml.py and run_offline.py both log one machine-readable line before their first
command (schedule.trajectory_log_line); the recorder keeps /rosout, so a bag names the
trajectory it played without any file beside it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from tutorial_atlas_control.trajectories import (
    TRAJECTORY_LOG_PREFIX,
    parse_trajectory_log_line,
)

__all__ = ['PlayedTrajectory', 'trajectory_lines']

LOG_TYPE = 'rosgraph_msgs/msg/Log'


@dataclass(frozen=True)
class PlayedTrajectory:
    """A trajectory a player logged: file, name, the logging node and bag time (ns)."""

    file: str
    name: str
    node: str
    time_ns: int

    def describe(self) -> str:
        return f"'{self.name}' of {self.file} (played by {self.node})"


def trajectory_lines(times: Sequence[Any], times_ns: Sequence[int], raws: Sequence[bytes],
                     typestore: Any) -> list[tuple[Any, PlayedTrajectory]]:
    """(time, trajectory) of the player lines among /rosout messages `raws`.

    `times` are passed through (reader.py's run times); `times_ns` are the bag times.
    """
    marker = TRAJECTORY_LOG_PREFIX.encode()
    found = []
    for time, time_ns, raw in zip(times, times_ns, raws):
        if marker not in raw:  # most lines are not ours: skip deserializing them
            continue
        message = typestore.deserialize_ros1(raw, LOG_TYPE)
        fields = parse_trajectory_log_line(message.msg)
        if fields is not None:
            found.append((time, PlayedTrajectory(fields['file'], fields['name'], message.name,
                                                 int(time_ns))))
    return found

