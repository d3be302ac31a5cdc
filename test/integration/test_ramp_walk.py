"""Walk up and down the VRC mud pit's 22-degree ramp (offline/terrain_trial.py's
ramp_up_22deg and ramp_down_22deg, shortened to 2.6 m: onto the ramp, up or down its 1.5 m,
and half a metre beyond), from the deterministic start and seed 1: no fall, every planned
step landed within 5 cm of where it was asked, the pelvis ending at the walking height over
the platform (up) or the floor (down) past the ramp. The steps are planned on the ground
(walking/ground_strides.py); in the slopes' straight 0.2 m strides every run fell (up on the
ramp, down at the platform's edge). The 3.6 m figures over 8 starts are docs/vrc.md's
(tools/terrain_walk.py). About 15 s of CPU."""

from __future__ import annotations

import dataclasses

import pytest

from tutorial_atlas_control.offline import TERRAINS, planned_steps, terrain_walk
from tutorial_atlas_control.offline.terrain_trial import RAMP_RUN_M, RAMP_START_M

pytestmark = pytest.mark.offline

RUN_M = 2.6


def _walk(case_name: str, seed: int | None) -> None:
    case = dataclasses.replace(TERRAINS[case_name], run_m=RUN_M)
    planned = planned_steps(case)
    trial = terrain_walk(case, seed)
    x, _, z = trial.pelvis_end.tolist()
    ground = max(case.ramp_rise_m, 0.0)  # past the ramp: the platform up, the floor down
    print(f'figures: {case_name} seed {seed}: steps {trial.steps} of {planned}, worst landing '
          f'{trial.worst_landing_m:.4f} m, lowest pelvis {trial.lowest_pelvis_m:.3f} m, '
          f'pelvis end {trial.pelvis_end.round(3)}, {z - ground:.3f} m over the ground')
    assert not trial.fell
    assert trial.steps == planned
    assert trial.worst_landing_m < 0.05
    # The last step brings the feet together at the run's end, past the ramp's top or foot.
    assert RAMP_START_M + RAMP_RUN_M < x == pytest.approx(RUN_M, abs=0.1)
    assert 0.8 < z - ground < 0.95


@pytest.mark.parametrize('seed', [None, 1])
def test_up_the_pit_s_22_degree_ramp_onto_its_platform_without_a_fall(seed: int | None) -> None:
    _walk('ramp_up_22deg', seed)


@pytest.mark.parametrize('seed', [None, 1])
def test_down_the_pit_s_22_degree_ramp_onto_the_floor_without_a_fall(seed: int | None) -> None:
    _walk('ramp_down_22deg', seed)
