"""DRCSim AtlasPlugin's joint controller law, vectorized over the 28 joints.

Per joint, each 1 ms step (DRCSim 2.x AtlasPlugin::UpdateStates):

    q_target = clamp(position, lower, upper)
    e        = q_target - q
    de/dt    = (e - e_prev) / dt
    i        = clamp(i + dt * e, i_effort_min / ki, i_effort_max / ki)
    torque   = kp_position * e + ki_position * i + kd_position * de/dt
               + kp_velocity * (velocity - v) + effort
    torque   = clamp(torque, -effort_limit, +effort_limit)

Two choices differ from DRCSim, on purpose:
* First step after a reset: e_prev := e, so the derivative term starts at 0.
  DRCSim started from e_prev = 0, which kicks the joints with kd * e / dt on
  the first step after a command arrives (e.g. 10 * 0.1 / 0.001 = 1000 N m on
  a knee, then clamped to the effort limit).
* ki == 0: the integral is held at 0 (DRCSim divided by ki, giving NaN or
  inf bounds). Nothing winds up while the integral gain is off, so turning
  it on later starts from a clean integral.

The torque clamp here is the only place the effort limits are enforced (the
MuJoCo motors have no ctrlrange).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from tutorial_atlas_control import topics
from tutorial_atlas_control.commands import JointCommandArrays
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.units import finite_number

#: Where the gains live on the parameter server (and in config/atlas_controller.yaml).
GAINS_PARAM = topics.GAINS_PARAM
GAIN_KEYS: tuple[str, ...] = ('p', 'i', 'd', 'i_clamp')
LOAD_HINT = ('load the gains with `roslaunch tutorial_atlas_control atlas.launch` '
             'or `rosparam load config/atlas_controller.yaml`')


class GainsError(AtlasControlError):
    """The controller gains are missing or malformed."""


def _zeros() -> np.ndarray:
    return np.zeros(NUM_JOINTS)


@dataclass
class PidState:
    """Per-joint memory of the law: integral of the error and the previous error."""

    integral: np.ndarray = field(default_factory=_zeros)        # rad s
    previous_error: np.ndarray = field(default_factory=_zeros)  # rad
    initialized: bool = False
    # Scratch buffers so that compute_torque allocates nothing per step.
    _error: np.ndarray = field(default_factory=_zeros, repr=False)
    _term: np.ndarray = field(default_factory=_zeros, repr=False)
    _low: np.ndarray = field(default_factory=_zeros, repr=False)
    _high: np.ndarray = field(default_factory=_zeros, repr=False)

    def reset(self) -> None:
        """Forget the integral and the previous error (e.g. after a simulation reset)."""
        self.integral.fill(0.0)
        self.previous_error.fill(0.0)
        self.initialized = False


def compute_torque(command: JointCommandArrays, q: np.ndarray, v: np.ndarray, state: PidState,
                   dt_s: float, lower: np.ndarray, upper: np.ndarray, effort_limit: np.ndarray,
                   out: np.ndarray | None = None) -> np.ndarray:
    """Joint torques (N m, (28,)) for one control step; updates `state` in place.

    Args:
        command: targets and gains, tutorial joint order.
        q: joint positions (rad); v: joint velocities (rad/s).
        state: the law's memory, advanced by this call.
        dt_s: step length (s), > 0.
        lower, upper: position limits (rad) the target is clamped to.
        effort_limit: |torque| bound (N m).
        out: optional (28,) buffer for the result.
    """
    error, term, low, high = state._error, state._term, state._low, state._high
    torque = np.empty(NUM_JOINTS) if out is None else out

    # target clamped to the joint limits (minimum/maximum: cheaper than clip)
    np.minimum(command.position, upper, out=error)
    np.maximum(error, lower, out=error)
    error -= q
    if not state.initialized:
        state.previous_error[:] = error
        state.initialized = True

    # proportional + derivative of the error
    np.multiply(command.kp_position, error, out=torque)
    np.subtract(error, state.previous_error, out=term)
    term *= command.kd_position
    term *= 1.0 / dt_s
    torque += term
    state.previous_error[:] = error

    # integral, clamped so that ki * integral stays in [i_effort_min, i_effort_max]
    ki = command.ki_position
    integral = state.integral
    if ki.any():
        error *= dt_s
        integral += error
        integral_on = ki != 0.0
        np.divide(command.i_effort_min, ki, out=low, where=integral_on)
        np.divide(command.i_effort_max, ki, out=high, where=integral_on)
        np.minimum(low, high, out=term)   # a negative ki swaps the bounds
        np.maximum(low, high, out=high)
        np.maximum(integral, term, out=integral)
        np.minimum(integral, high, out=integral)
        np.copyto(integral, 0.0, where=~integral_on)
        np.multiply(ki, integral, out=term)
        torque += term
    else:
        integral.fill(0.0)

    # velocity feedback and feed-forward effort
    np.subtract(command.velocity, v, out=term)
    term *= command.kp_velocity
    torque += term
    torque += command.effort

    np.negative(effort_limit, out=term)
    np.maximum(torque, term, out=torque)
    np.minimum(torque, effort_limit, out=torque)
    return torque


@dataclass(frozen=True)
class Gains:
    """atlas_controller/gains as (28,) arrays in the tutorial's joint order."""

    p: np.ndarray        # N m/rad
    i: np.ndarray        # N m/(rad s)
    d: np.ndarray        # N m s/rad
    i_clamp: np.ndarray  # N m


