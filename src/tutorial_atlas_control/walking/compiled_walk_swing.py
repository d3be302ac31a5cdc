"""A walking tick with a foot swinging as one C call (src/atlas_walk_swing.c through ctypes).

With the foot in the air, WalkController.tick_torque took the capture point's reference
from the step's plan, moved the landing by the predicted error (step_adjustment, the step
limits' clamp), made the law's pressure centre, then ran the legs' one call
(compiled_legs): a hundred float operations and a dozen Python calls a tick around a C call
of about the same cost. Here the legs' input is loaded as before and one call does the rest;
the step's numbers (its plan's first stage, the landing as planned, the stance foot, the
limits, the legs' reference's timed moves, whose heading, height and rate the call computes
each tick) are set once a step. Python makes the moved Footstep and SwingPath only in the ticks
where the landing moves. Used for a compiled estimate's state with the legs' one call; equal
to the Python bit for bit (test/unit/walking/test_compiled_walk_swing.py).
"""

from __future__ import annotations

import ctypes
from typing import TYPE_CHECKING

import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import BEARING_AT
from tutorial_atlas_control.native import AtlasWalkSwing, address
from tutorial_atlas_control.walking.footsteps import side_sign

if TYPE_CHECKING:
    from tutorial_atlas_control.walking.compiled_legs import CompiledLegs
    from tutorial_atlas_control.walking.dcm_plan import DcmPlan
    from tutorial_atlas_control.walking.footsteps import Footstep
    from tutorial_atlas_control.walking.leg_tasks import LegTasks
    from tutorial_atlas_control.walking.step_queue import StepLimits
    from tutorial_atlas_control.walking.walk import WalkGains

#: Set to `python` for the walk's swinging tick in Python (its legs' part still one call,
#: unless leg_tasks.LEGS_ENV says `python`).
WALK_SWING_ENV = 'TAC_WALK_SWING'

#: src/atlas_walk_swing.c's output: the capture point's reference, moved (1.0), the landing.
XI_REF, MOVED, STEP, OUT_SIZE = 0, 2, 3, 5


class CompiledWalkSwing:
    """atlas_walk_swing_tick around one CompiledLegs, with the walk's gain, whether and from
    what change (m) the landing is adjusted; its buffers its own."""

    def __init__(self, library: ctypes.CDLL, tasks: LegTasks, legs: CompiledLegs,
                 dcm_gain: float, adjust: bool, tolerance_m: float,
                 near_cop_m: float | None = None) -> None:
        """`near_cop_m`: the stance-sole rule's distance (sole_support.stance_rule), read by
        the call from the estimate's row each tick; None: the rule off, the legs' input as
        their caller loads it."""
        self._library = library
        self._tasks = tasks  # its timed moves of the legs' reference
        self._legs = legs
        self._out = np.zeros(OUT_SIZE)
        call = self._call = AtlasWalkSwing()
        call.legs = legs.address
        call.out = address(self._out, np.float64)
        call.dcm_gain = dcm_gain
        call.adjust = int(adjust)
        call.tolerance_m = tolerance_m
        #: Whether the call applies the stance-sole rule itself (the legs' load skips it).
        self.rule_in_call = near_cop_m is not None
        call.rule_in_call = int(self.rule_in_call)
        call.near_cop_m = 0.0 if near_cop_m is None else near_cop_m
        call.bearing_at = BEARING_AT
        self._pointer = ctypes.byref(call)
        self._tick = library.atlas_walk_swing_tick
        #: What the call's step numbers were set from (plan, planned, step, stance, limits).
        self._bound: tuple[object, ...] = ()

    def bind(self, plan: DcmPlan, planned: Footstep, step: Footstep, stance: Footstep,
             limits: StepLimits) -> None:
        """The step's numbers, unless they were set from these very objects: its plan's
        first stage, the landing as planned and as adjusted so far (`step`), the stance
        foot as the queue holds it, the step limits, and the legs' reference's timed moves
        (LegTasks.moves: the CoM height's, the heading's)."""
        moves = self._tasks.moves
        last = self._bound
        if last and last[0] is plan and last[1] is planned and last[2] is step \
                and last[3] is stance and last[4] is limits and last[5] is moves[0] \
                and last[6] is moves[1]:  # every tick of the step
            return
        call = self._call
        call.height[:], call.facing[:] = moves
        (cop_x, cop_y), (end_x, end_y) = plan.cops[0].tolist(), plan.ends[0].tolist()
        durations = plan.durations_s.tolist()
        call.plan[:] = (cop_x, cop_y, end_x, end_y, durations[0])
        call.plan_omega = plan.omega
        call.has_next = int(len(durations) > 1)
        call.next_duration_s = durations[1] if len(durations) > 1 else 0.0
        call.step_duration_s = step.duration_s
        call.planned[:] = (planned.x_m, planned.y_m, planned.z_m)
        call.stance[:] = (stance.x_m, stance.y_m, stance.yaw_rad)
        call.limits[:] = (limits.forward_m, limits.back_m, limits.min_width_m,
                          limits.max_width_m)
        call.side = side_sign(step.foot_index)
        call.step_xy[:] = (step.x_m, step.y_m)
        self._bound = (plan, planned, step, stance, limits, *moves)

    def tick(self, elapsed_s: float, time_s: float) -> tuple[np.ndarray, np.ndarray,
                                                             np.ndarray,
                                                             tuple[float, float] | None]:
        """The tick at `time_s` (s), `elapsed_s` (s) into the step, the legs' input loaded
        but the pressure centre and the reference's heading, height and rate (the call's, from
        the moves bound): the torques, the pressure centre as kept, the capture point's
        reference (new arrays), and the landing (x, y) where it moved this tick (None: it
        did not)."""
        call = self._call
        call.elapsed_s = elapsed_s
        call.time_s = time_s
        self._tick(self._pointer)
        out = self._out
        moved = None
        if out[MOVED] != 0.0:
            x, y = out[STEP:STEP + 2].tolist()
            moved = (x, y)
        torque, cop = self._legs.results()
        return torque, cop, out[XI_REF:XI_REF + 2].copy(), moved


def walk_swing_kernel(legs: LegTasks, gains: WalkGains,
                      compiled: bool | None = None) -> CompiledWalkSwing | None:
    """The walk's swinging tick as one call around `legs`' one call, or None: in Python
    (`compiled` False, or None and WALK_SWING_ENV says `python`; or no legs' call)."""
    library = native.chosen_library(WALK_SWING_ENV, compiled)
    kernel = legs.legs_kernel
    if library is None or kernel is None:
        return None
    return CompiledWalkSwing(library, legs, kernel, gains.dcm_gain, gains.adjust_steps,
                             gains.adjust_tolerance_m, gains.legs.near_cop_m)
