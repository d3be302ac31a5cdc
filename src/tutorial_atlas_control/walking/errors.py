"""walking/'s error: what the walk refuses, as one class callers can catch."""

from __future__ import annotations

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['WalkingError']


class WalkingError(AtlasControlError, ValueError):
    """A plan, a step or a setting the walk cannot take (a step not the one under way, a
    swing of no duration, negative start noise), or Walk used before it was started. A
    ValueError too, as the bare one it replaces was."""
