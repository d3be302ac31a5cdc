"""How a (re)set robot starts: pinned or not, and when the start-up pin lets go.

DRCSim's `pinned` start holds the pelvis with gravity off and switches to `nominal` after
time_to_unpin; the port's historical start pins the pelvis with gravity on for that long.
`bdi_stand` is DRCSim 2.6/2.7's default start (VRCPlugin's `bdi_stand` mode, also sent on
/atlas/mode later): pinned with gravity off, the joints set to the Stand pose under the user's
PID, `nominal` at BDI_STAND_NOMINAL_S and the Stand behaviour, every k_effort 0, at
BDI_STAND_S; the simulator sets the pose and the modes when this pin says so. An explicit
/atlas/mode cancels what is pending.
"""

from __future__ import annotations

import enum

import mujoco

from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.vrc import VrcMode, VrcState
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['BDI_STAND_NOMINAL_S', 'BDI_STAND_S', 'StartupEvent', 'StartupPin']

#: VRCPlugin's atlas.startupStandPrepDuration (s): bdi_stand's Stand comes this long after
#: the mode was set, `nominal` (the pin released, gravity on) one second before.
BDI_STAND_S = 2.0
BDI_STAND_NOMINAL_S = BDI_STAND_S - 1.0


class StartupEvent(enum.Enum):
    """What a due release asks of the simulator."""

    NONE = 'none'  # the pin did all there was to do
    STAND = 'stand'  # bdi_stand's end: the Stand behaviour, every k_effort 0


class StartupPin:
    """The start-up pin of one simulator and its timed release.

    The simulator calls release() when `pending` and its sim time reaches `release_ns`
    (two attribute reads per step, no call).
    """

    def __init__(self, atlas: atlas_model.AtlasModel, data: mujoco.MjData, vrc: VrcState,
                 time_to_unpin_s: float, startup_mode: VrcMode) -> None:
        """`startup_mode`: one of vrc.STARTUP_MODES; `time_to_unpin_s` 0: no timed release
        (DRCSim's `pinned` then stays pinned for good). bdi_stand keeps DRCSim's own times."""
        self._atlas = atlas
        self._data = data
        self._vrc = vrc
        self.time_to_unpin_s = time_to_unpin_s
        self.startup_mode = startup_mode
        self.pending = False
        self.release_ns = 0
        #: bdi_stand's sequence is under way: its Stand is due at `stand_ns`.
        self.bdi_stand = False
        self.stand_ns = 0

    def start(self, sim_time_ns: int) -> None:
        """Pin (or not) as the start-up mode says, after reset_world reset the cheats.

        For bdi_stand the simulator calls begin_bdi_stand itself, once its commands are reset.
        """
        self.release_ns = sim_time_ns + int(round(self.time_to_unpin_s * NS_PER_S))
        self.bdi_stand = False
        timed = self.time_to_unpin_s > 0.0
        if self.startup_mode is VrcMode.PINNED:
            self._vrc.set_mode(VrcMode.PINNED)
            self.pending = timed
        elif self.startup_mode is VrcMode.BDI_STAND:
            self.pending = False
        else:  # the port's historical start: pinned with gravity for time_to_unpin
            atlas_model.set_pelvis_pinned(self._atlas, self._data, timed)
            self.pending = self._vrc.is_pinned()

    def begin_bdi_stand(self, sim_time_ns: int) -> None:
        """VRCPlugin's `bdi_stand`: pinned where the robot is, gravity off; `nominal` after
        BDI_STAND_NOMINAL_S, the Stand after BDI_STAND_S (the caller sets the pose)."""
        self._vrc.set_mode(VrcMode.BDI_STAND)
        self.bdi_stand = True
        self.pending = True
        self.release_ns = sim_time_ns + int(round(BDI_STAND_NOMINAL_S * NS_PER_S))
        self.stand_ns = sim_time_ns + int(round(BDI_STAND_S * NS_PER_S))

    def cancel(self) -> None:
        """The user chose a mode: no release will override it."""
        self.pending = False
        self.bdi_stand = False

    def release(self) -> StartupEvent:
        """Time is up: DRCSim's `pinned` becomes `nominal`, the historical pin lets go;
        bdi_stand goes `nominal`, then asks for its Stand."""
        if self.bdi_stand:
            if self.release_ns < self.stand_ns:  # the first stage
                self._vrc.set_mode(VrcMode.NOMINAL)
                self.release_ns = self.stand_ns
                return StartupEvent.NONE
            self.pending = self.bdi_stand = False
            return StartupEvent.STAND
        self.pending = False
        if self.startup_mode is VrcMode.PINNED:
            self._vrc.set_mode(VrcMode.NOMINAL)
        else:
            atlas_model.set_pelvis_pinned(self._atlas, self._data, False)
        return StartupEvent.NONE
