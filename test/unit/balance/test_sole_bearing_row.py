"""The compiled estimate's bearing summary of each sole (src/atlas_estimator.c's bearings: across
facets or not, the box of its bearing contacts in the sole frame) is what
walking/sole_support.py's Python makes of the sole's contacts, to 1e-9, on recorded swinging
ticks on the course's heightfield; and stance_rule, reading it, decides as on a Python
estimate's state.

The ticks (data/uneven_start_swinging.npz: the robot's qpos, the world's loose blocks left at
the model's qpos0) are every 12th single-support tick of
offline.course_walk(None, (Leg('gate_2', ((-0.24, -10.2),)),),
world_name='vrc_task_2_uneven_start'): nine steps over the heightfield's facets, where the
stance sole is across facets on about half of them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.vrc_world import WORLD_PATH
from tutorial_atlas_control import native
from tutorial_atlas_control.balance.estimator import BalanceEstimator
from tutorial_atlas_control.sim import AtlasModel, load_model
from tutorial_atlas_control.walking import sole_support

TICKS = Path(__file__).resolve().parent / 'data' / 'uneven_start_swinging.npz'
TOLERANCE = 1e-9

pytestmark = pytest.mark.skipif(native.find_library() is None,
                                reason='the compiled library is not built')


@pytest.fixture(scope='module')
def course() -> AtlasModel:
    return load_model(WORLD_PATH)


def _recorded_qpos(atlas: AtlasModel) -> list[np.ndarray]:
    robot = np.load(TICKS)['qpos']
    qpos = np.tile(atlas.model.qpos0, (len(robot), 1))
    qpos[:, :robot.shape[1]] = robot
    return list(qpos)


def test_the_rows_bearing_summary_is_the_python_rules_on_the_course(course: AtlasModel) -> None:
    compiled = BalanceEstimator(course, compiled=True)
    reference = BalanceEstimator(course, compiled=False)
    still = np.zeros(course.model.nv)
    across = single_plane = 0
    for qpos in _recorded_qpos(course):
        state, python = compiled.estimate(qpos, still), reference.estimate(qpos, still)
        assert python.sole_bearing(0) is None
        for foot in (0, 1):
            summary = state.sole_bearing(foot)
            assert summary is not None
            facets = sole_support.across_facets(python, foot)
            assert (summary[0] == 1.0) == facets
            box = sole_support.bearing_span(python, foot)
            if box == sole_support.NO_SPAN:
                assert tuple(summary[1:]) == box
            else:
                np.testing.assert_allclose(summary[1:], box, rtol=0.0, atol=TOLERANCE)
            near, span = sole_support.stance_rule(state, foot, sole_support.SHIFT_M)
            near_python, span_python = sole_support.stance_rule(python, foot,
                                                                sole_support.SHIFT_M)
            assert near == near_python
            np.testing.assert_allclose(span, span_python, rtol=0.0, atol=TOLERANCE)
            if state.in_contact[foot] and not state.in_contact[1 - foot]:
                across += facets
                single_plane += not facets
    # The ticks hold both kinds of stance: the comparison is not of empty boxes.
    assert across >= 50 and single_plane >= 50, (across, single_plane)
