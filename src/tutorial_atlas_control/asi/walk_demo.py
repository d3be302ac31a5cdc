"""DRCSim 2.7's actionlib front end to the AtlasSimInterface (actionlib_server.cpp), ROS-free:
what it does with each goal and each AtlasSimInterfaceState.

Kept as DRCSim had it, quirks included: a goal's steps are ego-centric, turned into the
pos_est frame by the pelvis's estimated x, y and the IMU's yaw when the goal arrives;
a WALK goal of fewer than four steps is padded with copies of the step two before (their
step_index the slot's position); the first four steps are sent, then the window starting at
the array position next_step_index_needed (at most the last four) each time that moves; once
current_step_index reaches the number of steps less one, STAND is sent; the goal succeeds
when a state says Stand. A STEP goal sends one STEP and succeeds on the first SWAYING after
STEPPING; STAND and STAND_PREP goals send their behaviour and succeed when it is reported;
USER and FREEZE goals send nothing. An error code or a FAILED_TRANS_* or ERROR_FALLING
status aborts the goal; while WARNING_AUTO_TRANS is reported nothing else happens. A new goal
while one runs sends STAND first. Ours: a WALK goal of fewer than two steps is aborted (DRCSim
left it active forever); a walk that returns to Stand before its last step (the padded copies
of a short walk repeat a foot: the walk stops there) ends the goal as the last step would
(DRCSim's waited for ever); MANIPULATE goals are sent (DRCSim only logged "not yet
implemented").

The messages are the node's (atlas_msgs' genpy classes): this module reads their fields and
fills a command made by `new_command`, so it needs neither rospy nor the workspace.
"""

from __future__ import annotations

import copy
import math
from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Any

from tutorial_atlas_control.asi.behaviors import AsiError, Behavior, Status
from tutorial_atlas_control.walking import QUEUE_LENGTH, STEPPING, SWAYING

__all__ = ['Decision', 'WalkDemoServer']

_ABORTING_STATUS = frozenset({Status.FAILED_TRANS_UNKNOWN_BEHAVIOR,
                              Status.FAILED_TRANS_ILLEGAL_BEHAVIOR, Status.FAILED_TRANS_COM_POS,
                              Status.FAILED_TRANS_COM_VEL, Status.FAILED_TRANS_VEL,
                              Status.ERROR_FALLING})
_PASSING_STATUS = frozenset({Status.OK, Status.TRANSITION_IN_PROGRESS,
                             Status.TRANSITION_SUCCESS})


@dataclass
class Decision:
    """What one state or goal asks the node to do, in order: publish `commands`, then end
    the goal (`succeeded`, or `aborted` with its reason) with `end_state`."""

    commands: list[Any] = field(default_factory=list)
    succeeded: bool = False
    aborted: str | None = None
    end_state: Any = None


def yaw_of_quaternion(x: float, y: float, z: float, w: float) -> float:
    return math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))


def _multiply(a: tuple[float, float, float, float],
              b: tuple[float, float, float, float]) -> tuple[float, float, float, float]:
    ax, ay, az, aw = a
    bx, by, bz, bw = b
    return (aw * bx + ax * bw + ay * bz - az * by, aw * by - ax * bz + ay * bw + az * bx,
            aw * bz + ax * by - ay * bx + az * bw, aw * bw - ax * bx - ay * by - az * bz)


