"""The AtlasSimInterface's numbers: behaviours, feedback flags, error codes (DRCSim 2.7's
atlas_msgs constants and the library's published values, ASI.md), and which simulator
control mode runs each behaviour."""

from __future__ import annotations

import enum

from tutorial_atlas_control.control_modes import ControlMode

__all__ = ['BEHAVIOR_OF_MODE', 'MODE_OF_BEHAVIOR', 'AsiError', 'Behavior', 'Status']


class Behavior(enum.IntEnum):
    """AtlasSimInterfaceCommand.behavior / AtlasSimInterfaceState.current_behavior."""

    STAND = 0
    USER = 1
    FREEZE = 2
    STAND_PREP = 3
    WALK = 4
    STEP = 5
    MANIPULATE = 6


class Status(enum.IntEnum):
    """AtlasBehaviorFeedback.status_flags: published one value at a time (DRCSim's
    actionlib server compares exact values)."""

    OK = 0
    TRANSITION_IN_PROGRESS = 1
    TRANSITION_SUCCESS = 2
    FAILED_TRANS_UNKNOWN_BEHAVIOR = 4
    FAILED_TRANS_ILLEGAL_BEHAVIOR = 8
    FAILED_TRANS_COM_POS = 16
    FAILED_TRANS_COM_VEL = 32
    FAILED_TRANS_VEL = 64
    WARNING_AUTO_TRANS = 128
    ERROR_FALLING = 256


class AsiError(enum.IntEnum):
    """AtlasSimInterfaceState.error_code."""

    NO_ERRORS = 0
    UNSPECIFIED = -1
    VALUE_OUT_OF_RANGE = -2
    INVALID_INDEX = -3
    FAILED_TO_START_BEHAVIOR = -4
    NO_ACTIVE_BEHAVIOR = -5
    NO_SUCH_BEHAVIOR = -6
    BEHAVIOR_NOT_IMPLEMENTED = -7
    TIME_RAN_BACKWARD = -8


#: The simulator's control mode that runs each behaviour served so far.
MODE_OF_BEHAVIOR: dict[Behavior, ControlMode] = {
    Behavior.STAND: ControlMode.STAND,
    Behavior.USER: ControlMode.USER,
    Behavior.FREEZE: ControlMode.FREEZE,
    Behavior.STAND_PREP: ControlMode.STAND_PREP,
}
#: The behaviour each control mode reports as current. ragdoll is every joint on the
#: user's (zeroed) PID: User, as far as the behaviour library is concerned.
BEHAVIOR_OF_MODE: dict[ControlMode, Behavior] = {
    **{mode: behavior for behavior, mode in MODE_OF_BEHAVIOR.items()},
    ControlMode.RAGDOLL: Behavior.USER,
    ControlMode.WALK: Behavior.WALK,  # served with the balancing Stand only
    ControlMode.STEP: Behavior.STEP,  # the same
}
