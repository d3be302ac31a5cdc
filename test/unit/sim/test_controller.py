"""The DRCSim joint controller law, gains loading and hold commands."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra import numpy as hnp

from tutorial_atlas_control.command.arrays import FIELD_NAMES, JointCommandArrays
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_INDEX, JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.sim.controller import (
    Gains,
    GainsError,
    PidState,
    compute_torque,
    gains_from_params,
    hold_command,
    load_gains_yaml,
)

REPO = Path(__file__).resolve().parents[3]
GAINS_YAML = REPO / 'config' / 'atlas_controller.yaml'
DT_S = 0.001
LOWER = np.full(NUM_JOINTS, -1.0)
UPPER = np.full(NUM_JOINTS, 1.0)
LIMIT = np.full(NUM_JOINTS, 100.0)

#: DRCSim v1 gains (p, d) as typed from whole_body_trajectory_controller.yaml; i = i_clamp = 0.
DRCSIM_PD = {
    'back_lbz': (20, 0.1), 'back_mby': (4000, 2), 'back_ubx': (2000, 1), 'neck_ay': (20, 1),
    'leg_uhz': (5, 0.01), 'leg_mhx': (100, 1), 'leg_lhy': (2000, 10), 'leg_kny': (1000, 10),
    'leg_uay': (900, 2), 'leg_lax': (300, 1),
    'arm_usy': (2000, 3), 'arm_shx': (1000, 20), 'arm_ely': (200, 3), 'arm_elx': (200, 3),
    'arm_uwy': (50, 0.1), 'arm_mwx': (100, 0.2),
}


def one_joint(**values: float) -> JointCommandArrays:
    """A command with the given field values on every joint."""
    command = JointCommandArrays.zeros()
    for name, value in values.items():
        getattr(command, name)[:] = value
    return command


def torque(command: JointCommandArrays, q: float, v: float = 0.0,
           state: PidState | None = None) -> float:
    state = PidState() if state is None else state
    result = compute_torque(command, np.full(NUM_JOINTS, q), np.full(NUM_JOINTS, v), state, DT_S,
                            LOWER, UPPER, LIMIT)
    assert np.all(result == result[0])
    return float(result[0])


# --- the message-shaped arrays ------------------------------------------------------------------

def test_field_names_follow_the_message() -> None:
    lines = (REPO / 'msg' / 'osrf_msgs' / 'msg' / 'JointCommands.msg').read_text().splitlines()
    arrays = [line.split()[1] for line in lines if line.startswith('float64[]')]
    assert tuple(arrays) == FIELD_NAMES


def test_zeros_and_copy_are_independent() -> None:
    command = JointCommandArrays.zeros()
    for name in FIELD_NAMES:
        value = getattr(command, name)
        assert value.shape == (NUM_JOINTS,) and value.dtype == np.float64 and not value.any()
    copy = command.copy()
    copy.position[0] = 1.0
    assert command.position[0] == 0.0
    assert JointCommandArrays.zeros().position is not JointCommandArrays.zeros().position


# --- each term of the law ---------------------------------------------------------------------

def test_proportional_term() -> None:
    assert torque(one_joint(position=0.5, kp_position=10.0), q=0.2) == pytest.approx(10.0 * 0.3)


def test_derivative_is_of_the_error_and_has_no_first_step_kick() -> None:
    command = one_joint(position=0.5, kd_position=2.0)
    state = PidState()
    assert torque(command, q=0.2, state=state) == 0.0  # e_prev := e on the first step
    # error goes 0.3 -> 0.25 in 1 ms: de/dt = -50 rad/s
    assert torque(command, q=0.25, state=state) == pytest.approx(2.0 * -50.0)
    state.reset()
    assert not state.initialized
    assert torque(command, q=0.9, state=state) == 0.0


def test_velocity_term_and_feed_forward() -> None:
    """DRCSim 2.7's velocity gain: the torque holds kp_velocity * velocity, whatever the
    joint's velocity (its - kp_velocity * v is the joint's damping, velocity_damping.py)."""
    command = one_joint(velocity=1.5, kp_velocity=4.0, effort=-7.0)
    assert torque(command, q=0.0, v=0.5) == pytest.approx(4.0 * 1.5 - 7.0)
    assert torque(command, q=0.0, v=-3.0) == pytest.approx(4.0 * 1.5 - 7.0)


def test_integral_accumulates_dt_times_ki_times_error_as_a_torque() -> None:
    command = one_joint(position=0.5, ki_position=100.0, i_effort_min=-50.0, i_effort_max=50.0)
    state = PidState()
    expected = [DT_S * 100.0 * 0.5 * k for k in (1, 2, 3)]
    assert [torque(command, q=0.0, state=state) for _ in range(3)] == pytest.approx(expected)
    np.testing.assert_allclose(state.integral, 3 * DT_S * 100.0 * 0.5)  # N m


def test_a_change_of_ki_keeps_the_accumulated_torque() -> None:
    command = one_joint(position=0.5, ki_position=100.0, i_effort_min=-50.0, i_effort_max=50.0)
    state = PidState()
    for _ in range(10):
        torque(command, q=0.0, state=state)
    command.ki_position[:] = 400.0  # the old law (ki * integral of e) jumped 4x here
    assert torque(command, q=0.0, state=state) == pytest.approx(10 * DT_S * 100.0 * 0.5
                                                                + DT_S * 400.0 * 0.5)
    command.ki_position[:] = 0.0  # ki off: the integral holds its torque
    held = torque(command, q=0.0, state=state)
    assert held == pytest.approx(10 * DT_S * 100.0 * 0.5 + DT_S * 400.0 * 0.5)
    assert torque(command, q=0.3, state=state) == held


def test_integral_is_clamped_to_the_effort_bounds() -> None:
    command = one_joint(position=1.0, ki_position=200.0, i_effort_min=-0.3, i_effort_max=0.5)
    state = PidState()
    for _ in range(50):  # unclamped: 200 * 50 * 1e-3 = 10 N m
        last = torque(command, q=0.0, state=state)
    assert last == pytest.approx(0.5)
    np.testing.assert_allclose(state.integral, 0.5)
    command.position[:] = -1.0
    for _ in range(100):
        last = torque(command, q=0.0, state=state)
    assert last == pytest.approx(-0.3)


def test_negative_ki_drives_the_integral_down() -> None:
    command = one_joint(position=1.0, ki_position=-100.0, i_effort_min=-0.2, i_effort_max=0.4)
    state = PidState()
    for _ in range(100):
        last = torque(command, q=0.0, state=state)
    # ki < 0, e > 0: the integral torque falls to its lower bound
    assert last == pytest.approx(-0.2)


def test_inverted_integral_bounds_clamp_as_gazebo_did() -> None:
    # Gazebo's clamp(x, lo, hi) = max(min(x, hi), lo): with lo > hi the integral sits at lo.
    command = one_joint(position=1.0, ki_position=100.0, i_effort_min=0.7, i_effort_max=-0.2)
    state = PidState()
    assert torque(command, q=0.0, state=state) == 0.7
    command.position[:] = -1.0
    assert torque(command, q=0.0, state=state) == 0.7


def test_tie_back_pulls_the_integral_back_under_saturation() -> None:
    # kp e = 150 N m against a 100 N m limit: the 50 N m cut off comes out of the integral.
    command = one_joint(position=1.0, kp_position=150.0, ki_position=1000.0,
                        i_effort_min=-80.0, i_effort_max=80.0)
    state = PidState()
    assert torque(command, q=0.0, state=state) == LIMIT[0]
    # I = 1000 * 1e-3 * 1 = 1; u = 151; tie-back: I = 1 + (100 - 151) = -50
    assert state.integral[0] == pytest.approx(-50.0)
    assert torque(command, q=0.0, state=state) == LIMIT[0]
    assert state.integral[0] == pytest.approx(-50.0)  # (-50 + 1) + 150 = 101 -> -49 - 1
    command.ki_position[:] = 0.0  # no integral gain: no tie-back, the integral is left alone
    torque(command, q=0.0, state=state)
    assert state.integral[0] == pytest.approx(-50.0)


def test_zero_ki_adds_nothing_to_a_zero_integral() -> None:
    command = one_joint(position=1.0, ki_position=0.0, i_effort_min=-5.0, i_effort_max=5.0)
    state = PidState()
    for _ in range(10):
        assert torque(command, q=0.0, state=state) == 0.0
    assert not state.integral.any()
    command.ki_position[3] = 1000.0  # integral on for one joint only
    command.i_effort_min[:] = command.i_effort_max[:] = 0.0
    command.i_effort_max[3] = 100.0
    result = compute_torque(command, np.zeros(NUM_JOINTS), np.zeros(NUM_JOINTS), state, DT_S,
                            LOWER, UPPER, LIMIT)
    assert result[3] == pytest.approx(DT_S * 1000.0 * 1.0)
    assert np.count_nonzero(result) == 1


def test_target_is_clamped_to_the_joint_limits() -> None:
    assert torque(one_joint(position=3.0, kp_position=10.0), q=0.0) == \
        pytest.approx(10.0 * UPPER[0])
    assert torque(one_joint(position=-3.0, kp_position=10.0), q=0.0) == \
        pytest.approx(10.0 * LOWER[0])


def test_torque_is_clamped_to_the_effort_limit() -> None:
    assert torque(one_joint(position=1.0, kp_position=1e4), q=0.0) == LIMIT[0]
    assert torque(one_joint(effort=-1e3), q=0.0) == -LIMIT[0]


def gazebo_clamp(value: float, low: float, high: float) -> float:
    """Gazebo's math::clamp: max(min(value, high), low)."""
    return max(min(value, high), low)


