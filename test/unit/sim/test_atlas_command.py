"""atlas_msgs/AtlasCommand and Test: decoding, checks, k_effort in the law and the
simulator, merging with JointCommands in the loop, and /atlas/reset_controls."""

from __future__ import annotations

import io
import re
from pathlib import Path

import numpy as np
import pytest
from test_controller import DT_S, LIMIT, LOWER, UPPER, one_joint

from support.stepping_fakes import atlas_bytes, command_bytes, complete_command, full, make_loop
from tutorial_atlas_control import topics
from tutorial_atlas_control.command.arrays import LAW_FIELDS, CommandError
from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_command import (
    decode_atlas_command,
    decode_test,
    encode_atlas_command,
    encode_test,
)
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import (
    PidState,
    compute_torque,
    gains_from_params,
    load_gains_yaml,
)
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode
from tutorial_atlas_control.stepping.controls import ResetControlsRequest
from tutorial_atlas_control.stepping.loop import SteppingLoop
from tutorial_atlas_control.units import NS_PER_S

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
ELX = JOINT_INDEX['l_arm_elx']
N = NUM_JOINTS


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def sim(atlas: atlas_model.AtlasModel) -> AtlasSimulator:
    return AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)


def run(sim: AtlasSimulator, steps: int) -> None:
    for _ in range(steps):
        sim.step()


# -- decoding ----------------------------------------------------------------------------

def test_the_encoder_matches_genpy_for_both_messages() -> None:
    atlas_msgs = pytest.importorskip('atlas_msgs.msg')
    genpy_command = atlas_msgs.AtlasCommand()
    genpy_command.header.stamp.secs, genpy_command.header.stamp.nsecs = 3, 5
    genpy_command.position = full(0.25)
    genpy_command.kp_position = full(100.0)
    genpy_command.k_effort = bytes([255] * N)
    genpy_command.desired_controller_period_ms = 7
    buffer = io.BytesIO()
    genpy_command.serialize(buffer)
    ours = encode_atlas_command(3 * NS_PER_S + 5, {'position': full(0.25),
                                                   'kp_position': full(100.0),
                                                   'k_effort': [255] * N}, 7)
    assert ours == buffer.getvalue()
    genpy_test = atlas_msgs.Test()
    genpy_test.damping = full(0.5)
    genpy_test.k_effort = bytes(range(N))
    buffer = io.BytesIO()
    genpy_test.serialize(buffer)
    assert encode_test(0, {'damping': full(0.5), 'k_effort': list(range(N))}) == \
        buffer.getvalue()


def test_a_full_atlas_command_decodes_to_every_law_field() -> None:
    update = decode_atlas_command(encode_atlas_command(
        2 * NS_PER_S, {'position': full(0.1), 'velocity': full(0.2), 'effort': full(0.3),
                       'kp_position': full(1.5), 'ki_position': full(2.5),
                       'kd_position': full(3.5), 'kp_velocity': full(4.5),
                       'k_effort': [0, 51] + [255] * (N - 2), 'i_effort_min': full(-5.0),
                       'i_effort_max': full(5.0)}, 4))
    assert update.update.is_complete and not update.ignored
    assert update.stamp_ns == 2 * NS_PER_S and update.desired_controller_period_ms == 4
    values = dict(zip(update.fields_set(), update.update.values))
    assert values['kp_position'][0] == 1.5 and values['i_effort_min'][0] == -5.0
    # AtlasPlugin's static_cast<double>(k_effort) / 255.0, the same doubles
    assert list(values['k_effort'][:3]) == [0.0, 51 / 255.0, 1.0]


def test_arrays_of_another_length_keep_their_field_with_one_warning_text() -> None:
    update = decode_atlas_command(encode_atlas_command(
        0, {'position': full(0.1)[:27], 'k_effort': [255] * N, 'kp_position': [1.0] * 3}))
    assert update.fields_set() == ['k_effort']
    assert update.ignored_text() == ('position (27 entries), kp_position (3 entries) not 28 '
                                     'long; those fields keep their previous values')
    empty = decode_atlas_command(encode_atlas_command(0, {'velocity': full(0.0)}))
    assert empty.ignored == () and empty.fields_set() == ['velocity']  # empty arrays: silent


