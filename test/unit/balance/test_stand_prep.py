"""StandPrep: from where the joints are to DRCSim's Stand pose over PREP_S, a PD with the
parameter gains; installed for StandPrep by the AtlasSimInterface with the balancing Stand."""

from __future__ import annotations

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.asi import AtlasSimInterface
from tutorial_atlas_control.balance import STAND_POSE_RAD, StandPrepBehaviour
from tutorial_atlas_control.balance.stand_prep import PREP_S
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasModel,
    AtlasSimulator,
    load_gains_yaml,
    load_model,
)


@pytest.fixture(scope='module')
def atlas() -> AtlasModel:
    return load_model()


def test_the_target_goes_from_the_start_pose_to_the_stand_pose(atlas: AtlasModel) -> None:
    gains = load_gains_yaml(DEFAULT_GAINS_FILE)
    prep = StandPrepBehaviour(atlas, gains)
    data = mujoco.MjData(atlas.model)
    data.time = 3.0
    start = data.qpos[atlas.qpos_adr].copy()  # the initial pose: every joint 0
    prep.start(data)
    np.testing.assert_array_equal(prep.target_at(3.0), start)
    middle = prep.target_at(3.0 + PREP_S / 2)
    np.testing.assert_allclose(middle, 0.5 * (start + STAND_POSE_RAD))  # smoothstep's half
    np.testing.assert_array_equal(prep.target_at(3.0 + PREP_S), STAND_POSE_RAD)
    np.testing.assert_array_equal(prep.target_at(10.0), STAND_POSE_RAD)
    data.qvel[atlas.dof_adr] = 0.5
    data.time = 10.0
    np.testing.assert_allclose(prep.torque(data), gains.p * (STAND_POSE_RAD - start)
                               - gains.d * 0.5)


def test_the_interface_installs_it_for_stand_prep(atlas: AtlasModel) -> None:
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE))
    AtlasSimInterface(sim)
    sim.set_mode(ControlMode.STAND_PREP)
    assert isinstance(sim.behaviours.acting, StandPrepBehaviour)
    bare = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE))
    AtlasSimInterface(bare, balance=False)
    bare.set_mode(ControlMode.STAND_PREP)
    assert bare.behaviours.acting is None  # the hold, as DRCSim 2.5.2's stand-in
