"""Walk as the simulator's behaviour for control mode Walk (sim/behaviour.py's protocol).

It shares the balancing Stand's estimator and whole-body controller. On start it takes the
robot over where it stands (the Stand's reference made from the present state, as Stand
itself does), builds a step queue from the feet as they are, and walks `next_steps` (set
before the start from an AtlasSimInterfaceCommand's queue) or, without them, its default
steps (DRCSim's fixed queue: /atlas/control_mode Walk). Steps offered while it walks
join the queue by index. Once the walk has caught itself after its last step it is
`done`: the interface then hands the robot back to Stand. The feet stand on the ground
under their soles (its height from the Stand's ground; a carrying sole on its own plane,
leg_tasks.standing_pose), and each tick the estimator's pendulum ground moves with the
walk's support height (feet_surfaces) from where it was as the walk began: on a slope omega
follows the CoM's height over the feet as they rise or fall, not over z 0; it stays there
for the Stand after. (Set to the support's own height instead, a walk begun on the
course's level ground at z 0.03 landed its steps 13 cm ahead on average: the walk's gains
were found with omega over z 0.)
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass

import mujoco
import numpy as np

from tutorial_atlas_control.balance import JOINTS_IN_CALL, BalanceState, StandBehaviour
from tutorial_atlas_control.walking.errors import WalkingError
from tutorial_atlas_control.walking.feet_surfaces import support_height_m
from tutorial_atlas_control.walking.footsteps import DRCSIM_WALK_QUEUE, Footstep
from tutorial_atlas_control.walking.leg_tasks import standing_pose
from tutorial_atlas_control.walking.status_flags import STEPPING
from tutorial_atlas_control.walking.step_queue import DEFAULT_LIMITS, StepLimits, StepQueue
from tutorial_atlas_control.walking.walk import WalkController, WalkGains

__all__ = ['WalkBehaviour', 'WalkStatus']


@dataclass(frozen=True)
class WalkStatus:
    """What walk_feedback reports (ASI.md): the time left in the step being taken (s), the
    steps taken, the first step the queue needs, the flags, and the next steps as clamped."""

    t_step_rem_s: float
    current_step_index: int
    next_step_index_needed: int
    status_flags: int
    steps_saturated: tuple[Footstep, ...]


class WalkBehaviour:
    """Walk on `stand`'s balance; steps come through `offer`."""

    def __init__(self, stand: StandBehaviour, gains: WalkGains | None = None,
                 limits: StepLimits = DEFAULT_LIMITS,
                 default_steps: Iterable[Footstep] = DRCSIM_WALK_QUEUE) -> None:
        """`default_steps`: what a start without next_steps walks."""
        self.stand = stand
        self.default_steps = tuple(default_steps)
        self.gains = gains
        self.limits = limits
        #: The walk under way (None before the first start).
        self.walk: WalkController | None = None
        #: The estimator's pendulum ground less the feet's support height as the walk began.
        self.pendulum_offset_m = 0.0
        #: The steps the next start walks (None: default_steps).
        self.next_steps: list[Footstep] | None = None
        #: The state the last tick estimated (None before the first).
        self.last_state: BalanceState | None = None
        #: The MjData ticked last and its qpos and qvel views (None: none yet).
        self._vectors: tuple[mujoco.MjData, np.ndarray, np.ndarray] | None = None

    @property
    def done(self) -> bool:
        """The walk has ended: its steps taken and the robot caught at rest."""
        return self.walk is not None and self.walk.done

    def offer(self, steps: Iterable[Footstep]) -> None:
        """A client's steps for the walk under way: into its queue by index."""
        if self.walk is None:
            raise WalkingError('WalkBehaviour.offer before start()')
        self.walk.queue.offer(steps)

    def finish(self) -> None:
        """End the walk with the step under way (none if it is swaying): then it catches
        itself and is done."""
        walk = self.walk
        if walk is None:
            raise WalkingError('WalkBehaviour.finish before start()')
        taking = walk.step.step_index if walk.phase == STEPPING and walk.step else None
        walk.queue.stop(taking)

    def start(self, data: mujoco.MjData) -> None:
        """Begin a walk from where the robot stands, over the steps offered so far (DRCSim's
        fixed queue if none were)."""
        stand = self.stand
        stand.start(data)
        controller, state = stand.controller, stand.last_state
        assert controller is not None and state is not None  # set by start
        under = stand.ground_under_soles(state)  # each sole's surface: its height, normal
        # The pendulum's ground moves with the feet's support from where it is now.
        self.pendulum_offset_m = (stand.estimator.ground_m
                                  - support_height_m(under[0][0], under[1][0]))
        queue = StepQueue(*(standing_pose(state, foot, under[foot][1]) for foot in (0, 1)),
                          self.limits)
        queue.offer(self.default_steps if self.next_steps is None else self.next_steps)
        self.next_steps = None
        self.walk = WalkController(controller, queue, state, float(data.time), self.gains,
                                   stand.ground_under_m(state) + stand.com_height_m,
                                   (under[0][0], under[1][0]))

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This tick's f_out (N m, (28,)), within the effort limits."""
        walk = self.walk
        if walk is None:
            raise WalkingError('WalkBehaviour.torque before start()')
        stand, atlas, time_s = self.stand, self.stand.atlas, float(data.time)
        ground = walk.surfaces.support_at(time_s) + self.pendulum_offset_m
        if ground != stand.estimator.ground_m:  # on level ground never: no C field written
            stand.estimator.ground_m = ground
        state = stand.estimator.estimate_stepped(data)
        self.last_state = state
        if state.row_address is not None and walk.legs.legs_kernel is not None:
            # every call of the tick compiled: they read the joints from the estimate's data
            return walk.tick_torque(state, JOINTS_IN_CALL, JOINTS_IN_CALL, time_s).torque_nm
        vectors = self._vectors  # the binding makes a new view at each read of data.qpos
        if vectors is None or vectors[0] is not data:
            vectors = self._vectors = (data, data.qpos, data.qvel)
        return walk.tick_torque(state, vectors[1][atlas.qpos_adr], vectors[2][atlas.dof_adr],
                                time_s).torque_nm

    def status(self, time_s: float) -> WalkStatus:
        """walk_feedback's values now."""
        walk = self.walk
        if walk is None:
            return WalkStatus(0.0, 0, 1, 0, ())
        queue = walk.queue
        remaining = 0.0
        if walk.phase == STEPPING and walk.step is not None:
            remaining = max(0.0, walk.step.duration_s - (time_s - walk.phase_start_s))
        preview = queue.preview()
        return WalkStatus(remaining, queue.current_step_index, queue.next_step_index_needed,
                          queue.status_flags(walk.phase, preview), tuple(preview))
