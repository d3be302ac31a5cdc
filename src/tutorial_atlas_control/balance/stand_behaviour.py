"""The balancing Stand as the simulator's Stand behaviour (sim/behaviour.py's protocol), and
Manipulate's pelvis servo on top of it.

On start it holds the robot where it stands (StandReference.from_state: the capture point
over the soles' midpoint, the pelvis upright at its yaw) and, over TRANSITION_S, brings the
posture and the centre-of-mass height from where they are to DRCSim's Stand pose carried to
the stance the feet are in (stance_posture: the legs that reach the soles where they lie; the
Stand pose's own, pulled to by the legs' posture PD in a staggered or turned stance, pushed
the soles against each other and turned one on the ground) (a smoothstep: no jump in the
reference, none in the torque). A robot taken over standing straight under the hold thus
bends its knees instead of fighting it.
`servo` moves the reference the same way to a pelvis height, yaw and lateral offset
(Manipulate, balance/manipulate.py), or back to the Stand pose (carried to the stance).
Each tick it estimates the
state from the simulator's MjData and returns the controller's torque, which the simulator
blends with the user's PID by k_effort as f_out.
"""

from __future__ import annotations

import dataclasses
import functools
import math

import mujoco
import numpy as np

from tutorial_atlas_control.balance.blend import smoothstep, smoothstep_rate
from tutorial_atlas_control.balance.compiled_whole_body import JOINTS_IN_CALL
from tutorial_atlas_control.balance.errors import BalanceError
from tutorial_atlas_control.balance.estimator import BalanceEstimator, BalanceState
from tutorial_atlas_control.balance.manipulate import (
    PelvisServo,
    SquatTable,
    clamp_servo,
)
from tutorial_atlas_control.balance.stance_posture import StancePosture
from tutorial_atlas_control.balance.stand import (
    StandController,
    StandGains,
    StandOutput,
    StandReference,
    pelvis_frame,
    pitch_of,
    yaw_of,
    yaw_rotation,
)
from tutorial_atlas_control.balance.stand_pose import place_in_stand_pose
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import AtlasModel, Ground

__all__ = ['TRANSITION_S', 'StandBehaviour', 'stand_pose_com_height_m']

#: How long Stand takes to bring the robot from where it starts to the Stand pose (s).
TRANSITION_S = 1.0
#: A start whose legs are further than this from the Stand pose's on some joint (rad) is a
#: take-over (the hold's straight legs: the knees 0.52 rad off), which Walk and Step wait for.
TAKE_OVER_RAD = 0.1
_LEGS = np.array([index for index, name in enumerate(JOINT_NAMES) if '_leg_' in name])


def stand_pose_com_height_m(atlas: AtlasModel) -> float:
    """The centre of mass's height (m) of the robot in the Stand pose above the ground its
    flat feet stand on (the robot's own: a world's loose bodies are not the robot)."""
    data = mujoco.MjData(atlas.model)
    place_in_stand_pose(atlas, data)
    mujoco.mj_comPos(atlas.model, data)
    return float(data.subtree_com[atlas.pelvis_body_id][2])


_UP = np.array([0.0, 0.0, 1.0])


def _still(size: int) -> np.ndarray:
    """Zeros that cannot be written: a reference's rates while it moves without them."""
    zeros = np.zeros(size)
    zeros.setflags(write=False)
    return zeros


#: A take-over's reference's pelvis angular velocity and posture rates: the same read-only
#: zeros every tick (the whole-body call copies a rate only when it is another array).
_STILL_TURN, _STILL_POSTURE = _still(3), _still(len(JOINT_NAMES))


def _as_vector(reference: StandReference) -> np.ndarray:
    """A reference's posture (28,), pelvis pitch and CoM height as one (30,) vector, the
    squat table's row layout."""
    return np.concatenate([reference.posture_rad,
                           (pitch_of(reference.pelvis_rotation), reference.com_height_m)])


