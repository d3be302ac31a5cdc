"""Offline command latency (CommandLatency): each command takes effect the drawn number of
steps late, in order, and a sweep row's seed picks the draws."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.offline.player import CommandLatency, write_offline_bag
from tutorial_atlas_control.search.runs import SweepError
from tutorial_atlas_control.search.sweep import SweepInputs, build_specs, parse_latency
from tutorial_atlas_control.sim.controller import DEFAULT_GAINS_FILE, load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.trajectories.trajectory import Waypoint

ELBOW = JOINT_INDEX['l_arm_elx']
#: One waypoint: the left elbow to 1 rad in 0.2 s (10 commands, 20 ms apart).
RAMP = [Waypoint(0.2, np.where(np.arange(NUM_JOINTS) == ELBOW, 1.0, 0.0))]


def _elbow_targets(tmp_path: Path, latency: CommandLatency | None) -> np.ndarray:
    """The elbow's active command after every step from the switch to User on."""
    targets: list[float] = []

    def on_step(sim: AtlasSimulator) -> None:
        targets.append(float(sim.commands.law_command.position[ELBOW]))

    write_offline_bag(tmp_path / f'run{len(list(tmp_path.iterdir()))}.bag', 'ramp.yaml', 'ramp',
                      RAMP, load_gains_yaml(DEFAULT_GAINS_FILE), settle_s=0.05,
                      start_after_s=0.01, on_step=on_step, latency=latency)
    return np.array(targets)


def _changes(targets: np.ndarray) -> np.ndarray:
    """Steps at which the elbow's target changed."""
    return np.flatnonzero(np.diff(targets)) + 1


def test_a_fixed_latency_moves_every_command_that_many_steps(tmp_path: Path) -> None:
    at_once = _changes(_elbow_targets(tmp_path, None))
    late = _changes(_elbow_targets(tmp_path, CommandLatency(3, 3)))
    # The first change is the switch to User (the mode's hold); the first command repeats
    # the pose; the nine after it ramp the elbow.
    assert len(at_once) == len(late) == 10 and late[0] == at_once[0]
    assert np.array_equal(late[1:], at_once[1:] + 3)


def test_drawn_latencies_keep_the_order_and_the_bounds(tmp_path: Path) -> None:
    at_once_targets = _elbow_targets(tmp_path, None)
    at_once = _changes(at_once_targets)
    targets = _elbow_targets(tmp_path, CommandLatency(0, 15, seed=7))
    late = _changes(targets)
    assert np.all(np.diff(targets) >= 0.0)  # never back: sent in order, applied in order
    assert targets[-1] == at_once_targets[-1] == 1.0
    delays = late[1:] - at_once[1:]
    assert np.all((delays >= 0) & (delays <= 15)) and len(set(delays)) > 1


def test_the_seed_picks_the_draws(tmp_path: Path) -> None:
    first = _elbow_targets(tmp_path, CommandLatency(0, 15, seed=1))
    again = _elbow_targets(tmp_path, CommandLatency(0, 15, seed=1))
    other = _elbow_targets(tmp_path, CommandLatency(0, 15, seed=2))
    assert np.array_equal(first, again)
    assert not np.array_equal(first, other)


def test_repeats_differ_only_in_their_seed(tmp_path: Path) -> None:
    path = tmp_path / 'ramp.yaml'
    path.write_text('ramp:\n  - [0.2, "' + ' '.join(['0'] * NUM_JOINTS) + '"]\n')
    specs = build_specs(SweepInputs([(str(path), 'ramp')], [str(DEFAULT_GAINS_FILE)],
                                    seed=5, latency_steps=(1, 3), repeats=3))
    assert [spec.seed for spec in specs] == [5, 6, 7]
    assert {spec.latency_steps for spec in specs} == {(1, 3)}
    assert specs[0].latency() == CommandLatency(1, 3, 5)


@pytest.mark.parametrize(('text', 'expected'), [('1:3', (1, 3)), ('4', (4, 4)), ('0:0', (0, 0))])
def test_latency_text(text: str, expected: tuple[int, int]) -> None:
    assert parse_latency(text) == expected


@pytest.mark.parametrize('text', ['3:1', '-1:2', '1:2:3', 'a:b', '1.5:2', ''])
def test_bad_latency_text(text: str) -> None:
    with pytest.raises(SweepError, match='is not LO:HI whole milliseconds'):
        parse_latency(text)