class ScalarJoint:
    """One joint of DRCSim 2.5.2's law, transcribed line by line with Python floats."""

    def __init__(self) -> None:
        self.reset()

    def reset(self) -> None:
        self.integral = 0.0
        self.previous_error = 0.0
        self.initialized = False
        self.tied_back = False

    def step(self, c: dict[str, float], q: float, v: float, dt: float, lower: float, upper: float,
             limit: float) -> float:
        e = gazebo_clamp(c['position'], lower, upper) - q
        if not self.initialized:  # the project's deviation: no derivative kick after a reset
            self.previous_error, self.initialized = e, True
        de = (e - self.previous_error) / dt
        self.previous_error = e
        self.integral = gazebo_clamp(self.integral + dt * c['ki_position'] * e,
                                     c['i_effort_min'], c['i_effort_max'])
        u = (c['kp_position'] * e + self.integral + c['kd_position'] * de
             + c['kp_velocity'] * c['velocity'] + c['effort'])
        tau = gazebo_clamp(u, -limit, limit)
        self.tied_back = math.fabs(tau - u) > 1e-6 and math.fabs(c['ki_position']) > 1e-6
        if self.tied_back:  # !math::equal(tau, u) && !math::equal(ki, 0)
            self.integral = gazebo_clamp(self.integral + (tau - u),
                                         c['i_effort_min'], c['i_effort_max'])
        return tau


