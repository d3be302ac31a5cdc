"""The one phase machine Walk and Step run, without MuJoCo: a phase ends past its shortest time
once its condition holds or at its longest, a swing at touchdown after its duration or
late_touchdown_s past it; Walk swings again while it has steps and catches when it has none
(a stop), Step shifts, swings and settles once; a swing runs from the sole where it lifts to
the step's pose; a walking step's weight transfer lifts the other foot once the landed sole
is flat and carries its share, or at its longest, and the share is the whole-body layer's."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from tutorial_atlas_control.balance.contact_wrench import left_share
from tutorial_atlas_control.walking.footsteps import Footstep
from tutorial_atlas_control.walking.phases import (
    STATIC_STEP_PHASES,
    WALK_PHASES,
    PhaseEnd,
    PhaseSequence,
    WeightTransfer,
    carried_share,
    settled,
    swing_to,
)
from tutorial_atlas_control.walking.status_flags import CATCHING, STEPPING, SWAYING

SWAY, WALK_SWING, CATCH = WALK_PHASES
SHIFT, STEP_SWING, SETTLE = STATIC_STEP_PHASES
#: A swing's duration and how late it may touch down (s), as the walk's defaults.
SWING_S, LATE_S = 0.63, 0.4


@pytest.mark.parametrize(('elapsed_s', 'at_rest', 'ends'), [
    (0.9, True, False),    # at rest, but not yet its shortest time
    (1.0, True, True),     # its shortest time, at rest
    (1.5, False, False),   # not at rest, not yet its longest
    (2.0, False, True),    # its longest: ends at rest or not
])
def test_a_timed_phase_ends_at_rest_after_its_shortest_time_or_at_its_longest(
        elapsed_s: float, at_rest: bool, ends: bool) -> None:
    assert settled(elapsed_s, 1.0, 2.0, at_rest) is ends


@pytest.mark.parametrize(('touching', 'swung_s', 'ends'), [
    (True, 0.62, False),   # down early: the swing runs its duration
    (True, 0.63, True),    # touchdown
    (False, 0.8, False),   # late, still in the air
    (False, 1.03, True),   # late_touchdown_s past its duration: put down where it is
])
def test_a_swing_ends_at_touchdown_or_late(touching: bool, swung_s: float, ends: bool) -> None:
    assert PhaseEnd.swing(SWING_S, LATE_S).ends(swung_s, touching) is ends


def first_ending(sequence: PhaseSequence, start_s: float, condition_from_s: float) -> float:
    """When the phase under way ends, ticking each 1 ms from `start_s`, its condition holding
    from `condition_from_s` on."""
    for tick in range(10_000):
        time_s = start_s + tick * 0.001
        if sequence.ended(time_s, time_s >= condition_from_s):
            return time_s
    raise AssertionError('the phase never ended')


def walk(time_s: float = 0.0) -> PhaseSequence:
    return PhaseSequence(WALK_PHASES, time_s, PhaseEnd(0.6, 0.6))


def test_a_walk_sways_then_swings_to_each_touchdown_while_it_has_steps() -> None:
    phases = walk()
    assert (phases.phase, phases.status) == (SWAY, SWAYING)
    ended_s = first_ending(phases, 0.0, 0.0)
    assert ended_s == pytest.approx(0.6)
    assert phases.following(more_steps=True) is WALK_SWING
    phases.enter(WALK_SWING, ended_s, PhaseEnd.swing(SWING_S, LATE_S))
    assert phases.status == STEPPING
    touchdown_s = first_ending(phases, ended_s, ended_s + 0.3)  # down early: waits
    assert touchdown_s - ended_s == pytest.approx(SWING_S)
    assert phases.following(more_steps=True) is WALK_SWING  # the next step
    phases.enter(WALK_SWING, touchdown_s, PhaseEnd.swing(SWING_S, LATE_S))
    assert phases.elapsed_s(touchdown_s + 0.1) == pytest.approx(0.1)


def test_a_late_touchdown_ends_the_swing_when_the_foot_comes_down() -> None:
    phases = walk()
    phases.enter(WALK_SWING, 1.0, PhaseEnd.swing(SWING_S, LATE_S))
    assert first_ending(phases, 1.0, 1.0 + SWING_S + 0.15) == pytest.approx(
        1.0 + SWING_S + 0.15)


def test_a_swing_that_never_touches_ends_late_touchdown_s_past_its_duration() -> None:
    phases = walk()
    phases.enter(WALK_SWING, 1.0, PhaseEnd.swing(SWING_S, LATE_S))
    assert first_ending(phases, 1.0, 99.0) == pytest.approx(1.0 + SWING_S + LATE_S)


def test_a_walk_stopped_catches_after_its_swing_and_is_done_at_rest() -> None:
    phases = walk()
    phases.enter(WALK_SWING, 1.0, PhaseEnd.swing(SWING_S, LATE_S))
    assert phases.following(more_steps=False) is CATCH  # stopped: no step after this one
    phases.enter(CATCH, 2.0, PhaseEnd(0.6, 3.0))
    assert phases.status == CATCHING
    assert first_ending(phases, 2.0, 3.0) == pytest.approx(3.0)  # at rest after 1 s
    assert phases.following(more_steps=True) is None
    phases.finish()
    assert phases.done and not phases.ended(9.0, True)


def test_a_walk_without_steps_catches_after_its_sway() -> None:
    assert walk().following(more_steps=False) is CATCH


def test_a_catch_never_at_rest_ends_at_its_longest() -> None:
    phases = walk()
    phases.enter(CATCH, 2.0, PhaseEnd(0.6, 3.0))
    assert first_ending(phases, 2.0, 99.0) == pytest.approx(5.0)


def test_a_static_step_shifts_swings_and_settles_once() -> None:
    phases = PhaseSequence(STATIC_STEP_PHASES, 0.0, PhaseEnd(1.0, 2.0))
    assert [(phase.name, phase.status) for phase in STATIC_STEP_PHASES] == [
        ('shift', SWAYING), ('swing', STEPPING), ('settle', SWAYING)]
    assert phases.following(more_steps=True) is STEP_SWING
    phases.enter(STEP_SWING, 1.0, PhaseEnd.swing(SWING_S, LATE_S))
    assert phases.following(more_steps=True) is SETTLE  # Step's swing does not repeat
    phases.enter(SETTLE, 2.0, PhaseEnd(1.0, 2.0))
    assert phases.following(more_steps=True) is None


def test_a_swing_runs_from_the_lifted_sole_to_the_steps_whole_pose() -> None:
    yaw = 0.3
    sole = np.array([[np.cos(yaw), -np.sin(yaw), 0.0], [np.sin(yaw), np.cos(yaw), 0.0],
                     [0.0, 0.0, 1.0]])
    state = SimpleNamespace(sole_centres=np.array([[0.0, 0.12, 0.0], [0.1, -0.12, 0.001]]),
                            sole_rotations=np.array([np.eye(3), sole]))
    step = Footstep(1, 1, 0.4, -0.12, 0.5, z_m=0.15)
    path = swing_to(state, step, 0.7)  # type: ignore[arg-type]
    np.testing.assert_array_equal(path.start, [0.1, -0.12, 0.001])
    np.testing.assert_array_equal(path.end, [0.4, -0.12, 0.15])
    assert (path.start_yaw_rad, path.end_yaw_rad, path.duration_s) == (
        pytest.approx(yaw), 0.5, 0.7)
    state.sole_centres[1, 0] = 9.0
    assert path.start[0] == 0.1  # a copy: the estimate's arrays are not kept


#: The walk's weight transfer: at most 0.1 s, over once the landed sole carries half; the
#: pressure centre over in 0.03 s.
TRANSFER = WeightTransfer(0.1, 0.5, blend_s=0.03)


@pytest.mark.parametrize(('elapsed_s', 'flat', 'share', 'lifts'), [
    (0.02, True, 0.6, True),     # flat and carrying its share: the other foot lifts
    (0.02, False, 0.9, False),   # carrying, but on its heel's edge: both feet stay down
    (0.02, True, 0.3, False),    # flat, but the weight not yet over it
    (0.099, False, 0.0, False),  # neither, not yet the longest
    (0.1, False, 0.0, True),     # the longest: it lifts anyway
])
def test_a_transfer_lifts_the_other_foot_once_the_landed_sole_is_flat_and_carries_its_share(
        elapsed_s: float, flat: bool, share: float, lifts: bool) -> None:
    assert TRANSFER.lifts(elapsed_s, SWING_S, flat, share) is lifts


def test_a_transfer_takes_at_most_a_quarter_of_a_short_step() -> None:
    """The swing keeps the rest: the step still ends on time."""
    assert TRANSFER.longest_for(SWING_S) == pytest.approx(0.1)
    assert TRANSFER.longest_for(0.2) == pytest.approx(0.05)
    assert TRANSFER.lifts(0.05, 0.2, False, 0.0)


def test_a_transfer_moves_the_pressure_centre_smoothly_to_the_laws_in_its_blend() -> None:
    blends = [TRANSFER.blend(tick * 0.001, SWING_S) for tick in range(0, 121)]
    assert blends[0] == 0.0 and blends[15] == pytest.approx(0.5) and blends[30] == 1.0
    assert all(later >= earlier for earlier, later in zip(blends, blends[1:]))
    assert blends[1] < 0.01 and 1.0 - blends[29] < 0.01  # no jump at either end
    assert blends[120] == 1.0
    # Within a short step's longest transfer too.
    assert WeightTransfer(0.1, 0.5, blend_s=0.2).blend(0.05, 0.2) == 1.0


@pytest.mark.parametrize(('cop', 'share'), [
    ((0.0, -0.12), 0.0),    # on the lifting sole's centre
    ((0.3, 0.12), 1.0),     # on the landed one's
    ((0.15, 0.0), 0.5),     # halfway
    ((0.2, 0.08), 0.7317),  # nearly three quarters of the way, a little off the line
    ((0.4, 0.3), 1.0),      # beyond the landed sole: all of it
    ((-0.1, -0.2), 0.0),    # behind the lifting one: none
])
def test_the_landed_soles_share_is_the_pressure_centres_place_between_the_soles(
        cop: tuple[float, float], share: float) -> None:
    lifting, landed = np.array([0.0, -0.12]), np.array([0.3, 0.12])
    assert carried_share(np.array(cop), lifting, landed) == pytest.approx(share, abs=1e-4)


@pytest.mark.parametrize('along', [0.1, 0.3, 0.5, 0.8])
def test_the_landed_soles_share_is_the_whole_body_layers_split_of_the_weight(
        along: float) -> None:
    """balance/contact_wrench.left_share (how the layer shares the weight between two soles)
    gives the landed (left) sole the same share for the weight over the pressure centre."""
    landed, lifting = np.array([0.3, 0.12, 0.0]), np.array([0.0, -0.12, 0.0])
    cop = lifting + along * (landed - lifting)
    middle = 0.5 * (landed + lifting)
    weight = 900.0
    moment_mid = np.cross(cop - middle, [0.0, 0.0, weight])
    share = left_share((0.0, 0.0, weight), tuple(moment_mid), tuple(landed), tuple(lifting))
    assert carried_share(cop[0:2], lifting[0:2], landed[0:2]) == pytest.approx(share)
