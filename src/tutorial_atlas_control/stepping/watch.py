"""The run's headless log lines: what a user without a window sees of a run.

One line per fall (sim/fall.py's: the pelvis less than FALL_HEIGHT_M above the ground under
the feet, once until a reset), one for the first
command since the start or a reset, a warning when joint commands arrive in a mode that
does not apply them, and one line per applied cheat (throttled per kind).
"""

from __future__ import annotations

from tutorial_atlas_control import topics
from tutorial_atlas_control.fall_report import fall_line
from tutorial_atlas_control.sim import (
    FALL_HEIGHT_M,
    AtlasSimulator,
    GroundUnderFeet,
    SimInput,
    describe_input,
)
from tutorial_atlas_control.stepping.outputs import LoopLog
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['INPUT_LOG_PERIOD_S', 'NOT_USER_WARN_PERIOD_S', 'RunWatch']

#: An applied input of a kind is logged at most once per this much sim time (s): a
#: disturbance generator streaming a wrench at 1 kHz must not flood /rosout.
INPUT_LOG_PERIOD_S = 1.0
#: Commands arriving while the mode is not User are warned about at once, then at most
#: this often (s of sim time) while they keep coming.
NOT_USER_WARN_PERIOD_S = 5.0


class RunWatch:
    """Falls, first commands, ignored commands and cheats, as log lines."""

    def __init__(self, sim: AtlasSimulator, log: LoopLog) -> None:
        self.sim = sim
        self.log = log
        self.pelvis_z_index = sim.atlas.free_qpos_adr + 2  # the pelvis height in qpos
        self.ground = GroundUnderFeet(sim.atlas, sim.data, sim.ground)  # the interface's too
        self.fall_armed = True  # one line per fall: disarmed by it, re-armed by a reset
        self.first_command_ns: int | None = None  # since the start or last reset
        self.not_user_warned_ns: int | None = None
        self._input_logged_ns: dict[str, int] = {}  # kind -> sim time it was last logged

    def rearm(self) -> None:
        """After a reset: the next fall and the next first command are new."""
        self.fall_armed = True
        self.first_command_ns = None
        self.not_user_warned_ns = None

    def watch_fall(self) -> None:
        """After a step: one line when the robot falls (headless, the only sign of a
        fall), then nothing until a reset."""
        pelvis_z_m = float(self.sim.data.qpos[self.pelvis_z_index])
        if self.fall_armed and self.ground.fallen(pelvis_z_m):
            self.fall_armed = False
            sim = self.sim
            after_s = (None if self.first_command_ns is None else
                       (sim.sim_time_ns - self.first_command_ns) / NS_PER_S)
            self.log.info(fall_line(FALL_HEIGHT_M, sim.sim_time_ns / NS_PER_S, after_s))

    def first_command(self, topic: str) -> None:
        """The first command since the start or last reset was applied (which one a
        trajectory started from: a late one makes the robot jump)."""
        sim = self.sim
        self.first_command_ns = sim.sim_time_ns
        self.log.info(f'first {topic} since the start or last reset, at '
                      f't={sim.sim_time_ns / NS_PER_S:.3f} s ({sim.mode.value} mode)')

    def new_mode(self) -> None:
        """A mode switch: commands it ignores are warned about again at once."""
        self.not_user_warned_ns = None

    def warn_not_user(self) -> None:
        """Commands arrived in a mode that does not apply them: say how to switch (the
        tutorial's step most often forgotten), at once, then every NOT_USER_WARN_PERIOD_S."""
        now_ns = self.sim.sim_time_ns
        last_ns = self.not_user_warned_ns
        if last_ns is not None and 0 <= now_ns - last_ns < NOT_USER_WARN_PERIOD_S * NS_PER_S:
            return  # (a rewind, reset_simulation, warns again)
        self.not_user_warned_ns = now_ns
        self.log.warn(f'{topics.JOINT_COMMANDS} arrive in {self.sim.mode.value} mode, which does '
                      f'not apply them; switch to User mode: {topics.SWITCH_TO_USER}')

    def input_applied(self, item: SimInput, time_ns: int) -> None:
        """A line for a cheat applied at `time_ns`, at most one per kind and
        INPUT_LOG_PERIOD_S."""
        last_ns = self._input_logged_ns.get(item.kind)
        if last_ns is None or not 0 <= time_ns - last_ns < INPUT_LOG_PERIOD_S * NS_PER_S:
            self._input_logged_ns[item.kind] = time_ns
            self.log.info(f'applied at t={time_ns / NS_PER_S:.3f} s: {describe_input(item)}')