def random_command(rng: np.random.Generator) -> JointCommandArrays:
    """Targets and gains that saturate often, with negative and tiny ki and inverted bounds."""
    command = JointCommandArrays(
        position=rng.uniform(-2.0, 2.0, NUM_JOINTS),
        velocity=rng.uniform(-3.0, 3.0, NUM_JOINTS),
        effort=rng.uniform(-60.0, 60.0, NUM_JOINTS),
        kp_position=(rng.choice([0.0, 10.0, 300.0, 4000.0], NUM_JOINTS)
                     * rng.uniform(0, 1, NUM_JOINTS)),
        ki_position=rng.choice([0.0, 1e-7, -5e-7, 50.0, -50.0, 3000.0, -3000.0], NUM_JOINTS)
        * rng.uniform(0.5, 1.5, NUM_JOINTS),
        kd_position=rng.uniform(0.0, 20.0, NUM_JOINTS),
        kp_velocity=rng.uniform(-5.0, 20.0, NUM_JOINTS),
        i_effort_min=rng.uniform(-80.0, 20.0, NUM_JOINTS),
        i_effort_max=rng.uniform(-20.0, 80.0, NUM_JOINTS),
    )
    return command


def test_vectorized_law_equals_the_scalar_transcription() -> None:
    """200 runs of 60 steps: ki changes and flips sign, bounds inverted, torques saturated."""
    rng = np.random.default_rng(2025)
    largest = 0.0
    counts = {'tie_backs': 0, 'inverted_bounds': 0, 'negative_ki': 0}
    for _run in range(200):
        lower = rng.uniform(-2.5, 0.0, NUM_JOINTS)
        upper = lower + rng.uniform(0.0, 3.0, NUM_JOINTS)
        limit = rng.uniform(0.0, 200.0, NUM_JOINTS)
        state, joints = PidState(), [ScalarJoint() for _ in range(NUM_JOINTS)]
        command = random_command(rng)
        q = rng.uniform(-2.0, 2.0, NUM_JOINTS)
        v = rng.uniform(-5.0, 5.0, NUM_JOINTS)
        for step in range(60):
            if rng.random() < 0.2:  # a new command: ki and bounds change between steps
                command = random_command(rng)
            if step == 30 and rng.random() < 0.5:  # a reset mid-run
                state.reset()
                for joint in joints:
                    joint.reset()
            q = q + rng.normal(0.0, 0.05, NUM_JOINTS)
            v = v + rng.normal(0.0, 0.5, NUM_JOINTS)
            result = compute_torque(command, q, v, state, DT_S, lower, upper, limit)
            fields = {name: getattr(command, name) for name in FIELD_NAMES}
            for j, joint in enumerate(joints):
                expected = joint.step({name: float(values[j]) for name, values in fields.items()},
                                      float(q[j]), float(v[j]), DT_S, float(lower[j]),
                                      float(upper[j]), float(limit[j]))
                largest = max(largest, abs(result[j] - expected),
                              abs(state.integral[j] - joint.integral))
            counts['tie_backs'] += sum(joint.tied_back for joint in joints)
            counts['inverted_bounds'] += int(
                np.count_nonzero(command.i_effort_min > command.i_effort_max))
            counts['negative_ki'] += int(np.count_nonzero(command.ki_position < -1e-6))
    assert largest == 0.0
    assert min(counts.values()) > 1000, counts  # every case the law distinguishes was exercised


