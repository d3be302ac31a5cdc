"""asi/'s error: an input the AtlasSimInterface's clients and tools cannot take.

Not named AsiError: behaviors.AsiError is the interface's error_code enum (atlas_msgs')."""

from __future__ import annotations

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['AsiInputError']


class AsiInputError(AtlasControlError, ValueError):
    """A teleop move, a walk plan or a demo cue the ASI code cannot take. A ValueError too,
    as the bare one it replaces was."""
