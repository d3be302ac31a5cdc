"""Stand holds the feet where a walk or a step left them, offline and deterministic: in every
stance Walk, Step or a stopped walk leaves (side by side, staggered 0.2, 0.25 and 0.4 m either
foot behind, one foot turned 0.3 rad), made through the AtlasSimInterface as a client makes
it, no sole turns or slides on the ground while the balancing Stand holds the robot.

The issue's bound is 0.02 rad and 1 cm over 60 s. A stance costs about 0.45 s of CPU per
second of Stand (the interface included), so 60 s of each of the five would add some 140 s
to `make test`; each runs 5 s instead, against a twelfth of the bound (1.7 mrad, 0.8 mm).
That is the stricter test, not an extrapolation: where a sole creeps it creeps fastest at
first (Stand's old posture, DRCSim's queue: 0.32 rad in the first 20 s, 0.51 rad in 60 s),
and the fixed Stand's creep is steady and far below it (docs/controllers.md has both
figures for every stance over 60 s). Planted once: with the Stand pose's legs in every
stance (the posture PD pulling a staggered or turned stance's legs to it), every stance
fails. About 15 s of CPU in all.
"""

from __future__ import annotations

import pytest

from support.stances import STANCES, hold, stand_in
from tutorial_atlas_control.sim import AtlasModel, load_model

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority beside
#: the serial tests, on the CPU they leave idle.
pytestmark = pytest.mark.offline

#: The issue's bounds over 60 s (rad, m), and the shorter hold they are scaled to (s).
TURN_BOUND_RAD = 0.02
SLIDE_BOUND_M = 0.01
BOUND_S = 60.0
HOLD_S = 5.0
#: The pelvis of a robot Stand holds stays above this (m; Step leaves it 5 cm low).
PELVIS_ABOVE_M = 0.84


@pytest.fixture(scope='module')
def atlas() -> AtlasModel:
    return load_model()


@pytest.mark.parametrize('stance', list(STANCES))
def test_stand_holds_both_feet_where_they_were_left(atlas: AtlasModel, stance: str) -> None:
    interface = stand_in(atlas, stance)
    held = hold(interface, HOLD_S)
    share = HOLD_S / BOUND_S
    assert held.turned_rad.max() < share * TURN_BOUND_RAD, held
    assert held.slid_m.max() < share * SLIDE_BOUND_M, held
    assert held.lowest_pelvis_m > PELVIS_ABOVE_M
