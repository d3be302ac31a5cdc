"""The offline trials' simulators are built from a model and gains compiled and parsed once a
process (push_trial.standing_simulator): each trial's are its own deep copies, equal to a fresh
compile's in every array, and a trial on them steps as on a freshly compiled model."""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.balance.push_trial import standing_simulator
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasSimulator,
    load_gains_yaml,
    load_model,
)

STEPS = 300


def _arrays(model: mujoco.MjModel) -> dict[str, np.ndarray]:
    """Every array the model holds, by name (its options' too)."""
    found = {}
    for owner, prefix in ((model, ''), (model.opt, 'opt.')):
        for name in dir(owner):
            if not name.startswith('_'):
                value = getattr(owner, name)
                if isinstance(value, np.ndarray):
                    found[prefix + name] = value.copy()
    return found


def test_each_trial_simulator_has_a_model_and_gains_of_its_own() -> None:
    first = standing_simulator()
    damping, p_gains = first.model.dof_damping.copy(), first.gains.p.copy()
    first.model.dof_damping[:] += 5.0  # what the joints' velocity gain does to a model
    first.gains.p[:] += 1.0
    second = standing_simulator()
    np.testing.assert_array_equal(second.model.dof_damping, damping)
    np.testing.assert_array_equal(second.gains.p, p_gains)
    assert second.model is not first.model and second.gains is not first.gains
    assert second.atlas.qpos_adr is not first.atlas.qpos_adr


def test_a_trial_model_is_a_fresh_compile_and_steps_as_one() -> None:
    copied = standing_simulator()
    fresh = AtlasSimulator(load_model(), load_gains_yaml(DEFAULT_GAINS_FILE), time_to_unpin_s=0.0)
    place_in_stand_pose(fresh.atlas, fresh.data)
    ours, theirs = _arrays(copied.model), _arrays(fresh.model)
    assert ours.keys() == theirs.keys() and len(ours) > 100
    different = [name for name in ours if ours[name].tobytes() != theirs[name].tobytes()]
    assert not different, f'arrays not equal bit for bit: {different}'
    for _ in range(STEPS):
        copied.step()
        fresh.step()
    assert copied.data.qpos.tobytes() == fresh.data.qpos.tobytes()
    assert copied.data.qvel.tobytes() == fresh.data.qvel.tobytes()