def _gain_value(params: Mapping[str, Any], joint: str, key: str) -> float:
    name = f'{GAINS_PARAM}/{joint}/{key}'
    entry = params.get(joint) if isinstance(params, Mapping) else None
    if not isinstance(entry, Mapping) or key not in entry:
        raise GainsError(f'parameter {name} is missing; {LOAD_HINT}')
    value = finite_number(entry[key])
    if value is None:
        raise GainsError(f'parameter {name} is {entry[key]!r}, not a finite number; '
                         'fix it in config/atlas_controller.yaml and reload it')
    return value


def gains_from_params(params: Mapping[str, Any]) -> Gains:
    """Gains from the dict under `atlas_controller/gains` ({joint: {p, i, d, i_clamp}}).

    Raises:
        GainsError: a joint or key is missing, or a value is not a finite number;
            the message names the parameter.
    """
    if not isinstance(params, Mapping):
        raise GainsError(f'parameter {GAINS_PARAM} is {params!r}, not a dictionary; {LOAD_HINT}')
    table = np.array([[_gain_value(params, joint, key) for key in GAIN_KEYS] for joint in JOINT_NAMES])
    return Gains(*(np.ascontiguousarray(table[:, column]) for column in range(len(GAIN_KEYS))))


def hold_command(gains: Gains, position: np.ndarray) -> JointCommandArrays:
    """Command that holds `position` (rad) with the parameter gains.

    What the Stand/Freeze modes apply: kp = p, ki = i, kd = d, no velocity
    feedback, integral torque within +-i_clamp, no feed-forward effort.
    """
    command = JointCommandArrays.zeros()
    command.position[:] = position
    command.kp_position[:] = gains.p
    command.ki_position[:] = gains.i
    command.kd_position[:] = gains.d
    command.i_effort_min[:] = -gains.i_clamp
    command.i_effort_max[:] = gains.i_clamp
    return command


def load_gains_yaml(path: str | Path) -> Gains:
    """Gains from a YAML file laid out like config/atlas_controller.yaml.

    Raises:
        GainsError: the file is missing or unreadable, or the gains are malformed.
    """
    import yaml  # local: only the file path needs PyYAML

    path = Path(path)
    try:
        document = yaml.safe_load(path.read_text())
    except (OSError, yaml.YAMLError) as err:
        raise GainsError(f'Could not read gains from {path}: {err}') from err
    node: Any = document
    for key in GAINS_PARAM.split('/'):
        if not isinstance(node, Mapping) or key not in node:
            raise GainsError(f'{path} has no {GAINS_PARAM} section; '
                             'see config/atlas_controller.yaml for the layout')
        node = node[key]
    return gains_from_params(node)
