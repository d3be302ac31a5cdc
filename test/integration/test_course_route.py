"""offline/course_route.py: a streamed walk along a route on the VRC course, scored, as
tools/course_walk.py measures the walk to gate_1 (docs/vrc.md). Here a short route from the
pen's start (DRCSim's bdi_stand start, Stand from 2 s, the walk planned at 3 s from
foot_pos_est): four 0.1 m strides east on the pen's floor (from the foot links' midpoint,
a few centimetres behind the pelvis), which the robot must walk to the end without a fall,
its pelvis brought to the route's end (within 5 cm), no gate passed, its closest call far
from a fall. About 20 s of CPU at a
load of 4 (the course's physics)."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.course import Leg
from tutorial_atlas_control.offline import course_walk
from tutorial_atlas_control.walking import RouteGait

pytestmark = pytest.mark.offline

#: The pen's start is at (-3.0, -38.0), facing east.
ROUTE = (Leg('gate_0', ((-2.65, -38.0),)),)


def test_a_short_route_in_the_pen_is_walked_to_its_end() -> None:
    walk = course_walk(None, ROUTE, gait=RouteGait(stride_m=0.1), stand_after_s=1.0)
    assert walk.outcome == 'walked' and walk.legs_walked == 1, walk
    assert walk.steps_taken == walk.steps_planned
    assert walk.steps_planned in (5, 6)  # four or five strides, then the feet together
    assert walk.fell_at_s is None and walk.scorer_falls == 0, walk
    assert walk.gates == () and walk.completion == 0
    # Its one leg's closest call: the pelvis near its standing height, the capture point
    # no further from the soles than a calm walk's lead towards the next step (0.175 m).
    (leg,) = walk.legs
    assert leg.gate == 'gate_0' and walk.variant == 'qualification'
    assert 0.75 < leg.lowest_pelvis_m < 0.95, leg
    assert 0.05 < leg.widest_capture_m < 0.25, leg
    x, y = walk.pelvis_xy
    assert x == pytest.approx(-2.65, abs=0.05)
    assert y == pytest.approx(-38.0, abs=0.05)
