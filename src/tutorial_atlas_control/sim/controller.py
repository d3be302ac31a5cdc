"""DRCSim 2.5.2 AtlasPlugin's joint controller law, vectorized over the 28 joints.

Per joint, each 1 ms step (AtlasPlugin::UpdateStates in DRCSim 2.5.2):

    q_target = clamp(position, lower, upper)
    e        = q_target - q
    de/dt    = (e - e_prev) / dt ;  e_prev = e
    I        = clamp(I + dt * ki_position * e, i_effort_min, i_effort_max)   # a torque (N m)
    u        = kp_position * e + I + kd_position * de/dt + kp_velocity * velocity + effort
    if k_effort != 1:                                  # AtlasCommand's k_effort / 255
        u    = k_effort * u + (1 - k_effort) * f_out
    tau      = clamp(u, -effort_limit, effort_limit)
    if |tau - u| > 1e-6 and |ki_position| > 1e-6:                         # tie-back
        I = clamp(I + (tau - u), i_effort_min, i_effort_max)
    applied torque = joint_states effort = tau

with Gazebo's clamp(x, lo, hi) = max(min(x, hi), lo) (so lo wins when lo > hi) and
Gazebo's math::equal tolerance (1e-6) deciding "saturated" and "ki is on". The integral
holds a torque, so a change of ki between commands keeps what was accumulated, and while
the torque saturates the integral is pulled back by the excess (anti-windup).

The velocity gain is DRCSim 2.7's, not 2.5.2's: 2.5.2 added kp_velocity * (velocity - v)
as an explicit torque, which on Atlas's light links (wrists, elbows, neck, feet) is past the
1 ms step's stability limit (gain * dt / inertia > 2) and shakes the robot; 2.7 passes
kp_velocity through to the joint's damping (clamped to [the model's damping, effort limit /
velocity limit * 50]), which the physics integrates implicitly, and keeps only
kp_velocity * velocity in the torque. Here the law gives that torque and
joint_law.JointLaw sets the damping (velocity_damping.py). With kp_velocity 0 (the
tutorial's commands, every hold) both laws are the same.

Where this differs from 2.5.2, on purpose:
* First step after a reset: e_prev := e, so the derivative term starts at 0.
  DRCSim started from e_prev = 0, which kicks the joints with kd * e / dt on
  the first step after a command arrives (e.g. 10 * 0.1 / 0.001 = 1000 N m on
  a knee, then clamped to the effort limit).
* f_out: 2.5.2 blended in the torque of BDI's AtlasSimInterface (its Stand, Walk, ...
  behaviours) by 1 - k_effort. There is no BDI library here: the simulator passes its own
  Stand/StandPrep/Freeze hold's torque where BDI's behaviour would act, and 0 in User and
  ragdoll, where BDI outputs nothing (mode_commands.py, joint_law.py). With k_effort = 1
  the term is skipped, so u is the PID sum exactly (2.5.2's 1 * u + 0 * f_out, up to the
  sign of a zero).

The torque clamp here is the only place the effort limits are enforced (the
MuJoCo motors have no ctrlrange).
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import yaml

from tutorial_atlas_control import topics
from tutorial_atlas_control.command import JointCommandArrays
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS
from tutorial_atlas_control.resources import package_path
from tutorial_atlas_control.units import finite_number
from tutorial_atlas_control.yaml_errors import yaml_problem

#: Where the gains live on the parameter server (and in config/atlas_controller.yaml).
GAINS_PARAM = topics.GAINS_PARAM
GAIN_KEYS: tuple[str, ...] = ('p', 'i', 'd', 'i_clamp')
#: DRCSim's gains as the package ships them (what atlas.launch loads by default).
DEFAULT_GAINS_FILE: Path = package_path('config', 'atlas_controller.yaml')
LOAD_HINT = ('load the gains with `roslaunch tutorial_atlas_control atlas.launch` '
             'or `rosparam load config/atlas_controller.yaml`')


class GainsError(AtlasControlError):
    """The controller gains are missing or malformed."""


def _zeros() -> np.ndarray:
    return np.zeros(NUM_JOINTS)


#: Gazebo's math::equal tolerance: AtlasPlugin ties the integral back only when the torque
#: was clipped by more than this (N m) and ki_position is further than this from 0.
TIE_BACK_EPSILON = 1e-6


@dataclass
class PidState:
    """Per-joint memory of the law: the integral term (a torque) and the previous error."""

    integral: np.ndarray = field(default_factory=_zeros)        # N m
    previous_error: np.ndarray = field(default_factory=_zeros)  # rad
    initialized: bool = False
    # Scratch buffers so that compute_torque allocates nothing per step while every ki is 0.
    _error: np.ndarray = field(default_factory=_zeros, repr=False)
    _term: np.ndarray = field(default_factory=_zeros, repr=False)
    _unclamped: np.ndarray = field(default_factory=_zeros, repr=False)

    def reset(self) -> None:
        """Forget the integral and the previous error (e.g. after a simulation reset)."""
        self.integral.fill(0.0)
        self.previous_error.fill(0.0)
        self.initialized = False


def _clamp(value: np.ndarray, low: np.ndarray, high: np.ndarray, out: np.ndarray) -> np.ndarray:
    """Gazebo's math::clamp, elementwise: max(min(value, high), low)."""
    np.minimum(value, high, out=out)
    return np.maximum(out, low, out=out)


