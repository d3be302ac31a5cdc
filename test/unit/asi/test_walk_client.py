"""A DRC-era walking client's decisions, state by state: the streamed window from
next_step_index_needed, the one-shot queue sent once, and how the walk ended."""

from __future__ import annotations

import pytest

from tutorial_atlas_control.asi import AsiInputError
from tutorial_atlas_control.asi.behaviors import Behavior, Status
from tutorial_atlas_control.asi.walk_client import Outcome, WalkClient, refusal_hint
from tutorial_atlas_control.errors import AtlasControlError
from tutorial_atlas_control.walking import Footstep, straight_steps

PLAN = straight_steps(6, 0.25)
STAND, WALK = int(Behavior.STAND), int(Behavior.WALK)


def indices(steps: list[Footstep] | None) -> list[int] | None:
    return None if steps is None else [step.step_index for step in steps]


def test_a_streaming_client_sends_its_window_on_every_state_until_back_in_stand() -> None:
    client = WalkClient(PLAN)
    assert indices(client.on_state(STAND, Status.OK, 0, 0)) == [1, 2, 3, 4]
    assert indices(client.on_state(STAND, Status.OK, 0, 0)) == [1, 2, 3, 4]  # every state
    assert indices(client.on_state(WALK, Status.TRANSITION_SUCCESS, 0, 1)) == [1, 2, 3, 4]
    assert indices(client.on_state(WALK, Status.OK, 1, 5)) == [5, 6]
    assert indices(client.on_state(WALK, Status.OK, 6, 7)) == []
    assert client.on_state(STAND, Status.WARNING_AUTO_TRANS, 0, 0) is None
    assert client.outcome is Outcome.WALKED and client.steps_taken == 6
    assert client.on_state(STAND, Status.WARNING_AUTO_TRANS, 0, 0) is None


def test_a_one_shot_client_sends_four_steps_once() -> None:
    client = WalkClient(PLAN, streaming=False)
    assert indices(client.on_state(STAND, Status.OK, 0, 0)) == [1, 2, 3, 4]
    assert client.on_state(STAND, Status.OK, 0, 0) is None
    assert client.on_state(WALK, Status.OK, 2, 5) is None
    client.on_state(STAND, Status.WARNING_AUTO_TRANS, 0, 0)
    assert client.outcome is Outcome.WALKED and client.steps_taken == 2


@pytest.mark.parametrize(('status', 'outcome'), [
    (Status.ERROR_FALLING, Outcome.FELL),
    (Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, Outcome.REFUSED),
    (Status.FAILED_TRANS_COM_POS, Outcome.REFUSED)])
def test_a_fall_or_a_refusal_ends_the_walk(status: Status, outcome: Outcome) -> None:
    client = WalkClient(PLAN)
    assert client.on_state(STAND, Status.OK, 0, 0) is not None  # its request
    assert client.on_state(STAND, status, 0, 0) is None
    assert client.outcome is outcome


def test_a_refusal_before_its_own_request_is_somebody_elses() -> None:
    client = WalkClient(PLAN)
    assert indices(client.on_state(STAND, Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, 0, 0)) == [
        1, 2, 3, 4]
    assert client.outcome is None


@pytest.mark.parametrize(('status', 'behavior', 'hint'), [
    (Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, Behavior.USER, 'WALK needs Stand; send STAND first'),
    (Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, Behavior.STAND, 'stand:=hold'),
    (Status.FAILED_TRANS_COM_POS, Behavior.STAND, '/gazebo/reset_world'),
    (Status.ERROR_FALLING, Behavior.WALK, 'the robot fell'),
    (999, Behavior.STAND, 'status 999')])
def test_a_refusal_is_said_with_what_to_do(status: int, behavior: Behavior, hint: str) -> None:
    assert hint in refusal_hint(status, behavior)


def test_a_plan_must_number_its_steps_from_one() -> None:
    with pytest.raises(ValueError, match='steps 1, 2'):
        WalkClient(PLAN[1:])


def test_a_plan_out_of_order_raises_the_asis_input_error() -> None:
    with pytest.raises(AsiInputError, match='a plan is steps 1, 2, ... in order') as raised:
        WalkClient(PLAN[::-1])
    assert isinstance(raised.value, AtlasControlError)  # what the command lines catch
