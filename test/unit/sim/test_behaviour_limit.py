"""A behaviour's torque alone (no command blended) is limited by one C call
(atlas_behaviour_torque): the torque, MjData.ctrl and f_out bit for bit numpy's maximum with
the limits' negatives then minimum with the limits, on torques beyond the limits, at them,
signed zeros, infinities and NaN."""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.joint_law import JointLaw


def _torques(limit: np.ndarray) -> list[np.ndarray]:
    rng = np.random.default_rng(7)
    cases = [rng.uniform(-3.0, 3.0, NUM_JOINTS) * limit for _ in range(20)]
    cases += [limit.copy(), -limit, limit * (1.0 + 1e-15), np.zeros(NUM_JOINTS),
              -np.zeros(NUM_JOINTS)]
    special = rng.uniform(-2.0, 2.0, NUM_JOINTS) * limit
    special[[0, 5, 9, 20]] = (np.nan, np.inf, -np.inf, -0.0)
    return [*cases, special]


def test_a_lone_behaviours_torque_is_limited_as_numpy_limits_it(library) -> None:
    atlas = atlas_model.load_model()
    compiled_data, numpy_data = mujoco.MjData(atlas.model), mujoco.MjData(atlas.model)
    compiled = JointLaw(atlas, compiled_data, 0.001, compiled=True)
    assert compiled.compiled
    reference = JointLaw(atlas, numpy_data, 0.001, compiled=False)
    limit = atlas.effort_limit_nm
    for torque in _torques(limit):
        compiled.apply_behaviour(torque, None)
        reference.apply_behaviour(torque, None)
        expected = np.minimum(np.maximum(torque, -limit), limit)
        for law, data in ((compiled, compiled_data), (reference, numpy_data)):
            assert law.torque_nm.tobytes() == expected.tobytes()
            assert data.ctrl.tobytes() == expected.tobytes()
            assert law.f_out_nm.tobytes() == expected.tobytes()
