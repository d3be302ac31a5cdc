"""Walk through DRCSim's mud (offline/terrain_trial.py): 3 m of the mud_40 case, the feet and
lower legs in mud 0.46 m deep at DRCSim's 40 N s/m, in its 0.15 m strides, from the
deterministic start: every step landed within 5.5 cm of where it was asked (5.03 cm; 4.64
before the weight transfer waited for the landed sole within 1 degree of its surface: the
swings, 12 ms shorter, lag more in the mud), no fall, the pelvis 3 m on (in 0.25 m strides
the landings trailed by up to 20 cm and 7 of 8 seeds fell: the figures over seeds, pushed
and not, are docs/vrc.md's, measured with tools/terrain_walk.py). About 15 s of CPU."""

from __future__ import annotations

import dataclasses

import pytest

from tutorial_atlas_control.offline import TERRAINS, terrain_walk

pytestmark = pytest.mark.offline

STEPS = 20


def test_twenty_steps_through_the_mud_land_where_asked_without_a_fall() -> None:
    case = dataclasses.replace(TERRAINS['mud_40'], steps=STEPS)
    trial = terrain_walk(case, None)
    print(f'figures: steps {trial.steps}, worst landing {trial.worst_landing_m:.4f} m, '
          f'lowest pelvis {trial.lowest_pelvis_m:.3f} m, end {trial.pelvis_end.round(3)}')
    assert not trial.fell
    assert trial.steps == STEPS
    assert trial.worst_landing_m < 0.055
    # The last step brings the feet together at the walk's end, 19 strides on.
    assert trial.pelvis_end[0] == pytest.approx((STEPS - 1) * case.stride_m, abs=0.1)
