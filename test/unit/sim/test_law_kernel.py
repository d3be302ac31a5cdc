"""The compiled controller law (src/atlas_law.c) equals the numpy law bit for bit."""

from __future__ import annotations

import warnings
from pathlib import Path

import numpy as np
import pytest
from test_controller import random_command

from tutorial_atlas_control import native
from tutorial_atlas_control.command.arrays import FIELD_NAMES, LAW_FIELDS, JointCommandArrays
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_command import decode_atlas_command, encode_atlas_command
from tutorial_atlas_control.sim import law_kernel
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import PidState, compute_torque, load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode
from tutorial_atlas_control.sim.vrc import ModeInput, SimInput, VrcMode, WrenchInput

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
DT_S = 0.001


def same_bits(a: np.ndarray, b: np.ndarray) -> bool:
    return a.tobytes() == b.tobytes()


class Joints:
    """q and v laid out like MjData: scattered through longer arrays, in another order."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.qpos = np.zeros(NUM_JOINTS + 7)
        self.qvel = np.zeros(NUM_JOINTS + 6)
        self.qpos_adr = (rng.permutation(NUM_JOINTS) + 7).astype(np.intp)
        self.dof_adr = (rng.permutation(NUM_JOINTS) + 6).astype(np.intp)

    def set(self, q: np.ndarray, v: np.ndarray) -> None:
        self.qpos[self.qpos_adr] = q
        self.qvel[self.dof_adr] = v

    def law_joints(self, lower: np.ndarray, upper: np.ndarray,
                   limit: np.ndarray) -> law_kernel.LawJoints:
        return law_kernel.LawJoints(self.qpos, self.qpos_adr, self.qvel, self.dof_adr, lower,
                                    upper, limit, DT_S)


def test_compiled_law_equals_the_numpy_law_on_random_inputs(library) -> None:
    """300 runs of 60 steps: saturation, tie-back, ki changes and sign flips, inverted
    integral bounds, targets beyond the limits, resets mid-run; torque and memory compared."""
    rng = np.random.default_rng(18)
    counts = {'tie_backs': 0, 'inverted_bounds': 0, 'negative_ki': 0, 'saturated': 0}
    for _run in range(300):
        lower = rng.uniform(-2.5, 0.0, NUM_JOINTS)
        upper = lower + rng.uniform(0.0, 3.0, NUM_JOINTS)
        upper[:3] = lower[:3]  # a joint without range
        limit = rng.uniform(0.0, 200.0, NUM_JOINTS)
        limit[3] = 0.0
        joints = Joints(rng)
        numpy_state, c_state = PidState(), PidState()
        torque, ctrl = np.zeros(NUM_JOINTS), np.full(NUM_JOINTS, np.nan)
        law = law_kernel.CompiledLaw(library, joints.law_joints(lower, upper, limit), c_state,
                                     torque, ctrl)
        command = random_command(rng)
        q = rng.uniform(-2.0, 2.0, NUM_JOINTS)
        v = rng.uniform(-5.0, 5.0, NUM_JOINTS)
        for step in range(60):
            if rng.random() < 0.2:  # a new command object: ki and bounds change
                command = random_command(rng)
                if rng.random() < 0.5:  # a merged one: its rows in one block (rows_block)
                    command = command.copy()
            elif rng.random() < 0.1:  # the same object, edited in place
                command.ki_position[:] = -command.ki_position
            if step == 30 and rng.random() < 0.5:
                numpy_state.reset()
                c_state.reset()
            q = q + rng.normal(0.0, 0.05, NUM_JOINTS)
            v = v + rng.normal(0.0, 0.5, NUM_JOINTS)
            if step % 7 == 0:
                q[5] = upper[5]  # exactly at a limit
                q[6] = -0.0
            joints.set(q, v)
            expected = compute_torque(command, q, v, numpy_state, DT_S, lower, upper, limit)
            law(command)
            assert same_bits(torque, expected), (step, torque - expected)
            assert same_bits(ctrl, expected)
            assert same_bits(c_state.integral, numpy_state.integral), step
            assert same_bits(c_state.previous_error, numpy_state.previous_error), step
            assert c_state.initialized
            counts['saturated'] += int(np.count_nonzero(np.abs(expected) == limit))
            counts['inverted_bounds'] += int(np.count_nonzero(
                command.i_effort_min > command.i_effort_max))
            counts['negative_ki'] += int(np.count_nonzero(command.ki_position < -1e-6))
            counts['tie_backs'] += int(np.count_nonzero(  # saturated with ki on
                (np.abs(command.ki_position) > 1e-6) & (np.abs(torque) == limit)))
    assert min(counts.values()) > 1000, counts  # every case the law distinguishes was exercised


def test_compiled_law_refuses_misshapen_arrays(library) -> None:
    state = PidState()
    good = np.zeros(NUM_JOINTS)
    adr = np.arange(NUM_JOINTS, dtype=np.intp)
    with pytest.raises(ValueError, match=r'qpos_adr has shape \(3,\), expected \(28,\)'):
        law_kernel.CompiledLaw(library, law_kernel.LawJoints(good, adr[:3], good, adr, good,
                                                             good, good, DT_S),
                               state, np.zeros(NUM_JOINTS))
    with pytest.raises(ValueError, match='C-contiguous int64 arrays, got int32'):
        law_kernel.CompiledLaw(library, law_kernel.LawJoints(good, adr.astype(np.int32), good,
                                                             adr, good, good, good, DT_S),
                               state, np.zeros(NUM_JOINTS))


def run_simulator(compiled_law: bool) -> tuple[AtlasSimulator, list[bytes]]:
    """Stand past the pin, then User commands with integral gains that saturate, ragdoll,
    a reset: the qpos bytes after every step."""
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG), time_to_unpin_s=0.3,
                         compiled_law=compiled_law)
    assert sim.uses_compiled_law is compiled_law
    rng = np.random.default_rng(7)
    states = []
    commands = [random_command(rng) for _ in range(4)]
    for step in range(2500):
        if step == 600:
            sim.set_mode(ControlMode.USER)
        if step in (700, 900, 1100, 1300):
            command = commands[(step - 700) // 200]
            sim.receive_command([], {name: getattr(command, name) for name in FIELD_NAMES})
        if step == 1500:
            sim.set_mode(ControlMode.RAGDOLL)
        if step == 1800:
            sim.reset_world()
            sim.set_mode(ControlMode.FREEZE)
        sim.step()
        states.append(sim.data.qpos.tobytes() + sim.torque_nm.tobytes()
                      + sim.law.pid.integral.tobytes())
    return sim, states


def test_simulator_runs_identically_with_either_law(library) -> None:
    _, with_c = run_simulator(True)
    _, with_numpy = run_simulator(False)
    first_difference = next((i for i, (a, b) in enumerate(zip(with_c, with_numpy)) if a != b),
                            None)
    assert first_difference is None
    integral_at_1500 = np.frombuffer(with_numpy[1499][-8 * NUM_JOINTS:])
    assert np.count_nonzero(integral_at_1500) > 5  # the User commands' integral was in play


def test_missing_library_falls_back_to_numpy_with_one_warning(
        monkeypatch: pytest.MonkeyPatch, tmp_path: Path) -> None:
    monkeypatch.setenv(native.LIBRARY_ENV, str(tmp_path / 'missing.so'))
    monkeypatch.setattr(native, '_library', None)
    monkeypatch.setattr(native, '_warned', False)
    with pytest.warns(RuntimeWarning, match=r'^TAC_LAW_LIBRARY=.*missing\.so does not exist; '
                                            r'using the numpy controller law'):
        first = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    assert not first.uses_compiled_law
    with warnings.catch_warnings():
        warnings.simplefilter('error')
        second = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    assert not second.uses_compiled_law
    second.step()
    assert np.isfinite(second.torque_nm).all()


def test_ragdoll_command_gives_zero_torque(library) -> None:
    sim = AtlasSimulator(atlas_model.load_model(), load_gains_yaml(CONFIG))
    sim.set_mode(ControlMode.RAGDOLL)
    sim.step()
    assert not sim.torque_nm.any() and not sim.data.ctrl.any()
    assert JointCommandArrays.zeros().position.shape == (NUM_JOINTS,)


K_EFFORT_128 = 128 / 255.0


def stand_with_cheat(atlas: atlas_model.AtlasModel, compiled_law: bool,
                     cheat: SimInput) -> AtlasSimulator:
    """Standing in Stand mode, past the pin, with `cheat` acting for 50 steps."""
    sim = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0,
                         compiled_law=compiled_law)
    assert sim.uses_compiled_law is compiled_law
    for _ in range(300):
        sim.step()
    sim.apply_input(cheat)
    for _ in range(50):
        sim.step()
    return sim


@pytest.mark.parametrize('cheat', [WrenchInput((40.0, 0.0, 0.0), (0.0, 0.0, 0.0)),
                                   ModeInput(VrcMode.HARNESSED)], ids=['wrench', 'harnessed'])
def test_both_laws_blend_an_atlas_command_while_a_cheat_acts(library, cheat: SimInput) -> None:
    """Stand's hold blended with an AtlasCommand at k_effort 128 while a cheat acts: the
    compiled and numpy laws give the same torques, and both are k u + (1 - k) f_out with u
    the command's PID torque and f_out the hold's (a twin without the command)."""
    atlas = atlas_model.load_model()
    compiled, numpy_law, hold_only = (stand_with_cheat(atlas, flag, cheat)
                                      for flag in (True, False, False))
    assert compiled.vrc.active
    q, v = compiled.joint_positions(), compiled.joint_velocities()
    assert same_bits(q, hold_only.joint_positions()) and same_bits(q, numpy_law.joint_positions())
    target = np.linspace(-0.3, 0.3, NUM_JOINTS)
    update = decode_atlas_command(encode_atlas_command(
        0, {'position': list(target), 'k_effort': [128] * NUM_JOINTS})).update
    for sim in (compiled, numpy_law):
        sim.receive_updates([update])
    user = compiled.user_command.copy()
    assert (user.k_effort == K_EFFORT_128).all()
    for sim in (compiled, numpy_law, hold_only):
        sim.step()
    hold_nm = hold_only.torque_nm
    # u: the command's PID torque on its first step (no derivative), unclamped
    user.k_effort[:] = 1.0
    u_nm = compute_torque(user, q, v, PidState(), DT_S, atlas.lower_rad, atlas.upper_rad,
                          np.full(NUM_JOINTS, np.inf))
    expected_nm = np.clip(K_EFFORT_128 * u_nm + (1.0 - K_EFFORT_128) * hold_nm,
                          -atlas.effort_limit_nm, atlas.effort_limit_nm)
    np.testing.assert_allclose(numpy_law.torque_nm, expected_nm, rtol=1e-12, atol=1e-9)
    assert same_bits(compiled.torque_nm, numpy_law.torque_nm)
    np.testing.assert_allclose(compiled.torque_nm, expected_nm, rtol=1e-12, atol=1e-9)
    assert np.abs(compiled.torque_nm - hold_nm).max() > 5.0  # the blend is not the hold
    for _ in range(200):
        compiled.step()
        numpy_law.step()
    assert same_bits(compiled.data.qpos, numpy_law.data.qpos)
    assert same_bits(compiled.torque_nm, numpy_law.torque_nm)


def test_a_copied_command_is_one_block_until_a_field_is_given_another_array() -> None:
    rng = np.random.default_rng(3)
    original = random_command(rng)
    assert original.rows_block() is None
    copied = original.copy()
    block = copied.rows_block()
    assert block is not None and block.shape == (len(LAW_FIELDS), NUM_JOINTS)
    for row, name in enumerate(LAW_FIELDS):
        assert same_bits(block[row], getattr(original, name))
        getattr(copied, name)[0] += 1.0  # edited in place: still the block's row
        assert block[row, 0] == getattr(original, name)[0] + 1.0
    copied.kp_velocity = np.zeros(NUM_JOINTS)
    assert copied.rows_block() is None
