"""What a bag's /rosout says about the run: the trajectory a player logged at its start.

traj_yaml.py and run_offline.py both log one machine-readable line before their first
command (schedule.trajectory_log_line); the recorder keeps /rosout, so a bag names the
trajectory it played without any file beside it.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from rosbags.rosbag1 import Reader, ReaderError

from tutorial_atlas_control.bags.typestore import load_typestore
from tutorial_atlas_control.topics import ROSOUT
from tutorial_atlas_control.trajectories.schedule import (
    TRAJECTORY_LOG_PREFIX,
    parse_trajectory_log_line,
)

__all__ = ['PlayedTrajectory', 'played_trajectories', 'trajectory_lines']

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

    `times` are passed through (bag_reader's run times); `times_ns` are the bag times.
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


def played_trajectories(path: Path | str) -> list[PlayedTrajectory]:
    """Every trajectory line on /rosout in the bag at `path`, in time order (none: empty).

    An unreadable bag gives an empty list: the caller reports the bag's problem itself.
    """
    typestore = load_typestore()
    found = []
    marker = TRAJECTORY_LOG_PREFIX.encode()
    try:
        with Reader(Path(path)) as reader:
            connections = [c for c in reader.connections
                           if c.topic == ROSOUT and c.msgtype == LOG_TYPE]
            for _, time_ns, raw in reader.messages(connections=connections):
                if marker not in raw:  # most lines are not ours: skip deserializing them
                    continue
                message = typestore.deserialize_ros1(raw, LOG_TYPE)
                fields = parse_trajectory_log_line(message.msg)
                if fields is not None:
                    found.append(PlayedTrajectory(fields['file'], fields['name'], message.name,
                                                  int(time_ns)))
    except (ReaderError, OSError, ValueError, KeyError, IndexError):
        return []
    return found