@dataclasses.dataclass(frozen=True)
class _Transition:
    """The reference moving from `start` to `goal` over transition_s from `started_s`; with
    `table` (the pelvis heights from and to, and the squat table's rows there), along the
    squat table between those heights. Once there, the reference is the table's posture at
    `end_height_m` (None: off the table)."""

    started_s: float
    start: StandReference
    goal: StandReference
    table: tuple[float, float, np.ndarray, np.ndarray] | None = None
    end_height_m: float | None = None
    #: Whether the reference carries its rates (Manipulate's moves; not start()'s, whose
    #: slow straightening the walking figures were measured from).
    with_rates: bool = True

    @functools.cached_property
    def vectors(self) -> tuple[np.ndarray, np.ndarray]:
        return _as_vector(self.start), _as_vector(self.goal)

    @functools.cached_property
    def capture_points(self) -> tuple[float, float, float, float]:
        """The start's and the goal's capture points (x, y each) as floats."""
        return (*self.start.capture_point.tolist(), *self.goal.capture_point.tolist())

    @functools.cached_property
    def yaws(self) -> tuple[float, float]:
        """(the start's yaw, the shorter turn to the goal's) (rad)."""
        start_yaw = yaw_of(self.start.pelvis_rotation)
        turn = (yaw_of(self.goal.pelvis_rotation) - start_yaw + np.pi) % (2 * np.pi) - np.pi
        return start_yaw, turn


_new_object = object.__new__


def _reference_without_rates(capture_point: np.ndarray, com_height_m: float,
                             pelvis_rotation: np.ndarray,
                             posture_rad: np.ndarray) -> StandReference:
    """StandReference(capture_point, com_height_m, pelvis_rotation, posture_rad) without the
    frozen dataclass's __init__ (an object.__setattr__ a field, its defaults' factories
    called through it), its zero rates shared read-only arrays: every tick of a take-over."""
    reference = _new_object(StandReference)
    reference.__dict__.update(
        capture_point=capture_point, com_height_m=com_height_m,
        pelvis_rotation=pelvis_rotation, posture_rad=posture_rad, com_height_rate_m_s=0.0,
        pelvis_angular_velocity=_STILL_TURN,
        posture_rate_rad_s=(_STILL_POSTURE if len(posture_rad) == len(_STILL_POSTURE)
                            else np.zeros(len(posture_rad))))
    return reference


