"""How a (re)set robot starts: pinned or not, and when the start-up pin lets go.

DRCSim's `pinned` start holds the pelvis with gravity off and switches to `nominal` after
time_to_unpin; the port's historical start pins the pelvis with gravity on for that long;
`bdi_stand` starts free. An explicit /atlas/mode cancels the pending release.
"""

from __future__ import annotations

import mujoco

from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.vrc import VrcMode, VrcState
from tutorial_atlas_control.units import NS_PER_S


class StartupPin:
    """The start-up pin of one simulator and its timed release.

    The simulator releases it when `pending` and its sim time reaches `release_ns`
    (two attribute reads per step, no call).
    """

    def __init__(self, atlas: atlas_model.AtlasModel, data: mujoco.MjData, vrc: VrcState,
                 time_to_unpin_s: float, startup_mode: VrcMode) -> None:
        """`startup_mode`: one of vrc.STARTUP_MODES; `time_to_unpin_s` 0: no timed release
        (DRCSim's `pinned` then stays pinned for good)."""
        self._atlas = atlas
        self._data = data
        self._vrc = vrc
        self.time_to_unpin_s = time_to_unpin_s
        self.startup_mode = startup_mode
        self.pending = False
        self.release_ns = 0

    def start(self, sim_time_ns: int) -> None:
        """Pin (or not) as the start-up mode says, after reset_world reset the cheats."""
        self.release_ns = sim_time_ns + int(round(self.time_to_unpin_s * NS_PER_S))
        timed = self.time_to_unpin_s > 0.0
        if self.startup_mode is VrcMode.PINNED:
            self._vrc.set_mode(VrcMode.PINNED)
            self.pending = timed
        elif self.startup_mode is VrcMode.BDI_STAND:
            self.pending = False
        else:  # the port's historical start: pinned with gravity for time_to_unpin
            atlas_model.set_pelvis_pinned(self._atlas, self._data, timed)
            self.pending = self._vrc.is_pinned()

    def cancel(self) -> None:
        """The user chose a mode: no release will override it."""
        self.pending = False

    def release(self) -> None:
        """Time is up: DRCSim's `pinned` becomes `nominal`, the historical pin lets go."""
        self.pending = False
        if self.startup_mode is VrcMode.PINNED:
            self._vrc.set_mode(VrcMode.NOMINAL)
        else:
            atlas_model.set_pelvis_pinned(self._atlas, self._data, False)