@settings(max_examples=200, deadline=None)
@given(hnp.arrays(np.float64, NUM_JOINTS, elements=st.floats(-1e6, 1e6)),
       hnp.arrays(np.float64, NUM_JOINTS, elements=st.floats(-10, 10)),
       hnp.arrays(np.float64, NUM_JOINTS, elements=st.floats(-100, 100)))
def test_torque_never_exceeds_the_effort_limit(gain: np.ndarray, q: np.ndarray,
                                               v: np.ndarray) -> None:
    command = JointCommandArrays(**{name: gain.copy() for name in FIELD_NAMES})
    state = PidState()
    for _ in range(2):
        result = compute_torque(command, q, v, state, DT_S, LOWER, UPPER, LIMIT)
        assert np.all(np.abs(result) <= LIMIT)


# --- gains ------------------------------------------------------------------------------------

def drcsim_params() -> dict:
    params = {}
    for joint in JOINT_NAMES:
        key = joint if joint.startswith(('back', 'neck')) else joint[2:]
        p, d = DRCSIM_PD[key]
        params[joint] = {'p': p, 'i': 0.0, 'd': d, 'i_clamp': 0.0}
    return params


def test_config_has_the_drcsim_gains() -> None:
    gains = load_gains_yaml(GAINS_YAML)
    expected = gains_from_params(drcsim_params())
    for key in ('p', 'i', 'd', 'i_clamp'):
        np.testing.assert_array_equal(getattr(gains, key), getattr(expected, key))
    assert gains.p[JOINT_INDEX['l_leg_kny']] == 1000.0
    assert gains.d[JOINT_INDEX['back_lbz']] == 0.1


def test_gains_from_params_names_the_missing_parameter() -> None:
    params = drcsim_params()
    del params['l_leg_kny']['p']
    with pytest.raises(GainsError, match=r'^parameter atlas_controller/gains/l_leg_kny/p '
                                         r'is missing; '
                                         r'load the gains with `roslaunch tutorial_atlas_control '
                                         r'atlas.launch` or '
                                         r'`rosparam load config/atlas_controller.yaml`$'):
        gains_from_params(params)
    params = drcsim_params()
    del params['r_arm_mwx']
    with pytest.raises(GainsError, match='atlas_controller/gains/r_arm_mwx/p is missing'):
        gains_from_params(params)
    assert issubclass(GainsError, AtlasControlError)


@pytest.mark.parametrize('bad', ['high', None, math.nan, math.inf, True, [1.0]])
def test_gains_from_params_rejects_non_numbers(bad: object) -> None:
    params = drcsim_params()
    params['neck_ay']['d'] = bad
    with pytest.raises(GainsError,
                       match='atlas_controller/gains/neck_ay/d is .*not a finite number'):
        gains_from_params(params)


def test_gains_from_params_rejects_a_non_dict() -> None:
    with pytest.raises(GainsError, match='atlas_controller/gains is .*not a dictionary'):
        gains_from_params(['p'])


def test_load_gains_yaml_errors(tmp_path: Path) -> None:
    with pytest.raises(GainsError, match='Could not read gains'):
        load_gains_yaml(tmp_path / 'missing.yaml')
    wrong = tmp_path / 'wrong.yaml'
    wrong.write_text('atlas_controller: {joints: []}\n')
    with pytest.raises(GainsError, match='no atlas_controller/gains section'):
        load_gains_yaml(wrong)


def test_hold_command_is_what_stand_and_freeze_apply() -> None:
    rng = np.random.default_rng(3)
    gains = Gains(*(rng.uniform(0, 10, NUM_JOINTS) for _ in range(4)))
    position = rng.uniform(-1, 1, NUM_JOINTS)
    command = hold_command(gains, position)
    np.testing.assert_array_equal(command.position, position)
    assert command.position is not position
    np.testing.assert_array_equal(command.kp_position, gains.p)
    np.testing.assert_array_equal(command.ki_position, gains.i)
    np.testing.assert_array_equal(command.kd_position, gains.d)
    np.testing.assert_array_equal(command.i_effort_min, -gains.i_clamp)
    np.testing.assert_array_equal(command.i_effort_max, gains.i_clamp)
    for name in ('velocity', 'effort', 'kp_velocity'):
        assert not getattr(command, name).any()