@pytest.mark.parametrize(('arrays', 'text'), [
    ({'position': full(0.0)[:27] + [float('nan')]},
     'position[27] is nan (NaN/Inf are refused)'),
    ({'effort': [float('inf')] * 3},  # refused though that field would be left out
     'effort[0] is inf (NaN/Inf are refused)'),
    ({'kp_position': full(1e7)}, 'kp_position[0] is 1e+07, beyond the sane bound of 1e+06 '
                                 'in magnitude'),
    ({'i_effort_max': full(1e6)}, 'i_effort_max[0] is 1e+06, beyond the sane bound of 100000 '
                                  'in magnitude'),
])
def test_nan_and_absurd_values_refuse_the_whole_atlas_command(arrays: dict, text: str) -> None:
    with pytest.raises(CommandError) as err:
        decode_atlas_command(encode_atlas_command(0, {'k_effort': [255] * N, **arrays}))
    assert str(err.value) == text


def test_test_messages_carry_damping_gains_and_k_effort() -> None:
    update = decode_test(encode_test(0, {'damping': full(0.5), 'kd_position': full(2.0),
                                         'k_effort': [0] * N}))
    assert update.fields_set() == ['damping', 'kd_position', 'k_effort']
    np.testing.assert_array_equal(update.damping, full(0.5))
    with pytest.raises(CommandError, match=r'^damping\[2\] is -1, outside 0\.\.10000 N m s/rad$'):
        decode_test(encode_test(0, {'damping': [0.1, 0.1, -1.0] + full(0.1)[3:]}))


def test_malformed_bytes_are_refused() -> None:
    raw = encode_atlas_command(0, {'position': full(0.1)})
    with pytest.raises(CommandError, match=r'^malformed message \('):
        decode_atlas_command(raw[:-9])
    with pytest.raises(CommandError, match=r'^malformed message \(1 bytes left'):
        decode_atlas_command(raw + b'\0')


# -- the law ------------------------------------------------------------------------------

def test_k_effort_blends_the_pid_torque_with_f_out_as_by_hand() -> None:
    k = 100 / 255.0
    command = one_joint(position=0.5, kp_position=10.0, effort=2.0)
    command.k_effort[:] = k
    f_out = np.full(N, -30.0)
    result = compute_torque(command, np.full(N, 0.2), np.zeros(N), PidState(), DT_S, LOWER,
                            UPPER, LIMIT, f_out=f_out)
    u_pid = 10.0 * (0.5 - 0.2) + 2.0
    assert result[0] == k * u_pid + (1.0 - k) * -30.0  # about -16.3 N m, within the limit
    # k = 1: the PID alone, whatever f_out; k = 0: f_out alone
    command.k_effort[:2] = (1.0, 0.0)
    result = compute_torque(command, np.full(N, 0.2), np.zeros(N), PidState(), DT_S, LOWER,
                            UPPER, LIMIT, f_out=f_out)
    assert result[0] == 10.0 * (0.5 - 0.2) + 2.0 and result[1] == -30.0


def test_the_blended_torque_saturates_and_ties_the_integral_back() -> None:
    k = 100 / 255.0
    command = one_joint(position=0.5, kp_position=10.0, ki_position=100.0, effort=2.0,
                        i_effort_min=-50.0, i_effort_max=50.0)
    command.k_effort[:] = k
    state = PidState()
    result = compute_torque(command, np.full(N, 0.2), np.zeros(N), state, DT_S, LOWER, UPPER,
                            LIMIT, f_out=np.full(N, -300.0))
    integral = DT_S * 100.0 * 0.3
    unclamped = k * (10.0 * 0.3 + integral + 2.0) + (1.0 - k) * -300.0  # about -180 N m
    assert result[0] == -100.0
    assert state.integral[0] == min(max((-100.0 - unclamped) + integral, -50.0), 50.0) == 50.0


