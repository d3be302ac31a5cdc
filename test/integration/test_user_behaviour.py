"""The example of a behaviour of one's own (examples/arm_wave.py), registered as the user's
Stand through the interface and run offline in the simulator's tick, over seeded, perturbed
starts: the robot stays up while its right arm rises and the forearm waves; and a run is
deterministic (the same seed, the same bits)."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.asi import AtlasSimInterface, Behavior, load_user_behaviour
from tutorial_atlas_control.balance import place_in_stand_pose
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import AtlasSimulator, load_gains_yaml, load_model
from tutorial_atlas_control.walking import perturb_start

pytestmark = pytest.mark.offline

REPO = Path(__file__).resolve().parents[2]
EXAMPLE = f"{REPO / 'examples' / 'arm_wave.py'}:ArmWave"
CONFIG = REPO / 'config' / 'atlas_controller.yaml'
SEEDS = range(8)
RUN_S = 3.0
#: The pelvis stays above this (m); the shoulder reaches within this of its raised angle
#: (rad); the raised forearm's wave (0.4 rad either way) spans at least this (rad).
PELVIS_ABOVE_M = 0.85
SHOULDER_TOLERANCE_RAD = 0.1
ELBOW_SPAN_RAD = 0.5
SHOULDER, ELBOW = JOINT_NAMES.index('r_arm_shx'), JOINT_NAMES.index('r_arm_elx')
RAISED_RAD = {SHOULDER: 0.8}


def _wave(seed: int | None, run_s: float = RUN_S) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """(pelvis heights, shoulder angles, elbow angles) each 10 ms of a run."""
    atlas = load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    place_in_stand_pose(atlas, sim.data)
    perturb_start(atlas, sim.data, seed)
    interface = AtlasSimInterface(sim, user_behaviour=load_user_behaviour(EXAMPLE, atlas))
    assert sim.mode is ControlMode.STAND
    assert sim.behaviours.acting is interface.library[Behavior.STAND]
    pelvis, shoulder, elbow = [], [], []
    for tick in range(round(run_s / sim.dt_s)):
        sim.step()
        interface.end_step()
        if tick % 10 == 9:
            pelvis.append(float(sim.data.qpos[atlas.free_qpos_adr + 2]))
            shoulder.append(float(sim.data.qpos[atlas.qpos_adr[SHOULDER]]))
            elbow.append(float(sim.data.qpos[atlas.qpos_adr[ELBOW]]))
    return np.array(pelvis), np.array(shoulder), np.array(elbow)


def test_the_example_stands_and_waves_over_seeds() -> None:
    waved = 0
    for seed in SEEDS:
        pelvis, shoulder, elbow = _wave(seed)
        late = slice(len(elbow) // 2, None)  # raised by 1 s: the last 1.5 s wave
        if (pelvis.min() > PELVIS_ABOVE_M
                and abs(shoulder[late].mean() - RAISED_RAD[SHOULDER]) < SHOULDER_TOLERANCE_RAD
                and np.ptp(elbow[late]) > ELBOW_SPAN_RAD):
            waved += 1
    assert waved == len(SEEDS)


def test_a_run_of_the_example_is_deterministic() -> None:
    first, again = _wave(3, 1.0), _wave(3, 1.0)
    for a, b in zip(first, again):
        np.testing.assert_array_equal(a, b)


def test_manipulate_is_not_served_beside_the_users_stand() -> None:
    atlas = load_model()
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    interface = AtlasSimInterface(sim, user_behaviour=load_user_behaviour(EXAMPLE, atlas))
    assert Behavior.MANIPULATE not in interface.session.served
    assert interface.serves(ControlMode.WALK) and interface.serves(ControlMode.STEP)
