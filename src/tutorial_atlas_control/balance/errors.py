"""balance/'s error: what the balance refuses, as one class callers can catch."""

from __future__ import annotations

from tutorial_atlas_control.errors import AtlasControlError

__all__ = ['BalanceError']


class BalanceError(AtlasControlError, ValueError):
    """A value the balance cannot work with (a pendulum under the ground), or a behaviour
    used before it was started. A ValueError too, as the bare one it replaces was."""
