"""DRCSim's actionlib server's decisions (actionlib_server.cpp), goal by goal and state by
state, on atlas_msgs' own messages: ego-centric steps made world poses, a short walk padded,
the window re-sent as next_step_index_needed moves, STAND after the last step, success in
Stand; STEP and STAND goals; aborts on errors, nothing while WARNING_AUTO_TRANS."""

from __future__ import annotations

import math

import pytest

atlas = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')

from tutorial_atlas_control.asi import Behavior, Status, WalkDemoServer  # noqa: E402

STAND, WALK = int(Behavior.STAND), int(Behavior.WALK)


def goal_of(behavior: int, steps: int = 0) -> atlas.WalkDemoGoal:
    goal = atlas.WalkDemoGoal(behavior=behavior)
    for k in range(1, steps + 1):
        step = atlas.AtlasBehaviorStepData(step_index=k, foot_index=(k + 1) % 2, duration=0.63)
        step.pose.position.x, step.pose.position.y = 0.2 * k, 0.12 if k % 2 else -0.12
        step.pose.orientation.w = 1.0
        goal.steps.append(step)
    return goal


def state_of(behavior: int = STAND, status: int = Status.OK, current: int = 0,
             needed: int = 0, step_flags: int = 0, error: int = 0,
             at: tuple[float, float] = (0.0, 0.0)) -> atlas.AtlasSimInterfaceState:
    state = atlas.AtlasSimInterfaceState(current_behavior=behavior, error_code=error)
    state.behavior_feedback.status_flags = status
    state.walk_feedback.current_step_index = current
    state.walk_feedback.next_step_index_needed = needed
    state.step_feedback.status_flags = step_flags
    state.pos_est.position.x, state.pos_est.position.y = at
    return state


def queue(command: atlas.AtlasSimInterfaceCommand) -> list[int]:
    return [step.step_index for step in command.walk_params.step_queue]


def test_a_walk_goal_is_streamed_then_stand_then_succeeds() -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    server.on_state(state_of())
    assert server.accept(goal_of(WALK, 8)).commands == []
    first = server.on_state(state_of()).commands
    assert [c.behavior for c in first] == [WALK] and queue(first[0]) == [1, 2, 3, 4]
    assert server.on_state(state_of(WALK, current=0, needed=0)).commands == []
    # The window from the array position next_step_index_needed (DRCSim's: the step
    # indexed one more), at most the last four; sent when that position moves on.
    (window,) = server.on_state(state_of(WALK, current=1, needed=3)).commands
    assert queue(window) == [4, 5, 6, 7]
    assert server.on_state(state_of(WALK, current=1, needed=3)).commands == []
    (window,) = server.on_state(state_of(WALK, current=2, needed=6)).commands
    assert queue(window) == [5, 6, 7, 8]
    (last,) = server.on_state(state_of(WALK, current=7, needed=8)).commands
    assert last.behavior == STAND
    decision = server.on_state(state_of(STAND, Status.TRANSITION_SUCCESS))
    assert decision.succeeded and decision.commands == []


def test_steps_are_turned_by_the_imu_and_moved_by_pos_est_and_a_short_walk_padded() -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    server.on_state(state_of(at=(1.0, 2.0)))
    server.on_imu(0.0, 0.0, math.sin(math.pi / 4), math.cos(math.pi / 4))  # yaw 90 degrees
    server.accept(goal_of(WALK, 2))
    (command,) = server.on_state(state_of(at=(1.0, 2.0))).commands
    steps = command.walk_params.step_queue
    # Step 1, ego (0.2, 0.12), facing +y from (1, 2): world (1 - 0.12, 2 + 0.2).
    assert (steps[0].pose.position.x, steps[0].pose.position.y) == pytest.approx((0.88, 2.2))
    assert steps[0].pose.orientation.z == pytest.approx(math.sin(math.pi / 4))
    # Padded with copies of the step two before, numbered by their slot: 2 and 3.
    assert [s.step_index for s in steps] == [1, 2, 2, 3]
    assert [s.foot_index for s in steps] == [0, 1, 0, 1]
    assert steps[2].pose == steps[0].pose


