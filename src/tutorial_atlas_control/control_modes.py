"""The strings /atlas/control_mode accepts (DRCSim's): the simulator's modes and the bag tools'.

Here, below every subpackage, so that the bag tools mark a refused string without importing
the simulator. A bag records every string published, also those the simulator refused
(`user`): the tools mark those as refused.
"""

from __future__ import annotations

import enum

__all__ = ['ControlMode', 'VALID_CONTROL_MODES', 'is_refused_mode']


class ControlMode(str, enum.Enum):
    """The strings DRCSim accepted on /atlas/control_mode."""

    STAND = 'Stand'
    STAND_PREP = 'StandPrep'
    FREEZE = 'Freeze'
    RAGDOLL = 'ragdoll'
    USER = 'User'
    WALK = 'Walk'
    #: Step runs in a mode of its own, entered only through the AtlasSimInterface's STEP:
    #: /atlas/control_mode does not take it (DRCSim's did not), but /atlas/current_control_mode
    #: says it.
    STEP = 'Step'


VALID_CONTROL_MODES: tuple[str, ...] = tuple(mode.value for mode in ControlMode
                                             if mode is not ControlMode.STEP)


def is_refused_mode(mode: str) -> bool:
    """True for a /atlas/control_mode string the simulator refuses (and so never applied)."""
    return mode not in VALID_CONTROL_MODES