def test_compiled_law_equals_numpy_with_k_effort_and_f_out(library) -> None:
    from test_controller import random_command
    from test_law_kernel import Joints, same_bits

    from tutorial_atlas_control.sim import law_kernel

    rng = np.random.default_rng(25)
    blended = 0
    for _run in range(100):
        lower = rng.uniform(-2.5, 0.0, N)
        upper = lower + rng.uniform(0.0, 3.0, N)
        limit = rng.uniform(0.0, 200.0, N)
        joints = Joints(rng)
        numpy_state, c_state = PidState(), PidState()
        torque, f_out = np.zeros(N), np.zeros(N)
        law = law_kernel.CompiledLaw(library, joints.law_joints(lower, upper, limit), c_state,
                                     torque, None, f_out)
        for _step in range(30):
            command = random_command(rng)
            command.k_effort[:] = rng.choice([0.0, 1.0, 128 / 255.0, 3 / 255.0], N)
            f_out[:] = rng.uniform(-300.0, 300.0, N)
            q, v = rng.uniform(-2.0, 2.0, N), rng.uniform(-5.0, 5.0, N)
            joints.set(q, v)
            expected = compute_torque(command, q, v, numpy_state, DT_S, lower, upper, limit,
                                      f_out=f_out)
            law(command)
            assert same_bits(torque, expected)
            assert same_bits(c_state.integral, numpy_state.integral)
            blended += int(np.count_nonzero(command.k_effort != 1.0))
    assert blended > 1000


# -- the simulator -----------------------------------------------------------------------

def atlas_update(**arrays: list[float]):
    return decode_atlas_command(encode_atlas_command(0, arrays)).update


def test_k_effort_0_in_user_mode_leaves_the_joint_limp(sim: AtlasSimulator) -> None:
    """BDI outputs nothing in User mode: a joint at k_effort 0 gets no torque at all. The
    shoulder (l_arm_shx) holds the arm out sideways against 36 N m of its weight."""
    shx, other = JOINT_INDEX['l_arm_shx'], JOINT_INDEX['r_arm_shx']
    run(sim, 300)
    sim.set_mode(ControlMode.USER)
    k_effort = [255] * N
    k_effort[shx] = 0
    sim.receive_updates([atlas_update(position=list(sim.joint_positions()),
                                      k_effort=k_effort)])
    held = sim.joint_positions()
    torques = []
    for _ in range(1000):
        sim.step()
        torques.append(sim.torque_nm.copy())
    torques = np.array(torques)
    assert not torques[:, shx].any()
    assert np.abs(torques[:, other]).mean() > 20.0  # the other shoulder holds its arm
    moved = np.abs(sim.joint_positions() - held)
    assert moved[shx] > 0.5  # the limp arm fell (rad)
    assert moved[other] < 0.05


def test_in_stand_mode_k_effort_hands_one_joint_to_the_user(
        sim: AtlasSimulator, atlas: atlas_model.AtlasModel) -> None:
    """Stand's hold stands in for BDI's Stand: k_effort 255 on the elbow gives it to the
    AtlasCommand's PID; the joints at 0 keep the hold's torque, bit for bit."""
    twin = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    run(sim, 300)
    run(twin, 300)
    k_effort = [0] * N
    k_effort[ELX] = 255
    position = full(0.0)
    position[ELX] = 0.8
    sim.receive_updates([atlas_update(position=position, k_effort=k_effort)])
    sim.step()
    twin.step()
    others = np.arange(N) != ELX
    assert sim.torque_nm[others].tobytes() == twin.torque_nm[others].tobytes()
    assert sim.torque_nm[ELX] != twin.torque_nm[ELX]
    run(sim, 1500)
    assert abs(sim.joint_positions()[ELX] - 0.8) < 0.05
    assert abs(sim.joint_positions()[JOINT_INDEX['r_arm_elx']]) < 0.05
    # A switch out of User and back sets every k_effort as AtlasPlugin::OnRobotMode does.
    sim.set_mode(ControlMode.USER)
    assert (sim.user_command.k_effort == 1.0).all()
    sim.set_mode(ControlMode.FREEZE)
    assert not sim.user_command.k_effort.any() and sim.commands.blend_command is None


def test_joint_commands_in_stand_mode_stay_ineffective_as_in_drcsim(
        sim: AtlasSimulator, atlas: atlas_model.AtlasModel) -> None:
    twin = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    sim.receive_command([], {'position': full(0.5)})  # k_effort stays 0 outside User
    run(sim, 200)
    run(twin, 200)
    assert sim.data.qpos.tobytes() == twin.data.qpos.tobytes()