def compute_torque(command: JointCommandArrays, q: np.ndarray, v: np.ndarray, state: PidState,
                   dt_s: float, lower: np.ndarray, upper: np.ndarray, effort_limit: np.ndarray,
                   out: np.ndarray | None = None,
                   f_out: np.ndarray | None = None) -> np.ndarray:
    """Joint torques (N m, (28,)) for one control step; updates `state` in place.

    The operations run in the order of the scalar law in the module docstring, so each
    joint's result is bit for bit what a per-joint loop of it gives.

    Args:
        command: targets and gains, tutorial joint order.
        q: joint positions (rad); v: joint velocities (rad/s).
        state: the law's memory, advanced by this call.
        dt_s: step length (s), > 0.
        lower, upper: position limits (rad) the target is clamped to.
        effort_limit: |torque| bound (N m), >= 0.
        out: optional (28,) buffer for the result.
        f_out: the behaviour's torque (N m, (28,)) blended in by 1 - k_effort; None: 0.
    """
    error, term, unclamped = state._error, state._term, state._unclamped
    torque = np.empty(NUM_JOINTS) if out is None else out
    integral = state.integral
    ki = command.ki_position

    _clamp(command.position, lower, upper, out=error)
    error -= q
    if not state.initialized:
        state.previous_error[:] = error
        state.initialized = True

    # integral: a torque, accumulating dt * ki * e within [i_effort_min, i_effort_max]
    np.multiply(ki, dt_s, out=term)
    term *= error
    integral += term
    _clamp(integral, command.i_effort_min, command.i_effort_max, out=integral)

    # u = kp * e + I + kd * de/dt + kp_velocity * velocity + effort, summed in that order (the
    # velocity gain's damping, - kp_velocity * v, is the joint's: velocity_damping.py)
    np.multiply(command.kp_position, error, out=unclamped)
    unclamped += integral
    np.subtract(error, state.previous_error, out=term)
    term /= dt_s
    term *= command.kd_position
    unclamped += term
    state.previous_error[:] = error
    np.multiply(command.velocity, command.kp_velocity, out=term)
    unclamped += term
    unclamped += command.effort
    k_effort = command.k_effort
    if (k_effort != 1.0).any():
        _blend(k_effort, f_out, unclamped, term)

    np.negative(effort_limit, out=term)
    _clamp(unclamped, term, effort_limit, out=torque)

    # with every ki 0 (the tutorial's gains) there is nothing to tie back
    if ki.any():
        _tie_back(command, torque, unclamped, integral, term)
    return torque


