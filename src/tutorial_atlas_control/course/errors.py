"""course/'s error: what the course's description, world or scoring refuses."""

from __future__ import annotations

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['CourseError']


class CourseError(AtlasControlError, ValueError):
    """A course description, a world or a score input that cannot be taken (an unknown
    world or start, a terrain file that does not match its description). A ValueError too."""