class WalkDemoServer:
    """The server's state between goals and states; `new_command` makes an empty
    atlas_msgs/AtlasSimInterfaceCommand."""

    def __init__(self, new_command: Callable[[], Any]) -> None:
        self.new_command = new_command
        self.goal: Any = None
        self.active = False
        self.new_goal = False
        self.executing = False
        self.current_step_index = 0
        self.stepping = False
        #: The walk of the goal has been reported (ours: to see it end early).
        self.walk_seen = False
        #: The pelvis's estimated position (pos_est) and the IMU's yaw.
        self.robot_xy = (0.0, 0.0)
        self.robot_yaw = 0.0

    # -- inputs ---------------------------------------------------------------------------
    def on_imu(self, x: float, y: float, z: float, w: float) -> None:
        """AtlasState's orientation: the robot's yaw for the next goal's steps."""
        self.robot_yaw = yaw_of_quaternion(x, y, z, w)

    def accept(self, goal: Any) -> Decision:
        """A new WalkDemoGoal (a copy is kept; its step poses made world poses)."""
        goal = copy.deepcopy(goal)
        self.goal, self.active, self.new_goal = goal, True, True
        if goal.behavior == Behavior.WALK:
            if len(goal.steps) < 2:
                return self._abort('Walk goal must contain two or more steps', None)
            for step in goal.steps:
                self._to_world(step.pose)
            self.current_step_index = 0
            while len(goal.steps) < QUEUE_LENGTH:
                i = len(goal.steps)
                repeat = copy.deepcopy(goal.steps[i - 2])
                repeat.step_index = i
                goal.steps.append(repeat)
        elif goal.behavior == Behavior.STEP:
            self.stepping = False
            self._to_world(goal.step_params.desired_step.pose)
        self.walk_seen = False
        return Decision()

    def preempted(self) -> None:
        """The client cancelled the goal (the node has told actionlib)."""
        self.active = False

    def on_state(self, state: Any) -> Decision:
        """One AtlasSimInterfaceState."""
        self.robot_xy = (state.pos_est.position.x, state.pos_est.position.y)
        decision = Decision(end_state=state)
        if state.error_code != AsiError.NO_ERRORS:
            decision = self._abort(f'ActionServer: ERROR_CODE: {_error_name(state.error_code)}',
                                   state)
        status = state.behavior_feedback.status_flags
        if decision.aborted is not None and status not in _PASSING_STATUS:
            return decision  # aborted once, for the error code
        if status in _ABORTING_STATUS:
            return self._abort('ActionServer: AtlasBehaviorFeedback error: '
                               f'STATUS_{Status(status).name}', state)
        if status == Status.WARNING_AUTO_TRANS:
            return decision
        if status not in _PASSING_STATUS:
            return self._abort('UNDOCUMENTED STATUS STATE', state)
        goal = self.goal
        if (goal is not None and state.current_behavior == Behavior.STAND
                and goal.behavior == Behavior.WALK and self.active
                and not self.new_goal and not self.executing):
            self.active = False
            decision.succeeded = True
        if self.new_goal and self.executing:
            decision.commands.append(self._bare(Behavior.STAND))
            self.executing = False
        elif self.new_goal:
            self.new_goal, self.executing = False, True
            decision.commands.extend(self._start())
        elif self.executing:
            self._follow(state, decision)
        return decision

    # -- what each goal does --------------------------------------------------------------
    def _start(self) -> list[Any]:
        goal = self.goal
        if goal.behavior == Behavior.WALK:
            return [self._walk_command(0)]
        if goal.behavior == Behavior.STEP:
            command = self._bare(Behavior.STEP)
            wanted, step = goal.step_params.desired_step, command.step_params.desired_step
            step.step_index, step.foot_index = 1, wanted.foot_index
            step.pose = copy.deepcopy(wanted.pose)
            self.stepping = False
            return [command]
        if goal.behavior in (Behavior.STAND, Behavior.STAND_PREP):
            return [self._bare(goal.behavior)]
        if goal.behavior == Behavior.MANIPULATE:
            return [self._command(Behavior.MANIPULATE)]
        return []  # USER, FREEZE: nothing sent

    def _follow(self, state: Any, decision: Decision) -> None:
        goal = self.goal
        if goal.behavior == Behavior.WALK:
            walk = state.walk_feedback
            if state.current_behavior == Behavior.WALK:
                self.walk_seen = True
            elif self.walk_seen:  # ours: the walk ended before its last step (Stand by itself)
                self.executing = False
                return
            if walk.current_step_index >= len(goal.steps) - 1:
                decision.commands.append(self._command(Behavior.STAND))
                self.executing = False
                return
            start = min(walk.next_step_index_needed, len(goal.steps) - QUEUE_LENGTH)
            if self.current_step_index < start:
                decision.commands.append(self._walk_command(start))
        elif goal.behavior == Behavior.STEP:
            flags = state.step_feedback.status_flags
            if self.active and flags == SWAYING and self.stepping:
                self.stepping, self.active, self.executing = False, False, False
                decision.succeeded = True
            elif flags == STEPPING:
                self.stepping = True
        elif goal.behavior in (Behavior.STAND, Behavior.STAND_PREP):
            if self.active and state.current_behavior == goal.behavior:
                self.active, self.executing = False, False
                decision.succeeded = True

    def _walk_command(self, start: int) -> Any:
        """WALK with the goal's steps from array position `start`."""
        self.current_step_index = start
        command = self._command(Behavior.WALK)
        for slot, step in enumerate(self.goal.steps[start:start + QUEUE_LENGTH]):
            command.walk_params.step_queue[slot] = copy.deepcopy(step)
        return command

    def _bare(self, behavior: int) -> Any:
        """A command for `behavior` with the goal's header only (no k_effort: the blend
        stays), as DRCSim's server built its STAND, STAND_PREP and STEP commands."""
        command = self.new_command()
        command.header = copy.deepcopy(self.goal.header)
        command.behavior = int(behavior)
        return command

    def _command(self, behavior: int) -> Any:
        """A command for `behavior` with the goal's header, k_effort and parameters."""
        command, goal = self.new_command(), self.goal
        command.header = copy.deepcopy(goal.header)
        command.behavior = int(behavior)
        command.k_effort = goal.k_effort
        command.step_params = copy.deepcopy(goal.step_params)
        command.stand_params = copy.deepcopy(goal.stand_params)
        command.manipulate_params = copy.deepcopy(goal.manipulate_params)
        return command

    def _abort(self, reason: str, state: Any) -> Decision:
        self.executing = self.new_goal = False
        if not self.active:
            return Decision(end_state=state)
        self.active = False
        return Decision(aborted=reason, end_state=state)

    def _to_world(self, pose: Any) -> None:
        """An ego-centric pose made a world pose: turned by the IMU's yaw, moved by the
        pelvis's x, y (its z is kept)."""
        c, s = math.cos(self.robot_yaw), math.sin(self.robot_yaw)
        x, y = pose.position.x, pose.position.y
        pose.position.x = self.robot_xy[0] + c * x - s * y
        pose.position.y = self.robot_xy[1] + s * x + c * y
        o = pose.orientation
        norm = math.sqrt(o.x * o.x + o.y * o.y + o.z * o.z + o.w * o.w) or 1.0
        half = 0.5 * self.robot_yaw
        turned = _multiply((0.0, 0.0, math.sin(half), math.cos(half)),
                           (o.x / norm, o.y / norm, o.z / norm, o.w / norm))
        o.x, o.y, o.z, o.w = turned


def _error_name(code: int) -> str:
    try:
        return f'ERROR_{AsiError(code).name}'
    except ValueError:
        return 'UNDOCUMENTED ERROR'
