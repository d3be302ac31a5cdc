"""Where a controller plugs into the stepping loop: one call before each step.

The default is the loop's CommandInbox: it hands the simulator what users sent (joint
commands, AtlasCommands, Tests) and the simulator's law turns that into torques. A
controller of its own (a balance or walking controller) implements before_step: it reads
the simulator's state and gives it this step's command (AtlasSimulator.receive_updates),
usually after applying what users sent (CommandInbox.apply_pending). The loop makes it
from its inbox (SteppingLoop's `controller` argument) and calls nothing else of it.
"""

from __future__ import annotations

from typing import Protocol

__all__ = ['StepController']


class StepController(Protocol):
    """Decides each step's command."""

    def before_step(self) -> None:
        """Called once before each step, under the loop's lock (not while paused): give
        the simulator the command for the coming step."""
