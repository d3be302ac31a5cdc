"""A spun spindle's scans replay bit for bit: set_spindle_speed's record time is the
recorder's receipt, not the step the simulator first took it in, so that step is found from
the recorded /tf's spindle angles (bags/laser_scans.spindle_command_steps) and the replay
takes each command there."""

from __future__ import annotations

import math

import numpy as np
import pytest

from tutorial_atlas_control.bags import LaserScans, spindle_command_steps
from tutorial_atlas_control.offline.replay_scan import ScanReplay
from tutorial_atlas_control.sensors import HeadSensors, Spindle
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasSimulator,
    load_gains_yaml,
    load_model,
)
from tutorial_atlas_control.topics import LASER_SCAN, SET_SPINDLE_SPEED

MS = 1_000_000
#: (the end (ns) of the first spindle step with the speed, the speed, its record time (ns)):
#: recorded late and early, a NaN (ignored), a stop.
COMMANDS = ((207 * MS, 1.0, 301 * MS), (601 * MS, 5.0, 561 * MS), (700 * MS, math.nan, 702 * MS),
            (811 * MS, 0.0, 900 * MS))
RUN_NS = 1_000 * MS
SCAN_EVERY_NS, TF_EVERY_NS = 25 * MS, 20 * MS


def _samples(commands: tuple[tuple[int, float, int], ...]) -> tuple[np.ndarray, np.ndarray]:
    """/tf's spindle angles every 20 ms of a spindle commanded as `commands` say."""
    spindle, stamps, angles = Spindle(0.001), [], []
    for end_ns in range(MS, RUN_NS + 1, MS):
        for acted_ns, speed, _ in commands:
            if acted_ns == end_ns and not math.isnan(speed):
                spindle.command(speed)
        spindle.step()
        if end_ns % TF_EVERY_NS == 0:
            stamps.append(end_ns)
            angles.append(spindle.angle)
    return np.array(stamps, dtype=np.int64), np.array(angles)


def _scans(stamp_ns: np.ndarray, ranges: np.ndarray,
           samples: tuple[np.ndarray, np.ndarray] | None) -> LaserScans:
    return LaserScans(stamp_ns, ranges, 'head_hokuyo_frame', -1.5708, 0.0043633,
                      [(record, speed) for _, speed, record in COMMANDS], samples)


def test_each_command_is_placed_at_the_step_it_first_acted_in() -> None:
    empty = (np.zeros(0, np.int64), np.zeros((0, 3), np.float32))
    found = spindle_command_steps(_scans(*empty, _samples(COMMANDS)))
    assert found == [(acted, speed) for acted, speed, _ in COMMANDS if not math.isnan(speed)]
    stamps, angles = _samples(COMMANDS)
    angles[30] += 1e-6  # a sample the spindle never gave
    assert spindle_command_steps(_scans(*empty, (stamps, angles))) is None
    assert spindle_command_steps(_scans(*empty, None)) is None


@pytest.fixture(scope='module')
def recorded() -> LaserScans:
    """A second of the pinned robot's scans with the spindle commanded as COMMANDS say, cast
    as the node casts them (the spindle's step after each physics step, a scan of the step's
    start every 25 ms), its head pitched down so that the scans meet the floor."""
    sim = AtlasSimulator(load_model(), load_gains_yaml(DEFAULT_GAINS_FILE))
    head = HeadSensors(sim.model, sim.data, sim.dt_s, seed=4)
    stamps, ranges = [], []
    while sim.sim_time_ns < RUN_NS:
        sim.step()
        for acted_ns, speed, _ in COMMANDS:
            if acted_ns == sim.sim_time_ns and not math.isnan(speed):
                head.spindle.command(speed)
        head.step()
        if sim.state_time_ns % SCAN_EVERY_NS == 0:
            head.scan(sim.state_time_ns)
            stamps.append(sim.state_time_ns)
            ranges.append(head.scan_wire.ranges.copy())
    return _scans(np.array(stamps, dtype=np.int64), np.stack(ranges), _samples(COMMANDS))


def _replayed(scans: LaserScans) -> tuple[int, int]:
    sim = AtlasSimulator(load_model(), load_gains_yaml(DEFAULT_GAINS_FILE))
    replay = ScanReplay(sim, scans, seed=4)
    while sim.sim_time_ns < RUN_NS:
        sim.step()
        replay()
    return replay.compared, replay.differing


def test_a_spun_spindle_s_scans_replay_bit_for_bit(recorded: LaserScans) -> None:
    warnings: list[str] = []
    assert ScanReplay.comparable(recorded, warnings) and warnings == []
    assert np.isfinite(recorded.ranges).any(axis=1).sum() > 5  # the spun scans hit things
    assert _replayed(recorded) == (len(recorded.stamp_ns), 0)
    # /tf a step later: the commands are placed a step late, and the scans differ.
    late = _scans(recorded.stamp_ns, recorded.ranges,
                  (recorded.spindle_samples[0] + MS, recorded.spindle_samples[1]))
    compared, differing = _replayed(late)
    assert compared == len(recorded.stamp_ns) and differing > compared // 2
    stamps, angles = recorded.spindle_samples
    unlike = _scans(recorded.stamp_ns, recorded.ranges, (stamps, angles + 1e-6))
    assert not ScanReplay.comparable(unlike, warnings)
    assert warnings == [f'{LASER_SCAN} is not compared: the spindle was commanded '
                        f'({SET_SPINDLE_SPEED}), and the recorded /tf does not say the step '
                        'each command first acted in.']