#: f_out where the behaviour outputs nothing (N m).
_NO_TORQUE = np.zeros(NUM_JOINTS)
_NO_TORQUE.setflags(write=False)


def _blend(k_effort: np.ndarray, f_out: np.ndarray | None, unclamped: np.ndarray,
           scratch: np.ndarray) -> None:
    """u = k * u + (1 - k) * f_out on the joints whose k_effort is not 1 (2.5.2's order)."""
    blended = k_effort * unclamped
    np.subtract(1.0, k_effort, out=scratch)
    scratch *= _NO_TORQUE if f_out is None else f_out
    blended += scratch
    np.copyto(unclamped, blended, where=k_effort != 1.0)


def _tie_back(command: JointCommandArrays, torque: np.ndarray, unclamped: np.ndarray,
              integral: np.ndarray, scratch: np.ndarray) -> None:
    """While saturated, pull the integral back by the torque the clamp cut off (2.5.2's
    anti-windup), on joints whose ki and cut both exceed Gazebo's equality tolerance."""
    np.subtract(torque, unclamped, out=scratch)
    tie_back = np.abs(scratch) > TIE_BACK_EPSILON
    tie_back &= np.abs(command.ki_position) > TIE_BACK_EPSILON
    if tie_back.any():
        scratch += integral
        _clamp(scratch, command.i_effort_min, command.i_effort_max, out=scratch)
        np.copyto(integral, scratch, where=tie_back)


@dataclass(frozen=True)
class Gains:
    """atlas_controller/gains as (28,) arrays in the tutorial's joint order."""

    p: np.ndarray        # N m/rad
    i: np.ndarray        # N m/(rad s)
    d: np.ndarray        # N m s/rad
    i_clamp: np.ndarray  # N m


def _gain_value(params: Mapping[str, Any], joint: str, key: str, source: Path | None) -> float:
    name = f'{GAINS_PARAM}/{joint}/{key}'
    entry = params.get(joint) if isinstance(params, Mapping) else None
    if not isinstance(entry, Mapping) or key not in entry:
        if source is not None:
            raise GainsError(f'{source}: {name} is missing')
        raise GainsError(f'parameter {name} is missing; {LOAD_HINT}')
    value = finite_number(entry[key])
    if value is None:
        if source is not None:
            raise GainsError(f'{source}: {name} is {entry[key]!r}, not a finite number')
        raise GainsError(f'parameter {name} is {entry[key]!r}, not a finite number; '
                         'fix it in config/atlas_controller.yaml and reload it')
    return value


def gains_from_params(params: Mapping[str, Any], source: Path | None = None) -> Gains:
    """Gains from the dict under `atlas_controller/gains` ({joint: {p, i, d, i_clamp}}).

    `source` is the YAML file the dict was read from (None: the parameter server); the
    messages name it instead of telling how to load the parameters.

    Raises:
        GainsError: a joint or key is missing, or a value is not a finite number;
            the message names the parameter.
    """
    if not isinstance(params, Mapping):
        if source is not None:
            raise GainsError(f'{source}: {GAINS_PARAM} is {params!r}, not a dictionary')
        raise GainsError(f'parameter {GAINS_PARAM} is {params!r}, not a dictionary; {LOAD_HINT}')
    table = np.array([[_gain_value(params, joint, key, source) for key in GAIN_KEYS]
                      for joint in JOINT_NAMES])
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
    path = Path(path)
    try:
        document = yaml.safe_load(path.read_text())
    except OSError as err:
        raise GainsError(f'Could not read gains from {path}: {err.strerror or err}') from err
    except yaml.YAMLError as err:
        raise GainsError(f'Could not read gains from {path}: {yaml_problem(err)}') from err
    node: Any = document
    for key in GAINS_PARAM.split('/'):
        if not isinstance(node, Mapping) or key not in node:
            raise GainsError(f'{path} has no {GAINS_PARAM} section; '
                             'see config/atlas_controller.yaml for the layout')
        node = node[key]
    return gains_from_params(node, path)
