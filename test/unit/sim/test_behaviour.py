"""A behaviour installed as Stand: its torque is f_out, blended with the user's PID by
k_effort exactly as the hold's was; started when Stand begins; silent in other modes."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_command import decode_atlas_command, encode_atlas_command
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import PidState, compute_torque, load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
DT_S = 0.001
#: The joints a mixed session gives the user (k_effort 255): the left arm.
USER_JOINTS = [JOINT_INDEX[name] for name in ('l_arm_usy', 'l_arm_shx', 'l_arm_ely',
                                              'l_arm_elx', 'l_arm_uwy', 'l_arm_mwx')]


class FixedBehaviour:
    """f_out a fixed torque; counts its calls and remembers the state it started from."""

    def __init__(self, torque_nm: np.ndarray) -> None:
        self.torque_nm = torque_nm
        self.starts: list[np.ndarray] = []
        self.calls = 0

    def start(self, data: mujoco.MjData) -> None:
        self.starts.append(data.qpos.copy())

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        self.calls += 1
        return self.torque_nm


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


def make_sim(atlas: atlas_model.AtlasModel, compiled_law: bool = True) -> AtlasSimulator:
    return AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0,
                          compiled_law=compiled_law)


def f_out(atlas: atlas_model.AtlasModel) -> np.ndarray:
    """A torque per joint, some beyond their effort limits (those must be clamped)."""
    torque = np.linspace(-20.0, 20.0, NUM_JOINTS)
    torque[0] = 10.0 * atlas.effort_limit_nm[0]
    return torque


def test_stand_applies_the_behaviour_torque_within_the_limits(
        atlas: atlas_model.AtlasModel) -> None:
    sim = make_sim(atlas)
    behaviour = FixedBehaviour(f_out(atlas))
    sim.install_stand(behaviour)  # the simulator starts in Stand: the behaviour starts now
    assert len(behaviour.starts) == 1
    expected = np.clip(f_out(atlas), -atlas.effort_limit_nm, atlas.effort_limit_nm)
    np.testing.assert_array_equal(sim.next_law_torque(), expected)
    sim.step()
    assert behaviour.calls == 2  # the prediction and the step
    np.testing.assert_array_equal(sim.torque_nm, expected)
    np.testing.assert_array_equal(sim.data.ctrl, expected)
    assert sim.torque_nm[0] == atlas.effort_limit_nm[0]


@pytest.mark.parametrize('compiled_law', [True, False], ids=['compiled', 'numpy'])
def test_k_effort_255_joints_follow_the_user_the_rest_the_behaviour(
        library, atlas: atlas_model.AtlasModel, compiled_law: bool) -> None:
    """A mixed session: an AtlasCommand with k_effort 255 on the left arm, 0 elsewhere.
    The arm gets its PID torque, every other joint f_out; both laws bit for bit."""
    sim = make_sim(atlas, compiled_law)
    assert sim.uses_compiled_law is compiled_law
    behaviour = FixedBehaviour(f_out(atlas))
    sim.install_stand(behaviour)
    for _ in range(5):
        sim.step()
    k_effort = [0] * NUM_JOINTS
    for joint in USER_JOINTS:
        k_effort[joint] = 255
    target = np.full(NUM_JOINTS, 0.4)
    sim.receive_updates([decode_atlas_command(encode_atlas_command(
        0, {'position': list(target), 'k_effort': k_effort})).update])
    user = sim.user_command.copy()
    q, v = sim.joint_positions(), sim.joint_velocities()
    predicted = sim.next_law_torque()
    sim.step()
    np.testing.assert_array_equal(sim.torque_nm, predicted)
    user.k_effort[:] = 1.0
    pid_nm = compute_torque(user, q, v, PidState(), DT_S, atlas.lower_rad, atlas.upper_rad,
                            atlas.effort_limit_nm)
    behaviour_nm = np.clip(f_out(atlas), -atlas.effort_limit_nm, atlas.effort_limit_nm)
    others = np.setdiff1d(np.arange(NUM_JOINTS), USER_JOINTS)
    np.testing.assert_allclose(sim.torque_nm[USER_JOINTS], pid_nm[USER_JOINTS], rtol=1e-12)
    np.testing.assert_array_equal(sim.torque_nm[others], behaviour_nm[others])
    assert np.abs(pid_nm[USER_JOINTS] - behaviour_nm[USER_JOINTS]).max() > 1.0


def test_laws_agree_bit_for_bit_under_a_half_blend(library, atlas: atlas_model.AtlasModel) -> None:
    sims = [make_sim(atlas, flag) for flag in (True, False)]
    update = decode_atlas_command(encode_atlas_command(
        0, {'position': [0.2] * NUM_JOINTS, 'k_effort': [128] * NUM_JOINTS})).update
    for sim in sims:
        sim.install_stand(FixedBehaviour(f_out(atlas)))
        sim.receive_updates([update])
    for _ in range(50):
        for sim in sims:
            sim.step()
    assert sims[0].torque_nm.tobytes() == sims[1].torque_nm.tobytes()
    assert sims[0].data.qpos.tobytes() == sims[1].data.qpos.tobytes()


def test_other_modes_do_not_run_the_behaviour_and_stand_restarts_it(
        atlas: atlas_model.AtlasModel) -> None:
    sim = make_sim(atlas)
    behaviour = FixedBehaviour(f_out(atlas))
    sim.install_stand(behaviour)
    for mode in (ControlMode.USER, ControlMode.FREEZE, ControlMode.STAND_PREP,
                 ControlMode.RAGDOLL):
        sim.set_mode(mode)
        sim.step()
        assert sim.behaviours.acting is None
    assert behaviour.calls == 0
    assert not np.array_equal(sim.torque_nm, f_out(atlas))
    for _ in range(200):
        sim.step()  # ragdoll: the robot moves
    sim.set_mode(ControlMode.STAND)
    assert len(behaviour.starts) == 2
    np.testing.assert_array_equal(behaviour.starts[-1], sim.data.qpos)  # from where it is
    sim.reset_world()
    assert len(behaviour.starts) == 3  # reset in Stand: starts again from the reset robot
    np.testing.assert_array_equal(behaviour.starts[-1], sim.data.qpos)
    sim.install_stand(None)
    sim.step()
    assert behaviour.calls == 0 and sim.behaviours.acting is None  # Stand is the hold again