def test_test_damping_sets_the_joint_damping(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    damping = full(0.1)
    damping[ELX] = 7.5
    loop.receive_command(encode_test(0, {'damping': damping}), topics.ATLAS_TEST)
    loop.apply_pending_commands()
    assert sim.joint_damping()[ELX] == 7.5
    assert sim.model.dof_damping[sim.atlas.dof_adr[ELX]] == 7.5
    assert log.of('refused') == []


# -- merging in the loop ------------------------------------------------------------------

def test_the_newest_message_sets_the_fields_it_carries(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    sim.set_mode(ControlMode.USER)
    # AtlasCommand, then JointCommands: the JointCommands' position, the AtlasCommand's k
    loop.receive_command(atlas_bytes(position=full(0.1), k_effort=[128] * N), topics.ATLAS_COMMAND)
    loop.receive_command(complete_command(0.2, stamp_ns=5 * NS_PER_S))
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.user_command.position, full(0.2))
    np.testing.assert_array_equal(sim.user_command.k_effort, full(128 / 255.0))
    assert loop.statistics.command_stamp_ns == 5 * NS_PER_S
    # JointCommands, then AtlasCommand: the AtlasCommand's position wins
    loop.receive_command(complete_command(0.3))
    loop.receive_command(atlas_bytes(stamp_ns=6 * NS_PER_S, position=full(0.4)),
                         topics.ATLAS_COMMAND)
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.user_command.position, full(0.4))
    assert sim.user_command.kp_position[0] == 0.0  # from the complete JointCommands
    assert loop.statistics.command_stamp_ns == 6 * NS_PER_S
    # a partial JointCommands after an AtlasCommand sets only its joint
    loop.receive_command(atlas_bytes(position=full(0.5), kd_position=full(3.0)),
                         topics.ATLAS_COMMAND)
    loop.receive_command(command_bytes(['neck_ay'], position=[0.6]))
    loop.apply_pending_commands()
    assert sim.user_command.position[JOINT_INDEX['neck_ay']] == 0.6
    assert sim.user_command.position[ELX] == 0.5 and sim.user_command.kd_position[ELX] == 3.0
    assert log.of('info') == [
        'first /atlas/atlas_command since the start or last reset, at t=0.000 s (User mode)']


def test_a_refused_newest_atlas_command_keeps_the_joint_command_and_its_stamp(
        sim: AtlasSimulator) -> None:
    """Across the two topics: the valid JointCommands stays applied, with its stamp."""
    loop, _, log, _ = make_loop(sim)
    loop.receive_command(complete_command(0.1, stamp_ns=3 * NS_PER_S))
    loop.receive_command(atlas_bytes(stamp_ns=4 * NS_PER_S, position=full(float('nan'))),
                         topics.ATLAS_COMMAND)
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.user_command.position, full(0.1))
    assert log.of('refused') == ['refused /atlas/atlas_command: position[0] is nan '
                                 '(NaN/Inf are refused); previous command kept']
    assert loop.statistics.command_stamp_ns == 3 * NS_PER_S


def test_refusals_and_left_out_fields_are_one_line_each(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    loop.receive_command(atlas_bytes(position=full(0.1)), topics.ATLAS_COMMAND)
    loop.receive_command(atlas_bytes(position=full(0.2), kp_position=full(float('nan'))),
                         topics.ATLAS_COMMAND)
    loop.receive_command(atlas_bytes(velocity=[1.0] * 5, period_ms=10), topics.ATLAS_COMMAND)
    loop.receive_command(atlas_bytes(period_ms=20), topics.ATLAS_COMMAND)
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.user_command.position, full(0.1))
    assert log.of('refused') == ['refused /atlas/atlas_command: kp_position[0] is nan '
                                 '(NaN/Inf are refused); previous command kept']
    assert log.of('kept') == ['/atlas/atlas_command: velocity (5 entries) not 28 long; that '
                              'field keeps its previous values']
    assert log.of('warn') == []
    assert [line for line in log.of('info') if 'synchronization' in line] == [
        'synchronization window on (/atlas/atlas_command desired_controller_period_ms = 10): '
        'each step waits for a command stamped no more than 10 ms before its end, at most '
        '0.025 s per step and 0.25 s per 5 s']
    assert loop.inbox.period_ms == 20


# -- /atlas/reset_controls ------------------------------------------------------------------

def reset(loop: SteppingLoop, bdi: bool = False, pid: bool = False, reload: bool = False,
          command: bytes | None = None, gains: object = None) -> tuple[bool, str]:
    raw = atlas_bytes() if command is None else command
    return loop.reset_controls(ResetControlsRequest(bdi, pid, reload, raw, gains))


