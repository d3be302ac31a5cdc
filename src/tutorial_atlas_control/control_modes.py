"""The strings /atlas/control_mode accepts (DRCSim's), for the tools that read bags.

The simulator's ControlMode (sim/simulator.py) is the authority; this copy keeps the bag
tools free of MuJoCo, and a unit test keeps the two equal. A bag records every string
published, also those the simulator refused (`user`): the tools mark those as refused.
"""

from __future__ import annotations

__all__ = ['VALID_CONTROL_MODES', 'is_refused_mode']

VALID_CONTROL_MODES: tuple[str, ...] = ('Stand', 'StandPrep', 'Freeze', 'ragdoll', 'User')


def is_refused_mode(mode: str) -> bool:
    """True for a /atlas/control_mode string the simulator refuses (and so never applied)."""
    return mode not in VALID_CONTROL_MODES
