"""Where a behaviour of the open AtlasSimInterface hands the simulator its torque, f_out.

DRCSim's AtlasPlugin blended each joint's PID torque with the output of BDI's behaviour
library (f_out) by k_effort. Here a Behaviour computes f_out from the simulator's state
once per step, and the simulator blends it exactly as it blends its hold's torque. The
behaviours themselves (balance/) sit above the simulator and are installed into it: the
simulator knows only this protocol, so it stays free of the controllers' imports.
"""

from __future__ import annotations

from typing import Protocol

import mujoco
import numpy as np

from tutorial_atlas_control.control_modes import ControlMode

__all__ = ['Behaviour', 'ModeBehaviours']


class Behaviour(Protocol):
    """A controller giving f_out, the 28 joint torques of one behaviour, each step."""

    def start(self, data: mujoco.MjData) -> None:
        """Take over the robot as it is in `data` now (e.g. stand where it stands)."""

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This step's f_out (N m, (28,), the tutorial's joint order) from `data`'s joint
        positions and velocities; `data` is read, never written. Within the simulator's
        step its body poses and centres of mass are at those positions (sim.shared_passes;
        with TAC_SHARED_PASSES=own, at the previous step's start)."""


class ModeBehaviours:
    """The behaviours installed for the control modes, and the one acting now.

    Stand and StandPrep take one; a mode without one keeps the simulator's law on its
    command (the hold, the user's PID, ragdoll's zeros). The port's start holds the robot
    with that law even where Stand has a behaviour (`holding_start`): the behaviour library
    is there, waiting to be asked, as DRCSim 3.x's library waited in User.
    """

    def __init__(self) -> None:
        #: What each mode runs; a mode absent: its hold (or the law's command).
        self.installed: dict[ControlMode, Behaviour] = {}
        #: The behaviour acting now (the mode's, started), or None.
        self.acting: Behaviour | None = None
        #: The start's hold acts although the mode's behaviour is installed: until a mode
        #: is selected (set_mode), no behaviour acts.
        self.holding_start = False
        #: A restart in Stand holds the start pose with the parameter gains (the tutorial's
        #: start) even when Stand has a behaviour installed: the AtlasSimInterface sets it
        #: when its library waits to be asked (atlas.launch).
        self.hold_stand_at_start = False

    @property
    def stand(self) -> Behaviour | None:
        """What Stand runs; None: Stand is the hold."""
        return self.installed.get(ControlMode.STAND)

    def install(self, mode: ControlMode, behaviour: Behaviour | None) -> None:
        """`mode` runs `behaviour` from its next selection (None: the hold again)."""
        if behaviour is None:
            self.installed.pop(mode, None)
        else:
            self.installed[mode] = behaviour

    def hold_start(self) -> None:
        """The start's hold acts, whatever is installed, until the next select."""
        self.acting = None
        self.holding_start = True

    def restart(self, mode: ControlMode, data: mujoco.MjData) -> None:
        """After a reset in `mode`: the start's hold (hold_stand_at_start, in Stand), else
        `mode`'s behaviour started from the robot in `data`."""
        if self.hold_stand_at_start and mode is ControlMode.STAND:
            self.hold_start()
        else:
            self.select(mode, data)

    def select(self, mode: ControlMode, data: mujoco.MjData) -> None:
        """`mode`'s behaviour, started from the robot in `data`, becomes the acting one."""
        self.holding_start = False
        behaviour = self.installed.get(mode)
        if behaviour is not None:
            behaviour.start(data)
        self.acting = behaviour
