"""DRCSim's mode-switching demo (asi/mode_switching.py) run offline through the stepping
loop, from the default launch's start (the tutorial's hold, the library in User), as the
live node would run it: the cues' messages received between steps."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

from support.stepping_fakes import make_loop
from tutorial_atlas_control.asi.mode_switching import (
    AFTER_LAST_S,
    CUES,
    KP_VELOCITY,
    cue_messages,
)
from tutorial_atlas_control.sim import fallen
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.walking.start_noise import perturb_start

CONFIG = Path(__file__).resolve().parents[2] / 'config' / 'atlas_controller.yaml'
#: When the demo begins (s of sim time): the hold has settled after its 1 s pin.
START_S = 3.0


@dataclass
class ModeSwitchingRun:
    """What the run did: the behaviours the library reported (each change, in order), the
    lowest pelvis from the first cue on (m), the pelvis at the WALK cue and at the end
    (x, y, z), whether it fell, and when (s of sim time)."""

    behaviours: list[int] = field(default_factory=list)
    lowest_pelvis_m: float = float('inf')
    at_walk: np.ndarray | None = None
    at_end: np.ndarray | None = None
    fell_at_s: float | None = None
    refused: list[str] = field(default_factory=list)


def run_mode_switching(seed: int | None = None, kp_velocity: float = KP_VELOCITY
                       ) -> ModeSwitchingRun:
    """The demo from a start perturbed by `seed` (None: not), its AtlasCommands with the
    velocity gain `kp_velocity`."""
    gains = load_gains_yaml(CONFIG)
    sim = AtlasSimulator(atlas_model.load_model(), gains)
    loop, _, log, _ = make_loop(sim, listeners=set(), balance_stand=True, hold_at_start=True)
    perturb_start(sim.atlas, sim.data, seed, on_ground=False)
    pelvis = sim.atlas.pelvis_body_id
    pending = list(CUES)
    end_s = START_S + CUES[-1].at_s + AFTER_LAST_S
    run = ModeSwitchingRun()

    def is_shutdown() -> bool:
        t_s = sim.sim_time_ns / 1e9
        position = sim.data.xpos[pelvis]
        if t_s >= START_S:
            run.lowest_pelvis_m = min(run.lowest_pelvis_m, float(position[2]))
        behaviour = int(loop.asi.current_behavior)
        if not run.behaviours or run.behaviours[-1] != behaviour:
            run.behaviours.append(behaviour)
        while pending and t_s >= START_S + pending[0].at_s:
            cue = pending.pop(0)
            xmat = sim.data.xmat[pelvis]
            pose = (float(position[0]), float(position[1]), float(np.arctan2(xmat[3], xmat[0])))
            if cue.name == 'WALK':
                run.at_walk = position.copy()
            for topic, raw in cue_messages(cue, sim.sim_time_ns, gains.p, pose, kp_velocity):
                loop.receive_command(raw, topic)
        if fallen(float(position[2])):  # sim/fall.py's criterion on the flat ground
            run.fell_at_s = t_s
        return t_s >= end_s or run.fell_at_s is not None

    loop.run(is_shutdown)
    run.at_end = sim.data.xpos[pelvis].copy()
    run.refused = log.of('refused')
    return run

