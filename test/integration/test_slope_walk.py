"""Walk up and down a slope of 8 degrees (offline/terrain_trial.py's up_8deg and down_8deg,
shortened to 6 steps of 0.2 m), from the deterministic start and seed 1: no fall, every step
landed within 5 cm of where it was asked, the pelvis ending at the walking height over the
slope where the walk ended. Before Walk followed its feet's heights (the CoM height held at
its world height, the feet's tilted surfaces put back flat, omega of the CoM's height over
z 0) every run fell within the first three steps. The 20-step figures over 8 starts, and
16 degrees, are docs/vrc.md's (tools/terrain_walk.py). And 6 steps up 16 degrees whose
surfaces are planned 5 degrees off the ground's, as a height map's can be. About 14 s of CPU."""

from __future__ import annotations

import dataclasses
import math

import pytest

from tutorial_atlas_control.offline import TERRAINS, terrain_walk

pytestmark = pytest.mark.offline

STEPS = 6


def _walk(case_name: str, seed: int | None, surface_error_deg: float = 0.0) -> None:
    case = dataclasses.replace(TERRAINS[case_name], steps=STEPS,
                               surface_error_rad=math.radians(surface_error_deg))
    trial = terrain_walk(case, seed)
    x, _, z = trial.pelvis_end.tolist()
    over_slope = z - x * math.tan(case.slope_rad)  # the floor turned about y through x = 0
    print(f'figures: {case_name} (planes {surface_error_deg:+g} degrees) seed {seed}: '
          f'steps {trial.steps}, fell {trial.fell}, worst landing '
          f'{trial.worst_landing_m:.4f} m, lowest pelvis {trial.lowest_pelvis_m:.3f} m, '
          f'pelvis end {trial.pelvis_end.round(3)}, {over_slope:.3f} m over the slope')
    assert not trial.fell
    assert trial.steps == STEPS
    assert trial.worst_landing_m < 0.05
    # The last step brings the feet together, 5 strides on; the pelvis stands over them.
    assert x == pytest.approx((STEPS - 1) * case.stride_m, abs=0.1)
    assert 0.8 < over_slope < 0.95


@pytest.mark.parametrize('seed', [None, 1])
def test_six_steps_up_8_degrees_land_where_asked_without_a_fall(seed: int | None) -> None:
    _walk('up_8deg', seed)


@pytest.mark.parametrize('seed', [None, 1])
def test_six_steps_down_8_degrees_land_where_asked_without_a_fall(seed: int | None) -> None:
    _walk('down_8deg', seed)


@pytest.mark.parametrize('seed', [None, 1])
@pytest.mark.parametrize('error_deg', [5.0, -5.0])
def test_steps_planned_on_planes_5_degrees_off_a_16_degree_slope_walk(
        error_deg: float, seed: int | None) -> None:
    """A height map's plane a few degrees off the ground's (the course's hills: a footprint
    plane 4.3 degrees off the one its sole came to rest on): each landed sole is held on the
    plane it rests on, not pressed onto the planned one. Pressed onto the planned plane, as
    the transfer did before, every seed fell: after 2 of 6 steps with planes 5 degrees
    steeper (the toe slammed, the sole rolled), after 6 with planes 5 degrees shallower."""
    _walk('up_16deg', seed, error_deg)
