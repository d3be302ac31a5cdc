"""Where the stepping loop's output goes: the outbox of serialized messages, the log, and
the node's few other publications. The node gives rospy's; tests give fakes."""

from __future__ import annotations

from collections.abc import Callable, Hashable, Mapping
from dataclasses import dataclass
from typing import Protocol

from tutorial_atlas_control import topics
from tutorial_atlas_control.course import ScoreRow

__all__ = ['LoopLog', 'LoopOutputs', 'Outbox']


class Outbox(Protocol):
    """Where serialized messages go, by outlet (the node: its publishers, in a WireBatch)."""

    def wanted(self, outlet: Hashable) -> bool:
        """Anyone listening? The loop serializes nothing for an outlet without listeners."""

    def add(self, outlet: Hashable, data: bytes | bytearray) -> None:
        """Queue a copy of `data` (TCPROS-framed messages) after what is queued."""

    def replace(self, outlet: Hashable, data: bytes | bytearray) -> None:
        """Queue `data` instead of anything still queued for `outlet`."""

    def flush(self) -> None:
        """Send everything queued."""


class LoopLog(Protocol):
    """The loop's log lines (the node: rospy's log, which throttles refused commands)."""

    def info(self, text: str) -> None: ...

    def refused_command(self, text: str, topic: str = topics.JOINT_COMMANDS) -> None:
        """Throttled per topic: a command message was refused."""

    def kept_fields(self, text: str, topic: str) -> None:
        """Throttled per topic: an AtlasCommand/Test array of the wrong length was left out."""

    def warn(self, text: str) -> None: ...

    def error(self, text: str) -> None: ...

    def fatal(self, text: str) -> None: ...


@dataclass(frozen=True)
class LoopOutputs:
    """Everything the loop writes to.

    Attributes:
        outbox: where each step's messages go.
        outlets: topic -> outlet (key in the outbox) of each topic the loop publishes;
            without topics.TF, no /tf; a topics.INTERFACE on-demand topic without an
            outlet is not sent.
        log: where log lines go.
        publish_config: sends /atlas/sim_config's JSON (latched: not through the outbox).
        publish_input: sends /atlas/sim_inputs' JSON of each applied cheat (None: nowhere).
        latch_synchronization: keeps the latest /atlas/synchronization_statistics
            (serialized, without its length prefix) for later subscribers (None: not kept).
        publish_score: sends a row of the course's scoring on the latched /vrc_score (None:
            score.log only).
    """

    outbox: Outbox
    outlets: Mapping[str, Hashable]
    log: LoopLog
    publish_config: Callable[[str], None]
    publish_input: Callable[[str], None] | None = None
    latch_synchronization: Callable[[bytes], None] | None = None
    publish_score: Callable[[ScoreRow], None] | None = None
