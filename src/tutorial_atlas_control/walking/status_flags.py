"""walk_feedback's and step_feedback's status_flags: one set for Walk, Step and the ASI.

The library's values (ASI.md), not atlas_msgs' constants: Walk reports one of its phases
(SWAYING, STEPPING, CATCHING) plus the warnings; Step reports SWAYING or STEPPING; DRCSim's
actionlib server (asi/walk_demo.py) compares Step's as literals.
"""

from __future__ import annotations

__all__ = ['CATCHING', 'ERROR_INCONSISTENT_STEPS', 'OKAY', 'STEPPING', 'SWAYING',
           'WARNING_INSUFFICIENT_STEP_DATA']

OKAY, SWAYING, STEPPING, CATCHING = 0, 1, 2, 4
#: Walk's warnings, added to its phase.
WARNING_INSUFFICIENT_STEP_DATA = 8
ERROR_INCONSISTENT_STEPS = 16
