"""The compiled whole-body call's reference buffer holds every field of the reference loaded
last, though it copies a rate array only when it is not the read-only one copied before (a
take-over's zeros, every tick): a random sequence of references sharing those zeros, with
rates of their own, with one writable rate array written into between loads, and with a
read-only view of an array written into."""

from __future__ import annotations

import dataclasses

import mujoco
import numpy as np

from tutorial_atlas_control.balance.compiled_whole_body import REFERENCE_FIXED
from tutorial_atlas_control.balance.estimator import BalanceEstimator
from tutorial_atlas_control.balance.stand import StandController, StandReference, pelvis_frame
from tutorial_atlas_control.balance.stand_behaviour import _reference_without_rates
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.sim import model as atlas_model

JOINTS = 28


def _layout(reference: StandReference) -> np.ndarray:
    """The buffer atlas_whole_body.c reads (WB_REF_*), made from the reference's fields."""
    return np.concatenate([reference.capture_point,
                           [reference.com_height_m, reference.com_height_rate_m_s],
                           reference.pelvis_rotation.ravel(), reference.pelvis_angular_velocity,
                           reference.posture_rad, reference.posture_rate_rad_s])


def test_the_buffer_holds_each_reference_loaded() -> None:
    atlas = atlas_model.load_model()
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    estimator = BalanceEstimator(atlas)
    state = estimator.estimate(data.qpos, data.qvel)
    base = StandReference.from_state(state)
    controller = StandController(estimator.mass_kg, atlas.effort_limit_nm, base,
                                 estimator.sole_half_size_m, compiled=True)
    kernel = controller.compiled_whole_body
    assert kernel is not None  # the library is built by make setup
    rng = np.random.default_rng(61)
    writable_turn = np.zeros(3)
    written_base = np.zeros(JOINTS)
    read_only_view = written_base[:]
    read_only_view.setflags(write=False)
    kinds = []
    for case in range(400):
        kind = int(rng.integers(0, 4))
        kinds.append(kind)
        capture = base.capture_point + rng.normal(0.0, 0.05, 2)
        frame = pelvis_frame(float(rng.normal(0.0, 0.3)), float(rng.normal(0.0, 0.1)))
        posture = rng.normal(0.0, 0.3, JOINTS)
        if kind == 0:  # a take-over's: the shared read-only zeros
            reference = _reference_without_rates(capture, 0.8, frame, posture)
        elif kind == 1:  # rates of its own
            reference = dataclasses.replace(
                base, capture_point=capture, pelvis_rotation=frame, posture_rad=posture,
                pelvis_angular_velocity=rng.normal(0.0, 0.2, 3),
                posture_rate_rad_s=rng.normal(0.0, 0.2, JOINTS))
        elif kind == 2:  # the same writable array, written into since the last load
            writable_turn[:] = rng.normal(0.0, 0.2, 3)
            reference = dataclasses.replace(base, capture_point=capture,
                                            pelvis_angular_velocity=writable_turn)
        else:  # the same read-only view, its base written into since the last load
            written_base[:] = rng.normal(0.0, 0.2, JOINTS)
            reference = dataclasses.replace(base, posture_rate_rad_s=read_only_view)
        kernel.load(state, controller.contacts_for((True, True), None), np.zeros(JOINTS),
                    np.zeros(JOINTS), (np.ones(JOINTS), np.ones(JOINTS)), reference)
        assert kernel._reference.tobytes() == _layout(reference).tobytes(), (case, kind)
    assert len(kernel._reference) == REFERENCE_FIXED + 2 * JOINTS
    assert {0, 1, 2, 3} <= set(kinds)
