"""AsiSession: which requests switch the behaviour, and the feedback values reported (one
status value at a time, DRCSim 2.7's numbers)."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.asi import AsiError, Behavior, Status
from tutorial_atlas_control.asi.behaviors import MODE_OF_BEHAVIOR
from tutorial_atlas_control.asi.session import REFUSAL_REPORTED_TICKS, AsiSession
from tutorial_atlas_control.control_modes import ControlMode

STAND, USER = Behavior.STAND, Behavior.USER


def test_an_accepted_switch_reports_success_for_one_step_then_ok() -> None:
    session = AsiSession()
    assert session.request(Behavior.FREEZE, STAND, feet_under_com=True) is ControlMode.FREEZE
    assert session.status_flags(Behavior.FREEZE, False) == Status.TRANSITION_SUCCESS == 2
    assert (session.trans_from_behavior, session.trans_to_behavior) == (0, 2)
    assert session.desired_behavior == 2 and session.error_code == AsiError.NO_ERRORS
    session.end_step()
    assert session.status_flags(Behavior.FREEZE, False) == Status.OK


def test_the_running_behaviour_requested_again_changes_nothing() -> None:
    session = AsiSession()
    session.request(Behavior.USER, STAND, True)
    for _ in range(1000):  # a client streaming its request at 1 kHz
        assert session.request(Behavior.USER, USER, feet_under_com=False) is None
    assert session.status_flags(USER, False) == Status.TRANSITION_SUCCESS  # not yet stepped
    session.end_step()
    assert session.request(Behavior.USER, USER, True) is None
    assert session.status_flags(USER, False) == Status.OK


@pytest.mark.parametrize(('behavior', 'status', 'error'), [
    (9, Status.FAILED_TRANS_UNKNOWN_BEHAVIOR, AsiError.NO_SUCH_BEHAVIOR),
    (-1, Status.FAILED_TRANS_UNKNOWN_BEHAVIOR, AsiError.NO_SUCH_BEHAVIOR),
    (Behavior.WALK, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, AsiError.BEHAVIOR_NOT_IMPLEMENTED),
    (Behavior.STEP, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, AsiError.BEHAVIOR_NOT_IMPLEMENTED),
    (Behavior.MANIPULATE, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR,
     AsiError.BEHAVIOR_NOT_IMPLEMENTED),
])
def test_a_refused_request_keeps_the_behaviour_and_says_why_until_a_switch(
        behavior: int, status: Status, error: AsiError) -> None:
    session = AsiSession({Behavior.STAND: ControlMode.STAND, Behavior.USER: ControlMode.USER,
                          Behavior.FREEZE: ControlMode.FREEZE})
    assert session.request(behavior, USER, True) is None
    for _ in range(3):
        session.end_step()
        assert session.status_flags(USER, False) == status
        assert session.error_code == error
    assert session.desired_behavior == behavior
    assert (session.trans_from_behavior, session.trans_to_behavior) == (USER, behavior)
    assert session.request(Behavior.FREEZE, USER, True) is ControlMode.FREEZE
    assert session.error_code == AsiError.NO_ERRORS


def test_stand_is_refused_while_the_centre_of_mass_is_outside_the_feet() -> None:
    session = AsiSession()
    assert session.request(Behavior.STAND, USER, feet_under_com=False) is None
    assert session.status_flags(USER, False) == Status.FAILED_TRANS_COM_POS
    assert session.request(Behavior.STAND, USER, feet_under_com=True) is ControlMode.STAND


def test_falling_is_reported_only_in_a_standing_behaviour_and_alone() -> None:
    session = AsiSession()
    session.request(Behavior.USER, STAND, True)
    assert session.status_flags(USER, falling=True) == Status.TRANSITION_SUCCESS
    assert session.status_flags(STAND, falling=True) == Status.ERROR_FALLING == 256
    session.end_step()
    assert session.status_flags(STAND, falling=False) == Status.OK


def test_a_switch_made_elsewhere_is_reported_as_the_library_s() -> None:
    session = AsiSession()
    session.request(9, STAND, True)
    session.switched(USER, STAND)
    assert session.status_flags(USER, False) == Status.TRANSITION_SUCCESS
    assert session.error_code == AsiError.NO_ERRORS and session.desired_behavior == USER


def test_every_status_is_a_single_value() -> None:
    assert all(status == 0 or status & (status - 1) == 0 for status in Status)


def test_walk_step_and_manipulate_need_a_standing_behaviour_first() -> None:
    served = {**MODE_OF_BEHAVIOR, Behavior.WALK: ControlMode.WALK,
              Behavior.STEP: ControlMode.STEP, Behavior.MANIPULATE: ControlMode.STAND}
    for current in (USER, Behavior.FREEZE, Behavior.STAND_PREP):
        for wanted in (Behavior.WALK, Behavior.STEP, Behavior.MANIPULATE):
            session = AsiSession(served)
            assert session.request(wanted, current, feet_under_com=True) is None
            assert session.status_flags(current, False) == Status.FAILED_TRANS_ILLEGAL_BEHAVIOR
            assert session.error_code == AsiError.FAILED_TO_START_BEHAVIOR
            refusal = session.take_refusal()
            assert refusal is not None and session.take_refusal() is None
            assert refusal.line() == (
                f'refused AtlasSimInterfaceCommand behavior {int(wanted)} ({wanted.name}) in '
                f'{current.name}: FAILED_TRANS_ILLEGAL_BEHAVIOR, {wanted.name} needs Stand: '
                'send STAND (behavior 0) first')
    session = AsiSession(served)
    assert session.request(Behavior.WALK, STAND, True) is ControlMode.WALK
    assert session.take_refusal() is None


@pytest.mark.parametrize(('behavior', 'feet', 'reason'), [
    (9, True, 'not a behaviour (0 STAND, 1 USER, 2 FREEZE, 3 STAND_PREP, 4 WALK, 5 STEP, '
              '6 MANIPULATE)'),
    (Behavior.WALK, True, 'WALK is not served with the stiff hold as Stand (atlas.launch '
                          'stand:=hold): launch with stand:=balance, the default'),
    (Behavior.STAND, False, 'STAND needs the centre of mass over the feet: the robot is down '
                            'or off balance (reset_world, or StandPrep from the harness)'),
])
def test_each_refusal_says_why_and_what_to_do(behavior: int, feet: bool, reason: str) -> None:
    session = AsiSession()
    session.request(behavior, USER, feet_under_com=feet)
    refusal = session.take_refusal()
    assert refusal is not None and refusal.reason == reason
    assert refusal.line().startswith(f'refused AtlasSimInterfaceCommand behavior {behavior} (')


def test_a_refusal_is_answered_by_the_next_request_and_never_latched() -> None:
    session = AsiSession()
    session.request(Behavior.WALK, STAND, True)  # not served here
    session.end_step()
    assert session.status_flags(STAND, False) == Status.FAILED_TRANS_ILLEGAL_BEHAVIOR
    assert session.request(Behavior.STAND, STAND, True) is None  # the running one: fine
    assert session.status_flags(STAND, False) == Status.OK
    assert session.error_code == AsiError.NO_ERRORS
    # Unanswered, it is reported for REFUSAL_REPORTED_TICKS ticks, then no more.
    session.request(Behavior.WALK, STAND, True)
    for _ in range(REFUSAL_REPORTED_TICKS - 1):
        session.end_step()
    assert session.status_flags(STAND, False) == Status.FAILED_TRANS_ILLEGAL_BEHAVIOR
    session.end_step()
    assert session.status_flags(STAND, False) == Status.OK
    assert session.error_code == AsiError.NO_ERRORS


def test_a_new_request_leaves_a_transition_under_way_reported() -> None:
    session = AsiSession()
    session.defer(Behavior.STAND, Behavior.WALK)
    assert session.request(Behavior.WALK, Behavior.WALK, True) is None
    assert session.status_flags(Behavior.WALK, False) == Status.TRANSITION_IN_PROGRESS