@pytest.mark.parametrize(('state', 'reason'), [
    (state_of(status=Status.ERROR_FALLING), 'STATUS_ERROR_FALLING'),
    (state_of(status=Status.FAILED_TRANS_COM_POS), 'STATUS_FAILED_TRANS_COM_POS'),
    (state_of(error=-7), 'ERROR_CODE: ERROR_BEHAVIOR_NOT_IMPLEMENTED'),
    (state_of(status=3), 'UNDOCUMENTED STATUS STATE'),
    # A refused STEP (Step is not served yet): the error code's reason, once.
    (state_of(status=Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, error=-7),
     'ERROR_CODE: ERROR_BEHAVIOR_NOT_IMPLEMENTED')])
def test_errors_abort_the_goal(state: atlas.AtlasSimInterfaceState, reason: str) -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    server.accept(goal_of(WALK, 4))
    decision = server.on_state(state)
    assert decision.aborted is not None and reason in decision.aborted
    assert decision.commands == [] and decision.end_state is state
    assert server.on_state(state_of()).commands == []  # nothing runs after it


def test_nothing_happens_while_the_library_warns_of_an_automatic_switch() -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    server.accept(goal_of(WALK, 4))
    decision = server.on_state(state_of(status=Status.WARNING_AUTO_TRANS))
    assert decision.commands == [] and not decision.succeeded and decision.aborted is None


def test_a_walk_of_one_step_is_aborted() -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    decision = server.accept(goal_of(WALK, 1))
    assert decision.aborted == 'Walk goal must contain two or more steps'


def test_a_step_goal_succeeds_on_the_first_swaying_after_stepping() -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    goal = goal_of(int(Behavior.STEP))
    goal.step_params.desired_step.foot_index = 1
    goal.step_params.desired_step.pose.position.x = 0.3
    goal.step_params.desired_step.pose.orientation.w = 1.0
    server.accept(goal)
    (command,) = server.on_state(state_of()).commands
    assert command.behavior == Behavior.STEP and command.step_params.desired_step.step_index == 1
    assert command.step_params.desired_step.pose.position.x == pytest.approx(0.3)
    assert not server.on_state(state_of(Behavior.STEP, step_flags=1)).succeeded
    assert not server.on_state(state_of(Behavior.STEP, step_flags=2)).succeeded
    assert server.on_state(state_of(Behavior.STEP, step_flags=1)).succeeded


def test_a_stand_goal_and_a_new_goal_while_one_runs() -> None:
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    server.accept(goal_of(WALK, 6))
    server.on_state(state_of())
    server.accept(goal_of(STAND))  # while walking: STAND first, then the new goal's own
    (stand,) = server.on_state(state_of(WALK, current=1, needed=5)).commands
    assert stand.behavior == STAND and len(stand.k_effort) == 0
    (again,) = server.on_state(state_of(WALK, current=1, needed=5)).commands
    assert again.behavior == STAND
    assert server.on_state(state_of(STAND, Status.TRANSITION_SUCCESS)).succeeded


def test_a_walk_back_in_stand_before_its_last_step_ends_the_goal() -> None:
    """Ours: DRCSim's padding of a short walk repeats a foot, so our Walk stops there and
    returns to Stand; DRCSim's server would have waited for ever."""
    server = WalkDemoServer(atlas.AtlasSimInterfaceCommand)
    server.accept(goal_of(WALK, 2))
    server.on_state(state_of())
    assert server.on_state(state_of(STAND)).commands == []  # not walking yet: waits
    server.on_state(state_of(WALK, current=2, needed=3))
    assert not server.on_state(state_of(STAND, Status.WARNING_AUTO_TRANS)).succeeded
    assert not server.on_state(state_of(STAND)).succeeded  # the walk seen ending
    assert server.on_state(state_of(STAND)).succeeded
