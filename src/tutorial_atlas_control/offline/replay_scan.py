"""A recorded laser scan stream cast again on the replayed steps and compared bit for bit.

A scan is a function of the state at its stamp (the head's pose, which replay reproduces
bit for bit), the spindle's angle and the noise of (the run's sensor_seed, the stamp): cast
again on the replayed state it is the recorded one, range for range, as float32 bytes. The
spindle is simulated from the replay's start at rest, as a run starts it, each recorded
set_spindle_speed taken in the step it first acted in: not recorded as such (the command's
record time is the recorder's receipt), but found from the recorded /tf's spindle angles
(bags/laser_scans.spindle_command_steps). A run whose commands cannot be placed so (no
/tf, or a reset before the replayed try) is not compared, and the report says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from tutorial_atlas_control import topics
from tutorial_atlas_control.bags import LaserScans, spindle_command_steps
from tutorial_atlas_control.sensors import HeadSensors
from tutorial_atlas_control.sim import AtlasSimulator
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['ScanComparison', 'ScanReplay']


@dataclass(frozen=True)
class ScanComparison:
    """How many recorded scans were cast again, how many differ, the first that does."""

    compared: int
    differing: int
    first_difference_s: float | None

    @property
    def same(self) -> bool:
        return self.differing == 0

    def line(self) -> str:
        if self.same:
            return f'  {"laser scans":<20} {self.compared} scans the same, bit for bit'
        return (f'  {"laser scans":<20} {self.differing} of {self.compared} scans DIFFER, the '
                f'first at {self.first_difference_s:.3f} s')

    def to_dict(self) -> dict[str, Any]:
        return {'compared': self.compared, 'differing': self.differing,
                'first_difference': self.first_difference_s}


class ScanReplay:
    """Called after each replayed step: the spindle's step, then the recorded scan of the
    step's start, if any, cast again and compared."""

    def __init__(self, sim: AtlasSimulator, scans: LaserScans, seed: int) -> None:
        self.sim = sim
        self.head = HeadSensors(sim.model, sim.data, sim.dt_s, seed)
        self.recorded = scans.ranges
        self.commands = (spindle_command_steps(scans) or []) if scans.spindle_commands else []
        self.row_at = {stamp: row for row, stamp in enumerate(scans.stamp_ns.tolist())}
        self.compared = 0
        self.differing = 0
        self.first_difference_ns: int | None = None

    @classmethod
    def of(cls, sim: AtlasSimulator, scans: LaserScans | None, seed: int) -> ScanReplay | None:
        """A replay of `scans` (None without any)."""
        return None if scans is None else cls(sim, scans, seed)

    @staticmethod
    def comparable(scans: LaserScans | None, warnings: list[str]) -> bool:
        """Whether a recording's scans can be compared (else a warning says why not)."""
        if scans is None:
            return False
        if scans.spindle_commands and spindle_command_steps(scans) is None:
            warnings.append(f'{topics.LASER_SCAN} is not compared: the spindle was commanded '
                            f'({topics.SET_SPINDLE_SPEED}), and the recorded /tf does not '
                            'say the step each command first acted in.')
            return False
        return True

    def __call__(self) -> None:
        head, stamp_ns = self.head, self.sim.state_time_ns
        while self.commands and self.commands[0][0] <= self.sim.sim_time_ns:
            head.spindle.command(self.commands.pop(0)[1])  # before the step it acted in
        head.step()
        row = self.row_at.get(stamp_ns)
        if row is None:
            return
        head.scan(stamp_ns)
        self.compared += 1
        if head.scan_wire.ranges.tobytes() != self.recorded[row].tobytes():
            self.differing += 1
            if self.first_difference_ns is None:
                self.first_difference_ns = stamp_ns

    def compare(self) -> ScanComparison:
        first = self.first_difference_ns
        return ScanComparison(self.compared, self.differing,
                              None if first is None else first / NS_PER_S)