def user_with_integral(sim: AtlasSimulator) -> None:
    """User mode, an integral gain on every joint, 100 steps: the integrals are non-zero."""
    sim.set_mode(ControlMode.USER)
    sim.receive_updates([atlas_update(position=full(0.3), ki_position=full(50.0),
                                      i_effort_min=full(-10.0), i_effort_max=full(10.0))])
    run(sim, 100)
    assert sim.law.pid.integral.all()


def test_reset_pid_controller_zeroes_the_law_memory(sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_loop(sim)
    user_with_integral(sim)
    assert reset(loop, pid=True) == (True, 'PID state reset (integral terms and previous '
                                           'errors); atlas_command has no array of 28: no '
                                           'field loaded')
    assert not sim.law.pid.integral.any() and not sim.law.pid.initialized


def test_reload_pid_from_ros_sets_the_gains_and_k_effort(sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_loop(sim)
    user_with_integral(sim)
    gains = load_gains_yaml(CONFIG)
    ok, status = reset(loop, bdi=True, reload=True, gains=gains,
                       command=atlas_bytes(position=full(0.9)))
    assert ok and status == (
        'reset_bdi_controller: there is no BDI controller in this simulator, nothing to '
        'reset; gains reloaded from atlas_controller/gains, k_effort 255 on every joint '
        '(atlas_command ignored)')
    command = sim.user_command
    np.testing.assert_array_equal(command.kp_position, gains.p)
    np.testing.assert_array_equal(command.ki_position, gains.i)
    np.testing.assert_array_equal(command.i_effort_max, gains.i_clamp)
    np.testing.assert_array_equal(command.position, full(0.3))  # targets kept
    assert (command.k_effort == 1.0).all()
    assert sim.law.pid.integral.any()  # reset_pid_controller was not asked


def test_reset_controls_loads_an_atlas_command(sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_loop(sim)
    sim.set_mode(ControlMode.USER)
    k_effort = [255] * N
    k_effort[ELX] = 0
    ok, status = reset(loop, command=atlas_bytes(position=full(0.2), k_effort=k_effort,
                                                 kd_position=[1.0] * 3))
    assert ok and status == ('atlas_command loaded: position, k_effort; kd_position (3 '
                             'entries) not 28 long; that field keeps its previous values')
    np.testing.assert_array_equal(sim.user_command.position, full(0.2))
    assert sim.user_command.k_effort[ELX] == 0.0


def test_a_refused_reset_controls_changes_nothing(sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_loop(sim)
    user_with_integral(sim)
    before = sim.user_command
    integral = sim.law.pid.integral.copy()
    ok, status = reset(loop, pid=True, command=atlas_bytes(effort=full(1e9)))
    assert (ok, status) == (False, 'atlas_command refused: effort[0] is 1e+09, beyond the sane '
                                   'bound of 100000 in magnitude; nothing was done')
    try:
        gains_from_params({})
    except Exception as err:  # noqa: BLE001 - the node passes GainsError's text
        text = str(err)
    ok, status = reset(loop, pid=True, reload=True, gains=text)
    assert not ok and status == f'reload_pid_from_ros: {text}; nothing was done'
    assert status.startswith('reload_pid_from_ros: parameter atlas_controller/gains/back_lbz/p '
                             'is missing')
    assert sim.user_command is before
    np.testing.assert_array_equal(sim.law.pid.integral, integral)
    run(sim, 10)  # and the simulator goes on
    assert np.isfinite(sim.torque_nm).all()


def test_reset_controls_applies_the_commands_received_before_it(sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_loop(sim)
    sim.set_mode(ControlMode.USER)
    loop.receive_command(atlas_bytes(position=full(0.1), kp_position=full(5.0)),
                         topics.ATLAS_COMMAND)
    reset(loop, command=atlas_bytes(position=full(0.7)))
    np.testing.assert_array_equal(sim.user_command.position, full(0.7))
    np.testing.assert_array_equal(sim.user_command.kp_position, full(5.0))


def test_a_mode_switch_comes_after_the_commands_received_before_it(
        sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_loop(sim)
    loop.set_mode(ControlMode.USER)
    loop.receive_command(atlas_bytes(position=full(0.1), k_effort=[255] * N),
                         topics.ATLAS_COMMAND)
    loop.set_mode(ControlMode.STAND)  # AtlasPlugin::OnRobotMode zeroes k_effort after it
    np.testing.assert_array_equal(sim.user_command.position, full(0.1))
    assert not sim.user_command.k_effort.any() and sim.commands.blend_command is None


def test_the_fast_path_for_full_commands_agrees_with_the_general_one() -> None:
    from tutorial_atlas_control.msgs.atlas_command import ATLAS_COMMAND_FIELDS, _decode

    rng = np.random.default_rng(3)
    arrays = {name: rng.uniform(-5.0, 5.0, N) for name, _ in ATLAS_COMMAND_FIELDS}
    arrays['k_effort'] = rng.integers(0, 256, N)
    raw = encode_atlas_command(9, arrays, 11)
    fast, general = decode_atlas_command(raw), _decode(raw, ATLAS_COMMAND_FIELDS, True)
    assert fast.update.rows == general.update.rows
    assert fast.update.values.tobytes() == general.update.values.tobytes()
    assert (fast.stamp_ns, fast.desired_controller_period_ms) == (9, 11)
    arrays['kd_position'][5] = float('nan')
    with pytest.raises(CommandError, match=r'^kd_position\[5\] is nan \(NaN/Inf are refused\)$'):
        decode_atlas_command(encode_atlas_command(0, arrays))


def test_the_gain_memo_decodes_a_stream_as_each_message_alone() -> None:
    """A controller's stream through one AtlasCommandDecoder: new targets on remembered
    gains, new gains, the old ones again, a refused target or gain (same text as alone, and
    the memo still right after it), a short array: every result is decode_atlas_command's."""
    from tutorial_atlas_control.msgs.atlas_command import ATLAS_COMMAND_FIELDS, AtlasCommandDecoder

    rng = np.random.default_rng(8)

    def message(gains_seed: int, **changes: float) -> bytes:
        gains = np.random.default_rng(gains_seed)
        arrays = {name: gains.uniform(0.0, 9.0, N) for name, _ in ATLAS_COMMAND_FIELDS}
        arrays['k_effort'] = gains.integers(0, 256, N)
        for name in ('position', 'velocity', 'effort'):
            arrays[name] = rng.uniform(-2.0, 2.0, N)
        for name, value in changes.items():
            arrays[name][4] = value
        return encode_atlas_command(int(rng.integers(0, 10**12)), arrays, int(rng.integers(256)))

    decoder = AtlasCommandDecoder()
    stream = [message(1), message(1), message(2), message(1), message(1, velocity=np.inf),
              message(1), message(1, kp_velocity=np.nan), message(1, kp_velocity=np.nan),
              message(1), message(3),
              encode_atlas_command(0, {'position': full(0.5), 'kp_position': [1.0] * 3}),
              message(3)]
    for index, raw in enumerate(stream):
        try:
            alone = decode_atlas_command(raw)
        except CommandError as err:
            with pytest.raises(CommandError, match=f'^{re.escape(str(err))}$'):
                decoder.decode(raw)
            continue
        streamed = decoder.decode(raw)
        assert streamed.update.rows == alone.update.rows, index
        assert streamed.update.values.tobytes() == alone.update.values.tobytes(), index
        assert streamed.update.indices.tobytes() == alone.update.indices.tobytes(), index
        assert (streamed.stamp_ns, streamed.desired_controller_period_ms, streamed.ignored) == (
            alone.stamp_ns, alone.desired_controller_period_ms, alone.ignored), index


def test_the_bare_header_path_decodes_and_refuses_as_each_message_alone() -> None:
    """A controller's full commands with an empty frame_id and remembered gains take the
    decoder's one-struct path: targets, stamp and period as decode_atlas_command makes them,
    and the same refusals (NaN, +-Inf where no bound is set, beyond a bound; a bound itself
    accepted); a frame_id, a short array or a byte too many leave that path, same results."""
    from tutorial_atlas_control.msgs.atlas_command import AtlasCommandDecoder

    rng = np.random.default_rng(61)
    gains = {'kp_position': full(100.0), 'ki_position': full(0.0), 'kd_position': full(1.0),
             'kp_velocity': full(0.0), 'k_effort': [255] * N, 'i_effort_min': full(-1.0),
             'i_effort_max': full(1.0)}

    def message(field: str = 'position', value: float | None = None) -> bytes:
        arrays = {name: rng.uniform(-3.0, 3.0, N) for name in ('position', 'velocity', 'effort')}
        if value is not None:
            arrays[field][int(rng.integers(N))] = value
        return encode_atlas_command(int(rng.integers(0, 10**12)), {**arrays, **gains},
                                    int(rng.integers(256)))

    def framed(raw: bytes) -> bytes:  # the same message with frame_id 'pelvis'
        return raw[:12] + (6).to_bytes(4, 'little') + b'pelvis' + raw[16:]

    decoder = AtlasCommandDecoder()
    decoder.decode(message())  # the gains remembered
    bare = [message() for _ in range(5)] + [message('position', 1e300),
                                            message('velocity', -1e3), message('effort', 1e5)]
    refused = [message('position', np.nan), message('position', np.inf),
               message('velocity', -np.inf), message('velocity', 1000.5),
               message('effort', -2e5), message('effort', np.nan)]
    other = [framed(message()), framed(message('effort', 3e5)), message()[:-1] + b'\0\0',
             encode_atlas_command(7, {'position': full(0.25)[:27], **gains})]
    for raw in bare:
        assert decoder._known_gains(raw) is not None
    for index, raw in enumerate(bare + refused + other):
        try:
            alone = decode_atlas_command(raw)
        except CommandError as err:
            with pytest.raises(CommandError, match=f'^{re.escape(str(err))}$'):
                decoder.decode(raw)
            assert index >= len(bare), index
            continue
        streamed = decoder.decode(raw)
        assert streamed.update.rows == alone.update.rows, index
        assert streamed.update.values.tobytes() == alone.update.values.tobytes(), index
        assert (streamed.stamp_ns, streamed.desired_controller_period_ms, streamed.ignored) == (
            alone.stamp_ns, alone.desired_controller_period_ms, alone.ignored), index
    assert sum(1 for raw in refused + other[1:3] if _refused(raw)) == len(refused) + 2


def _refused(raw: bytes) -> bool:
    try:
        decode_atlas_command(raw)
    except CommandError:
        return True
    return False


def test_one_atlas_command_alone_is_merged_as_by_the_general_path(
        atlas: atlas_model.AtlasModel, sim: AtlasSimulator) -> None:
    """The inbox's path for a step's lone AtlasCommand (a 1 kHz controller's) leaves the
    simulator, the stamp, the window's period, the watch and the log as the general path
    does with the same message: full and partial commands, a short array kept, the window
    on and off, refusals, in user mode and out of it."""
    twin = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    fast, _, fast_log, _ = make_loop(sim)
    general, _, general_log, _ = make_loop(twin)
    gains = {'kp_position': full(90.0), 'kd_position': full(2.0), 'k_effort': [200] * N}
    stream = [
        atlas_bytes(3 * NS_PER_S, 0, position=full(0.1), velocity=full(0.0), **gains),
        atlas_bytes(4 * NS_PER_S, 5, position=full(0.2), effort=full(1.0), **gains),
        atlas_bytes(5 * NS_PER_S, 5, position=full(0.3)[:20], velocity=full(0.5)),
        atlas_bytes(6 * NS_PER_S, 0, position=full(float('nan')), **gains),
        atlas_bytes(7 * NS_PER_S, 0, effort=full(3e5)),
        atlas_bytes(0, 0, position=full(-0.2), **gains),
        atlas_bytes(8 * NS_PER_S, 2, k_effort=[0] * N)]
    for index, raw in enumerate(stream):
        if index == 4:
            sim.set_mode(ControlMode.USER)
            twin.set_mode(ControlMode.USER)
        fast.receive_command(raw, topics.ATLAS_COMMAND)
        fast.apply_pending_commands()
        general.inbox._apply_received([(topics.ATLAS_COMMAND, raw)])
        for name in ('user_command', 'law_command', 'blend_command'):
            ours, theirs = getattr(sim.commands, name), getattr(twin.commands, name)
            assert (ours is None) == (theirs is None), (index, name)
            if ours is not None:
                assert _fields_bytes(ours) == _fields_bytes(theirs), (index, name)
        assert (fast.statistics.command_stamp_ns, fast.inbox.period_ms,
                fast.watch.first_command_ns) == (
            general.statistics.command_stamp_ns, general.inbox.period_ms,
            general.watch.first_command_ns), index
        assert fast_log.lines == general_log.lines, index
        sim.step()
        twin.step()
    assert len(fast_log.of('refused')) == 2 and len(fast_log.of('kept')) == 1
    assert any('synchronization window on' in line for line in fast_log.of('info'))


def _fields_bytes(command: object) -> bytes:
    return b''.join(np.asarray(getattr(command, name)).tobytes() for name in LAW_FIELDS)
