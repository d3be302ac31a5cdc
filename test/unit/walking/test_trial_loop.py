"""The offline walk's loop (walk_trial.run_walking_stand) keeps the trial's figures as
GroundUnderFeet measures them after every step: the lowest clearance of the pelvis, and the
fall at the first step it is not standing (sim.fall.standing), on a level world's ground read
once and on a ground asked at every step; the pushes applied at their ticks."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.balance import Push, push_events, standing_simulator
from tutorial_atlas_control.sim import AtlasSimulator, GroundUnderFeet
from tutorial_atlas_control.walking import straight_steps
from tutorial_atlas_control.walking.walk_trial import WalkingStand, run_walking_stand

#: A shove the Stand does not survive, early in the stand before the walk.
SHOVE = Push(0.2, (900.0, 300.0, 0.0), 0.25)
DURATION_S = 1.6


@pytest.mark.parametrize('level', [True, False])
def test_the_trial_loop_measures_the_fall_as_the_ground_does(level: bool) -> None:
    sim: AtlasSimulator = standing_simulator()
    behaviour = WalkingStand(sim.atlas, straight_steps(2, 0.2), 1.0)
    sim.install_stand(behaviour)
    ground = GroundUnderFeet(sim.atlas, sim.data)
    if not level:
        ground.ground.level_m = None  # the ground under the lower sole asked at every step
    seen: list[tuple[float, bool, float]] = []
    step = sim.step

    def measured_step() -> None:
        step()
        vrc = sim.vrc  # the pelvis force of the step just taken (the cheats' forces)
        force = float(vrc.xfrc[sim.atlas.pelvis_body_id, 0]) if vrc.active else 0.0
        seen.append((ground.clearance_m(), ground.standing(), force))

    sim.step = measured_step  # type: ignore[method-assign]
    trial = run_walking_stand(sim, behaviour, ground, DURATION_S,
                              push_events([SHOVE], sim.dt_s))
    standing = [stood for _, stood, _ in seen]
    assert trial.fell and not standing[-1] and all(standing[:-1])
    assert len(seen) < round(DURATION_S / sim.dt_s)
    assert trial.lowest_pelvis_m == min(clearance for clearance, _, _ in seen)
    pushed = [tick for tick, (_, _, force) in enumerate(seen) if force != 0.0]
    assert pushed[0] == round(SHOVE.start_s / sim.dt_s)
    assert len(pushed) == round(SHOVE.duration_s / sim.dt_s)
