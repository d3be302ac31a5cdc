"""The stances Walk, Step or a stopped walk leave the feet in, made offline through the
AtlasSimInterface as a client would make them, and how far each foot then turns and slides
while the balancing Stand holds the robot (the feet's sole boxes, as the balance sees them).

Steps are the foot links' poses, as a WALK or STEP carries them (x, y, yaw in pos_est's frame,
which starts where the robot starts).
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from tutorial_atlas_control.asi import AtlasSimInterface, Behavior
from tutorial_atlas_control.balance import place_in_stand_pose
from tutorial_atlas_control.balance.stand import yaw_of
from tutorial_atlas_control.msgs.atlas_sim_interface import AsiCommand, ManipulateParams, StepData
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasModel,
    AtlasSimulator,
    ControlMode,
    load_gains_yaml,
)
from tutorial_atlas_control.walking import Footstep, straight_steps

#: Stand before the behaviour that makes the stance (s); at most this long for it (s).
STAND_FIRST_S = 1.0
LONGEST_S = 15.0


def _step_data(step: Footstep) -> StepData:
    half = 0.5 * step.yaw_rad
    return StepData(step.step_index, step.foot_index, step.duration_s, (step.x_m, step.y_m, 0.0),
                    (0.0, 0.0, math.sin(half), math.cos(half)), 0.2)


def _command(behavior: Behavior, steps: tuple[Footstep, ...] = (),
             desired: Footstep | None = None) -> AsiCommand:
    queue = tuple(_step_data(step) for step in steps) + (StepData(),) * (4 - len(steps))
    return AsiCommand(0, behavior, queue, False,
                      StepData() if desired is None else _step_data(desired), False,
                      ManipulateParams(), None, 0)


def _until(interface: AtlasSimInterface, done: Callable[[], bool],
           each: Callable[[], None] = lambda: None) -> None:
    sim = interface.sim
    for _ in range(round(LONGEST_S / sim.dt_s)):
        if done():
            return
        each()
        sim.step()
        interface.end_step()
    raise AssertionError('the stance was not reached in time')


def _in_stand(interface: AtlasSimInterface) -> Callable[[], bool]:
    return lambda: interface.sim.mode is ControlMode.STAND


def _side_by_side(interface: AtlasSimInterface) -> None:
    """Four steps of 0.2 m: the last brings the feet side by side."""
    interface.apply(_command(Behavior.WALK, tuple(straight_steps(4, 0.2))))
    _until(interface, _in_stand(interface))


def _control_mode_walk(interface: AtlasSimInterface) -> None:
    """/atlas/control_mode Walk: DRCSim's queue leaves the left foot 0.2 m behind."""
    interface.sim.set_mode(ControlMode.WALK)
    _until(interface, _in_stand(interface))


def _walk_stopped_early(interface: AtlasSimInterface) -> None:
    """Eight steps of 0.25 m, STAND asked for during the third (as DRCSim's actionlib
    server asks as a goal's last step begins): the right foot 0.25 m behind."""
    walking = interface.walking
    assert walking is not None
    interface.apply(_command(Behavior.WALK, tuple(straight_steps(8, 0.25)[:4])))
    _until(interface, lambda: walking.walk is not None
           and walking.walk.queue.current_step_index == 2)
    interface.apply(_command(Behavior.STAND))
    _until(interface, _in_stand(interface))


def _far_step_clamped(interface: AtlasSimInterface) -> None:
    """A WALK whose second step is 0.8 m ahead of the first: clamped to 0.4 m, the
    right foot 0.4 m behind."""
    interface.apply(_command(Behavior.WALK, (Footstep(1, 1, 0.1, -0.12, 0.0),
                                             Footstep(2, 0, 0.9, 0.12, 0.0))))
    _until(interface, _in_stand(interface))


def _turned_by_a_step(interface: AtlasSimInterface) -> None:
    """One STEP of the left foot turned 0.3 rad out, then STAND."""
    stepping = interface.stepping
    assert stepping is not None
    turn = Footstep(1, 0, 0.0, 0.14, 0.3)
    _until(interface, lambda: stepping.steps_taken == 1 and stepping.static_step is None,
           lambda: interface.apply(_command(Behavior.STEP, desired=turn)))
    interface.apply(_command(Behavior.STAND))
    _until(interface, _in_stand(interface))


#: The stances, by name: how each is made from standing in the Stand pose.
STANCES: dict[str, Callable[[AtlasSimInterface], None]] = {
    'side by side': _side_by_side,
    'control_mode Walk': _control_mode_walk,
    'walk stopped early': _walk_stopped_early,
    'far step clamped': _far_step_clamped,
    'turned by a step': _turned_by_a_step,
}


def stand_in(atlas: AtlasModel, stance: str) -> AtlasSimInterface:
    """A robot in DRCSim's Stand pose, in Stand for STAND_FIRST_S, then taken to `stance`:
    back in Stand, as the behaviour that made it handed it back."""
    sim = AtlasSimulator(atlas, load_gains_yaml(DEFAULT_GAINS_FILE), time_to_unpin_s=0.0)
    place_in_stand_pose(sim.atlas, sim.data)
    interface = AtlasSimInterface(sim)
    for _ in range(round(STAND_FIRST_S / sim.dt_s)):
        sim.step()
        interface.end_step()
    STANCES[stance](interface)
    return interface


@dataclass(frozen=True)
class Held:
    """How the feet fared while Stand held the robot: where they were when it began
    ((2, 3): x, y, yaw per foot, left then right), the most each turned (rad) and slid
    (m), per foot, the lowest pelvis (m) and the CPU it took (s)."""

    feet: np.ndarray
    turned_rad: np.ndarray
    slid_m: np.ndarray
    lowest_pelvis_m: float
    cpu_s: float

    @property
    def stagger_m(self) -> float:
        """How far the left foot is ahead of the right along their mean heading (m)."""
        heading = float(np.mean(self.feet[:, 2]))
        return float(np.dot(self.feet[0, 0:2] - self.feet[1, 0:2],
                            (math.cos(heading), math.sin(heading))))


def feet_now(interface: AtlasSimInterface) -> np.ndarray:
    """(2, 3) each sole's centre x, y and yaw, as Stand's last estimate had them."""
    assert interface.stand is not None and interface.stand.last_state is not None
    state = interface.stand.last_state
    return np.array([[*state.sole_centres[foot, 0:2], yaw_of(state.sole_rotations[foot])]
                     for foot in (0, 1)])


def hold(interface: AtlasSimInterface, seconds: float) -> Held:
    """Stand for `seconds` from the stance's first step in Stand."""
    sim = interface.sim
    assert sim.mode is ControlMode.STAND
    started = time.process_time()
    start = feet_now(interface)
    turned, slid, lowest = np.zeros(2), np.zeros(2), math.inf
    for _ in range(round(seconds / sim.dt_s)):
        sim.step()
        interface.end_step()
        now = feet_now(interface)
        turned = np.maximum(turned, np.abs(np.angle(np.exp(1j * (now[:, 2] - start[:, 2])))))
        slid = np.maximum(slid, np.linalg.norm(now[:, 0:2] - start[:, 0:2], axis=1))
        lowest = min(lowest, float(sim.data.xpos[sim.atlas.pelvis_body_id][2]))
    return Held(start, turned, slid, lowest, time.process_time() - started)
