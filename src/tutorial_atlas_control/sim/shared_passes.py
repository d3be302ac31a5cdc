"""A behaviour's step with MuJoCo's passes shared: the physics step's own, read by the estimate.

mj_step computes the state's kinematics, centre of mass, its velocity and the bias forces
(mj_step1's position and velocity stages) before it integrates; the balance estimator used
to compute the same passes again on the same state in a scratch MjData of its own. Under a
behaviour the simulator now steps as mj_step1, the behaviour's torque, mj_step2: with the
model's implicitfast integrator the two halves are mj_step bit for bit (their one
requirement: what mj_step1 reads is set before it, the joints' damping from the velocity
gain included), and while the torque is computed the simulator's MjData holds those passes
at its present state, which `passes_current` tells the estimator (balance/estimator.py),
whose compiled estimate then copies them instead of running them.

What a behaviour reads of the MjData besides qpos and qvel (body poses, sites) is therefore
at the present state during its torque, where it was at the previous step's start; after the
step, MjData is as mj_step leaves it (poses at the step's start), so the messages built from
it mean what they meant. SHARED_PASSES_ENV set to `own` (or `python`, the Python references'
switch) keeps mj_step whole and the estimate's own passes: the equivalence test's "before".
"""

from __future__ import annotations

import os
import threading
from collections.abc import Callable

import mujoco
import numpy as np

from tutorial_atlas_control.command import JointCommandArrays
from tutorial_atlas_control.sim.behaviour import Behaviour
from tutorial_atlas_control.sim.joint_law import JointLaw

__all__ = ['SHARED_PASSES_ENV', 'behaviour_between', 'passes_current', 'shares_passes',
           'step_behaviour']

#: `own` or `python`: mj_step whole, the estimate's own passes; unset: shared.
SHARED_PASSES_ENV = 'TAC_SHARED_PASSES'

#: The MjData whose mj_step1 passes are at its present state, per thread (None: none).
_stepping = threading.local()


def shares_passes() -> bool:
    """Whether a simulator built now steps a behaviour on shared passes (SHARED_PASSES_ENV)."""
    return os.environ.get(SHARED_PASSES_ENV, '') not in ('own', 'python')


def passes_current(data: mujoco.MjData) -> bool:
    """Whether `data`'s position and velocity stages are those of its present qpos and qvel:
    within a behaviour's torque between the simulator's mj_step1 and mj_step2 only."""
    return getattr(_stepping, 'data', None) is data


def behaviour_between(law: JointLaw, behaviour: Behaviour, data: mujoco.MjData,
                      blended: JointCommandArrays | None) -> Callable[[], None]:
    """What runs between mj_step1 and mj_step2 for `behaviour`: its torque from `data` (its
    passes current meanwhile), applied by `law` with `blended`. The joints' damping, which
    mj_step1's passive forces read, is set here, before the step."""
    law.velocity_damping.apply(blended)

    def torque_between() -> None:
        law.apply_behaviour(_torque_of(behaviour, data), blended)

    return torque_between


def _torque_of(behaviour: Behaviour, data: mujoco.MjData) -> np.ndarray:
    """`behaviour`'s torque at `data`, its passes marked current while it reads them."""
    _stepping.data = data
    try:
        return behaviour.torque(data)
    finally:
        _stepping.data = None


def step_behaviour(model: mujoco.MjModel, data: mujoco.MjData, law: JointLaw,
                   behaviour: Behaviour) -> None:
    """One step under `behaviour` with nothing else acting (no command blended with it, no
    cheat's or mud's body forces): behaviour_between's step, mj_step1, the torque applied,
    mj_step2, in one call, without the closure and the three calls around it (every step of
    an offline walk)."""
    law.velocity_damping.apply(None)
    mujoco.mj_step1(model, data)
    law.apply_behaviour(_torque_of(behaviour, data), None)
    mujoco.mj_step2(model, data)