class StandBehaviour:
    """Capture-point Stand for one simulator's robot."""

    def __init__(self, atlas: AtlasModel, gains: StandGains | None = None,
                 transition_s: float = TRANSITION_S) -> None:
        self.atlas = atlas
        self.gains = gains
        self.transition_s = transition_s
        self.estimator = BalanceEstimator(atlas)
        self.com_height_m = stand_pose_com_height_m(atlas)
        self.controller: StandController | None = None
        #: The last tick's state and decision (None before the first), for feedback.
        self.last_state: BalanceState | None = None
        self.last_output: StandOutput | None = None
        #: Manipulate's pelvis target as clamped (None: the Stand pose).
        self.servo_target: PelvisServo | None = None
        #: How many times Stand has started (a restart drops the servo target).
        self.starts = 0
        #: The reference moving on; None once it has arrived.
        self._transition: _Transition | None = None
        #: Since a start() with the legs far from the Stand pose (TAKE_OVER_RAD), bringing
        #: them there: Walk and Step wait for it.
        self.taking_over = False
        #: The pelvis height (m) of the squat table's posture the reference is at or passing
        #: through (None: off the table, as after start()).
        self._table_height_m: float | None = None
        self._ground: Ground | None = None
        #: The MjData torque() was last given and its qpos, qvel views (the binding makes a
        #: new view at each attribute read; MjData's arrays never move).
        self._vectors: tuple[mujoco.MjData, np.ndarray, np.ndarray] | None = None

    @functools.cached_property
    def stand_height_m(self) -> float:
        """The pelvis height (m) of the Stand pose on flat ground."""
        return place_in_stand_pose(self.atlas, mujoco.MjData(self.atlas.model))

    @functools.cached_property
    def stance(self) -> StancePosture:
        """The Stand pose's legs solved for the stance the feet are in."""
        return StancePosture(self.atlas)

    def stance_reference(self, state: BalanceState, pelvis_yaw_rad: float
                         ) -> tuple[np.ndarray, float]:
        """(posture (28,), CoM height (m)): DRCSim's Stand pose with its legs where they
        are with the soles as they lie and the pelvis upright at `pelvis_yaw_rad`, lowered
        where they do not reach: the Stand pose itself with the feet side by side as it
        puts them; staggered or turned, legs that reach the soles (the Stand pose's would
        push them against each other, and turn one on the ground)."""
        stance = self.stance.stance(state.sole_centres, state.sole_rotations, pelvis_yaw_rad)
        return (stance.posture_rad,
                self.ground_under_m(state) + self.com_height_m - stance.com_lowered_m)

    def ground_under_soles(self, state: BalanceState
                           ) -> tuple[tuple[float, tuple[float, float, float]], ...]:
        """The ground's height (m) and unit normal under each sole's centre (left, right):
        the level ground's own where the world is level planes (no rays: z 0 and upright in
        Atlas's world); 0 and upright off any ground. Walk's feet stand on these."""
        if self._ground is None:
            raise BalanceError('StandBehaviour.ground_under_soles before start()')
        ground, upright = self._ground, (0.0, 0.0, 1.0)
        if ground.level_m is not None:
            return (ground.level_m, upright), (ground.level_m, upright)
        under = []
        for x, y in state.sole_centres[:, :2].tolist():
            height, normal, geom = ground.hit(x, y)
            under.append((height, tuple(normal.tolist())) if geom >= 0 and math.isfinite(height)
                         else (0.0, upright))
        return tuple(under)

    def ground_under_m(self, state: BalanceState) -> float:
        """The ground's height (m) under the soles' centres, their mean: the Stand's heights
        are over the world's ground, which is not z = 0 everywhere (0 off any ground)."""
        if self._ground is None:
            raise BalanceError('StandBehaviour.ground_under_m before start()')
        heights = [self._ground.height_m(x, y) for x, y in state.sole_centres[:, :2].tolist()]
        found = [height for height in heights if math.isfinite(height)]
        return sum(found) / len(found) if found else 0.0

    @functools.cached_property
    def squats(self) -> SquatTable:
        """Manipulate's reach and postures, built when first servoed (not every Stand is)."""
        return SquatTable(self.atlas)

    def start(self, data: mujoco.MjData) -> None:
        """Stand where the robot stands now, going to the Stand pose over transition_s."""
        if self._ground is None:  # the world's, its loose bodies where `data` has them
            self._ground = Ground(self.atlas.model, data)
        state = self.estimator.estimate(data.qpos, data.qvel)
        held = StandReference.from_state(state, posture_rad=data.qpos[self.atlas.qpos_adr])
        self.controller = StandController(
            self.estimator.mass_kg, self.atlas.effort_limit_nm, held,
            self.estimator.sole_half_size_m, self.gains)
        self.servo_target = None
        self.starts += 1
        posture, com_height = self.stance_reference(state, yaw_of(held.pelvis_rotation))
        self._transition = _Transition(float(data.time), held, dataclasses.replace(
            held, com_height_m=com_height, posture_rad=posture),
            end_height_m=self.stand_height_m, with_rates=False)
        self._table_height_m = None
        self.last_state = state
        self.last_output = None
        self.taking_over = bool(np.max(np.abs(held.posture_rad[_LEGS] - posture[_LEGS]))
                                > TAKE_OVER_RAD)

    def servo(self, desired: PelvisServo | None, time_s: float) -> PelvisServo | None:
        """Move the pelvis to `desired` (clamped to what the legs reach; None: back to the
        Stand pose) over transition_s from the present reference; the target as clamped.
        The same target again changes nothing (a client may stream it)."""
        target = None if desired is None else clamp_servo(desired, self.squats)
        if target == self.servo_target:
            return target
        controller, state = self.controller, self.last_state
        if controller is None or state is None:
            raise BalanceError('StandBehaviour.servo before start()')
        feet = state.sole_centres[:, :2]
        headings = state.sole_rotations[:, 0:2, 0].sum(axis=0)
        feet_yaw = float(np.arctan2(headings[1], headings[0]))
        left = feet[0] - feet[1]
        left /= np.linalg.norm(left)
        table = self.squats
        goal_height = table.stand_height_m if target is None else target.height_m
        if target is None:
            posture, com_height = self.stance_reference(state, feet_yaw)
            goal = StandReference(feet.mean(axis=0), com_height, yaw_rotation(feet_yaw),
                                  posture)
        else:
            goal = StandReference(
                feet.mean(axis=0) + target.lateral_m * left,
                self.ground_under_m(state) + self.squats.com_for(target.height_m),
                pelvis_frame(feet_yaw + target.yaw_rad, self.squats.pitch_for(target.height_m)),
                self.squats.posture_for(target.height_m, target.yaw_rad))
        table_path = None
        if self._table_height_m is not None:
            table_path = (self._table_height_m, goal_height,
                          table.row(self._table_height_m)[0], table.row(goal_height)[0])
        self._transition = _Transition(time_s, controller.reference, goal, table_path,
                                       goal_height)
        self.taking_over = False
        self.servo_target = target
        return target

    def _reference_at(self, time_s: float) -> StandReference:
        """The moving reference at `time_s`, with its rates; its goal once the transition's
        duration has passed."""
        transition = self._transition
        assert transition is not None
        duration = self.transition_s
        fraction = (time_s - transition.started_s) / duration if duration > 0.0 else 1.0
        if fraction >= 1.0:
            self._transition = None
            self.taking_over = False
            self._table_height_m = transition.end_height_m
            return transition.goal
        s = smoothstep(fraction)
        start, goal = transition.vectors
        vector = (1.0 - s) * start + s * goal
        per_s = None  # d(vector)/ds: goal - start, made where it is read
        self._table_height_m = None
        if transition.table is not None:
            # Along the squat table rather than straight across it, so that the posture,
            # the pelvis pitch and the CoM height stay those of one squat all the way.
            low, high, low_row, high_row = transition.table
            height = (1.0 - s) * low + s * high
            row, slope = self.squats.row(height)
            vector += row - ((1.0 - s) * low_row + s * high_row)
            per_s = goal - start
            per_s += slope * (high - low) - (high_row - low_row)
            self._table_height_m = height
        start_yaw, turn = transition.yaws
        yaw, pitch = start_yaw + s * turn, float(vector[28])
        # the capture points' elementwise blend in plain floats (the same bits)
        start_x, start_y, goal_x, goal_y = transition.capture_points
        capture_point = np.array([(1.0 - s) * start_x + s * goal_x,
                                  (1.0 - s) * start_y + s * goal_y])
        if not transition.with_rates:  # start()'s, every tick of its take-over
            return _reference_without_rates(capture_point, float(vector[29]),
                                            pelvis_frame(yaw, pitch), vector[:28])
        s_rate = smoothstep_rate(fraction, duration)  # ds/dt
        rate = (goal - start if per_s is None else per_s) * s_rate
        return StandReference(
            capture_point, float(vector[29]), pelvis_frame(yaw, pitch), vector[:28],
            com_height_rate_m_s=float(rate[29]),
            pelvis_angular_velocity=turn * s_rate * _UP + rate[28] * yaw_rotation(yaw)[:, 1],
            posture_rate_rad_s=rate[:28])

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """This tick's f_out (N m, (28,)), within the effort limits."""
        controller = self.controller
        if controller is None:
            raise BalanceError('StandBehaviour.torque before start()')
        if self._transition is not None:
            controller.reference = self._reference_at(float(data.time))
        state = self.estimator.estimate_stepped(data)
        if state.row_address is not None and controller.compiled:  # the call reads the joints
            output = controller.tick(state, JOINTS_IN_CALL, JOINTS_IN_CALL)
        else:
            atlas, vectors = self.atlas, self._vectors
            if vectors is None or vectors[0] is not data:
                vectors = self._vectors = (data, data.qpos, data.qvel)
            output = controller.tick(state, vectors[1][atlas.qpos_adr],
                                     vectors[2][atlas.dof_adr])
        self.last_state, self.last_output = state, output
        return output.torque_nm
