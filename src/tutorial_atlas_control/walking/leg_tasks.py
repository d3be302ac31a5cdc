"""What Walk and Step do alike each 1 ms tick: the Stand's tasks on the whole-body layer
(balance/whole_body.py) over the feet that carry the robot, with the legs' own reference
(the pelvis turned towards the feet's heading, lowered to the walking height: the Stand's
own reference is not touched), a swing foot servoed along its path, a foot that should be
down put back flat on its last pose.

The Stand's joint PD keeps the arms and the back; the legs' posture gains are off (leg_kd
of damping instead, a tenth of it on the swinging leg): in single support the stance leg's
joints follow from the pelvis and the foot, the swing leg's from its task. While a foot
swings, the stance sole's yaw moment is held within torsion_m times its load (beyond the
model's torsional friction the foot turns).

A foot is servoed in the leg's joint space: its pose error turned into joint errors by
the leg's damped least-squares inverse, then a joint PD scaled by the leg's inertia, so
that every joint has the same bandwidth; a swing foot's path has its acceleration fed
forward and its velocity compared with the sole's in the world (without either the foot ran
ahead of its path as it slowed down and with the pelvis's speed, and every landing sat
2.5 cm ahead of its step). The task-space PD it replaced (6000 N/m on the
sole, 600 N m/rad and 30 N m s/rad on its turn) was unstable at 1 kHz on the light foot:
the legs' torques flipped between their effort limits every millisecond (280 N m per
step on the hip pitch), and that shaking decided, chaotically, which walks stood.

The swing torque and the servo run as one C call a tick (compiled_swing) where the
package's library is built, equal to the Python here to rounding; in Python (SWING_ENV=python,
or no library) they compute here. With a foot swinging, torque and finish together (the
sole clamp, the whole body, the swing servo, the effort limits) are one C call around both
(compiled_legs: swing_tick) on a compiled estimate's state, unless LEGS_ENV says `python`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from tutorial_atlas_control import native
from tutorial_atlas_control.balance import (
    BalanceState,
    MovedReference,
    StandController,
    box_corners,
    clamp_into,
    convex_hull,
    orientation_error,
    smoothstep,
    smoothstep_rate,
    yaw_of,
)
from tutorial_atlas_control.walking import sole_support
from tutorial_atlas_control.walking.compiled_legs import CompiledLegs
from tutorial_atlas_control.walking.compiled_swing import CompiledSwing
from tutorial_atlas_control.walking.footsteps import Footstep, wrap_angle
from tutorial_atlas_control.walking.swing import SwingPath, quintic, sole_frame, surface_tilt

__all__ = ['LEGS_ENV', 'LEG_JOINTS', 'SWING_ENV', 'LegGains', 'LegTasks', 'foot_pose', 'sole_flat',
           'standing_pose']

#: Set to `python` for the swing servo in Python even where the compiled library is built.
SWING_ENV = 'TAC_SWING'
#: Set to `python` for a swinging tick's pieces called from Python (each compiled or not by
#: its own switch) rather than the one call around them.
LEGS_ENV = 'TAC_LEGS'

#: The leg joints (tutorial order): their Stand posture PD is off while stepping.
LEG_JOINTS = slice(4, 16)
#: A timed move of the legs' reference: began (s), duration (s), from, change.
Move = tuple[float, float, float, float]
#: Each foot's leg joints, uhz to lax (tutorial order).
LEG_OF_FOOT = (slice(4, 10), slice(10, 16))


@dataclass(frozen=True)
class LegGains:
    """The legs' numbers while stepping (ours)."""

    #: The foot servo's joint PD, per unit of the leg's inertia (1/s^2, 1/s): 20 rad/s of
    #: bandwidth. A damping of 20/s and more chattered again (period 2 ms, on both legs);
    #: at 10/s the 20 straight steps and the circles stand.
    swing_kp: float = 400.0
    swing_kd: float = 10.0
    #: Whether the swing path's acceleration is fed forward. Without it the servo's error
    #: is the path's acceleration over swing_kp: the foot lagged as it sped up and ran ahead
    #: as it slowed down, and came down 2.5 cm ahead of every step (heel first, toes up).
    swing_feedforward: bool = True
    #: Whether the swing servo damps the sole's velocity in the world (the pelvis's motion
    #: too) rather than the leg's joint velocities: the path's velocity is in the world,
    #: and the foot ran ahead of it by the pelvis's speed (1 cm at 0.4 m/s).
    world_velocity: bool = True
    #: The damping of the leg's least-squares inverse (m): bounded joint errors with the
    #: knee nearly straight.
    ik_damping_m: float = 0.02
    #: Damping on the leg joints (N m s/rad) in place of Stand's posture PD.
    leg_kd: float = 2.0
    #: That damping on the swinging leg's joints (N m s/rad), a tenth: its servo damps them
    #: itself. leg_kd there was 13 times the servo's damping of the ankle's pitch (0.155 N m
    #: s/rad: the foot's inertia, 0.0155 kg m^2, times swing_kd) against a servo stiffness
    #: of 6.2 N m/rad: the ankle lagged its path, and every sole came down with its toes
    #: 0.23 rad up (6 cm) and slapped down over 130 ms. At 0.2, 0.07 rad, and flat (0.015)
    #: when the next step begins; at 0, 0.02 rad, but up the pit's 22 degree ramp every
    #: start fell at its seventh step (at 0.1, one of four).
    swing_leg_kd: float = 0.2
    #: A swing foot not down when its step's time is up keeps going down at this speed
    #: (m/s), for at most late_touchdown_s (s), before the next step begins anyway.
    touchdown_speed_m_s: float = 0.2
    late_touchdown_s: float = 0.4
    #: The yaw moment a stance sole may take, per newton it bears (m): the model's
    #: torsional friction is 0.02 m (sim/atlas_v1.xml); beyond it the foot turns.
    torsion_m: float | None = 0.015
    #: A foot put back down aims this far below the ground (m), so that it lands.
    press_m: float = 0.005
    #: A swing foot's path ends this far below its step's surface (m): the servo lags its
    #: path, and a path ending on the surface left the sole 1.5 cm up, heel first, when the
    #: next step put the whole weight on it (on the course a landing slammed down and the
    #: stance foot rolled over). With the sole coming down nearly flat (swing_leg_kd) it
    #: touches sooner: 5 mm landed the straight walk's steps 5 mm short on average, 2 mm 3.7.
    swing_press_m: float = 0.002
    #: A sole is flat on the ground with its centre below flat_height_m (m) and its normal
    #: within acos(flat_cos) of vertical (0.05 rad).
    flat_height_m: float = 0.005
    flat_cos: float = 0.99875
    #: A lone stance sole across facets keeps its wrench's pressure centre within this (m)
    #: of the one asked or of the points it bears on (sole_support: the pelvis task's
    #: moment took it to the sole's edge, where on the course's hills nothing bore, and the
    #: sole rolled over); None: the whole sole, as on a plane.
    near_cop_m: float | None = sole_support.SHIFT_M


def foot_pose(state: BalanceState, foot: int, step_index: int = 0) -> Footstep:
    """Where a foot is now, as a step (sole centre, its height, and heading)."""
    centre = state.sole_centres[foot]
    return Footstep(step_index, foot, float(centre[0]), float(centre[1]),
                    yaw_of(state.sole_rotations[foot]), z_m=float(centre[2]))


def standing_pose(state: BalanceState, foot: int,
                  ground_normal: tuple[float, float, float] = (0.0, 0.0, 1.0),
                  step_index: int = 0) -> Footstep:
    """Where a foot stands as a walk begins or a swing lands, as a step on the surface it
    rests on: a sole that carries lies on that surface, so its own plane is the surface (the
    ground's normal under the sole's centre is one facet of a heightfield, on the course's
    hills 6 degrees off the plane a planted sole rested on, and a step's planned plane was 4
    degrees off the one its sole came to rest on: the put-down servo then pressed the sole
    onto the wrong plane, its pressure centre went astray or its toe slammed, and the robot
    fell); a sole that does not carry, the ground's `ground_normal` under it."""
    normal = ground_normal
    if state.in_contact[foot]:
        x, y, z = state.sole_rotations[foot][:, 2].tolist()
        normal = (x, y, z) if z > 0.0 else ground_normal
    return replace(foot_pose(state, foot, step_index), normal=normal)


def sole_flat(state: BalanceState, foot: int, pose: Footstep, height_m: float,
              flat_cos: float) -> bool:
    """Whether the sole `foot` lies flat on the surface of `pose`: its centre less than
    `height_m` over it, its normal within acos(`flat_cos`) of the surface's."""
    sole_normal = state.sole_rotations[foot][:, 2]
    return (float(state.sole_centres[foot][2]) - pose.z_m < height_m
            and float(sole_normal @ np.asarray(pose.normal)) > flat_cos)


class LegTasks:
    """The shared torques over one StandController's tasks, with a reference of their own."""

    def __init__(self, stand: StandController, gains: LegGains, time_s: float,
                 compiled: bool | None = None) -> None:
        """`compiled`: the swing servo by one C call when the library is built (None:
        unless SWING_ENV says `python`); False: in Python."""
        self.stand = stand
        self.gains = gains
        #: The legs' own reference for the whole-body layer: the Stand's as the walk or
        #: step begins, its heading and height moved on (the Stand's is left as it is).
        self.reference = stand.reference
        #: The legs' joint PD, standing and while each foot swings (_stepping_joint_gains).
        self._joint_gains, self._swing_joint_gains = _stepping_joint_gains(stand, gains)
        self._ik_damping = gains.ik_damping_m ** 2 * np.eye(6)
        #: The soles' contacts while each foot swings (the stance sole's yaw moment limited).
        self._swing_contacts = tuple(stand.contacts_for((foot != 0, foot != 1), gains.torsion_m)
                                     for foot in (0, 1))
        #: How far a lone stance sole's pressure centre may go from the sole's centre (m),
        #: along it and across it: the sole's half size less the Stand's margin.
        self.sole_reach_m = _sole_reach_m(stand)
        #: The pelvis's heading moving on: (start time, duration, from, turn) (s, rad).
        self._facing = (time_s, 1.0, yaw_of(stand.reference.pelvis_rotation), 0.0)
        #: The CoM height moving on: (start time, duration, from, change) (s, m).
        self._height = (time_s, 1.0, stand.reference.com_height_m, 0.0)
        library = native.chosen_library(SWING_ENV, compiled)
        self._kernel = None if library is None else CompiledSwing(
            library, gains, len(stand.gains.joint_kp))
        legs_library = native.chosen_library(LEGS_ENV, compiled)
        whole_body = stand.compiled_whole_body
        self._legs_kernel = (
            None if legs_library is None or whole_body is None or self._kernel is None
            else CompiledLegs(legs_library, whole_body, self._kernel, self.sole_reach_m,
                              (LEG_OF_FOOT[0].start, LEG_OF_FOOT[1].start),
                              (*stand.sole_half_size_m, stand.gains.cop_margin_m),
                              (gains.press_m, gains.flat_height_m, gains.flat_cos)))

    @property
    def compiled(self) -> bool:
        """Whether the swing servo runs the C call."""
        return self._kernel is not None

    @property
    def compiled_swing_tick(self) -> bool:
        """Whether swing_tick runs the one C call (on a compiled estimate's state)."""
        return self._legs_kernel is not None

    @property
    def legs_kernel(self) -> CompiledLegs | None:
        """swing_tick's one C call (None: it computes in pieces)."""
        return self._legs_kernel

    @property
    def moves(self) -> tuple[Move, Move]:
        """The CoM height's and heading's timed moves, for a call computing the reference."""
        return self._height, self._facing

    def move_height(self, height_m: float, time_s: float, duration_s: float) -> None:
        """Take the CoM's reference height from where it is to `height_m` (a smoothstep)."""
        now, _ = self.height(time_s)
        self._height = (time_s, duration_s, now, height_m - now)

    def height(self, time_s: float) -> tuple[float, float]:
        """The CoM height's reference and its rate at `time_s` (m, m/s)."""
        started_s, duration_s, start, change = self._height
        fraction = (time_s - started_s) / duration_s
        return (start + smoothstep(fraction) * change,
                smoothstep_rate(fraction, duration_s) * change)

    def face(self, first_yaw_rad: float, second_yaw_rad: float, time_s: float,
             duration_s: float) -> None:
        """Turn the pelvis, upright, to face halfway between two feet's headings over
        `duration_s` (a smoothstep from where its heading is now: a jump in the heading's
        reference at each tick kicked the pelvis, which the stance sole's little yaw
        moment could not stop)."""
        now = self.heading(time_s)
        goal = first_yaw_rad + 0.5 * wrap_angle(second_yaw_rad - first_yaw_rad)
        self._facing = (time_s, duration_s, now, wrap_angle(goal - now))

    def heading(self, time_s: float) -> float:
        """The pelvis heading's reference at `time_s` (rad)."""
        started_s, duration_s, start, turn = self._facing
        return start + smoothstep((time_s - started_s) / duration_s) * turn

    def _moved_reference(self, time_s: float) -> MovedReference:
        """The legs' reference's heading, CoM height and rate at `time_s` (the rest is
        self.reference's): the whole-body call writes them over its copy of the reference
        (no new reference a tick, as the heading turns through every step)."""
        height, height_rate = self.height(time_s)
        return self.heading(time_s), height, height_rate

    def swing_torque(self, state: BalanceState, joint_velocities: np.ndarray, foot: int,
                     swing: SwingPath, elapsed_s: float) -> np.ndarray:
        """The swing leg's torques (28,) along `swing`, `elapsed_s` into it, the path's
        acceleration fed forward; past its end the foot goes on down at touchdown_speed_m_s."""
        if self._kernel is not None:
            return self._kernel.swing_torque(state, joint_velocities, LEG_OF_FOOT[foot], foot,
                                             swing, elapsed_s)
        gains = self.gains
        position, velocity, yaw, yaw_rate = swing.at(elapsed_s)
        tilt = swing.tilt(elapsed_s)
        acceleration, yaw_acceleration = (swing.acceleration(elapsed_s)
                                          if gains.swing_feedforward else (None, 0.0))
        position[2] -= gains.swing_press_m * quintic(elapsed_s / swing.duration_s)[0]
        late = elapsed_s - swing.duration_s
        if late > 0.0:  # not down yet: on down
            position[2] -= gains.touchdown_speed_m_s * late
            velocity[2] = -gains.touchdown_speed_m_s
        return self.foot_servo(state, joint_velocities, foot, position, velocity, yaw,
                               yaw_rate, acceleration, yaw_acceleration,
                               world=gains.world_velocity, tilt=tilt)

    def foot_servo(self, state: BalanceState, joint_velocities: np.ndarray, foot: int,
                   position: np.ndarray, velocity: np.ndarray, yaw: float,
                   yaw_rate: float, acceleration: np.ndarray | None = None,
                   yaw_acceleration: float = 0.0, world: bool = False,
                   tilt: tuple[float, float] = (0.0, 0.0)) -> np.ndarray:
        """The leg's torques (28,) moving a sole towards a pose at a velocity (the module's
        joint-space servo), with `acceleration` (the sole's, and its yaw's) fed forward
        through the same inverse; `world`: damping the sole's velocity in the world (a
        swing foot's path is in the world, the pelvis's motion adds to it) rather than the
        leg's joint velocities (a foot put back down: its pelvis moves over it); `tilt`:
        the sole laid on a sloping surface (swing.surface_tilt), not upright."""
        leg = LEG_OF_FOOT[foot]
        if self._kernel is not None:
            return self._kernel.foot_servo(
                state, joint_velocities, leg, foot,
                (position, velocity, yaw, yaw_rate, acceleration, yaw_acceleration), world,
                tilt)
        return _python_foot_servo(self.gains, self._ik_damping, state, joint_velocities, foot,
                                  (position, velocity, yaw, yaw_rate, acceleration,
                                   yaw_acceleration), world, tilt)

    def flat_down(self, state: BalanceState, foot: int, pose: Footstep) -> bool:
        """Whether a sole lies flat on the surface of `pose` (not up, not on an edge)."""
        return sole_flat(state, foot, pose, self.gains.flat_height_m, self.gains.flat_cos)

    def put_down_torque(self, state: BalanceState, joint_velocities: np.ndarray, foot: int,
                        pose: Footstep) -> np.ndarray:
        """A foot off the ground while both should be down: back onto `pose`."""
        target = np.array([pose.x_m, pose.y_m, pose.z_m - self.gains.press_m])
        return self.foot_servo(state, joint_velocities, foot, target, np.zeros(3),
                               pose.yaw_rad, 0.0, tilt=surface_tilt(pose.normal))

    def torque(self, state: BalanceState, joint_positions: np.ndarray,
               joint_velocities: np.ndarray, time_s: float, cop: np.ndarray,
               swing_foot: int | None) -> tuple[np.ndarray, np.ndarray, tuple[bool, bool]]:
        """The whole-body torques (28,) for the pressure centre `cop` kept inside the
        carrying soles (the stance sole alone while `swing_foot` swings or is being
        unloaded, else the feet that are down, both if none is), the pressure centre as
        kept, and which soles carry. `finish` adds the swing or put-down torques; nothing
        is clipped yet."""
        stand = self.stand
        moved = self._moved_reference(time_s)
        if swing_foot is not None:
            contact = (swing_foot != 0, swing_foot != 1)
            cop = _clamp_to_sole(state, 1 - swing_foot, self.sole_reach_m, cop)
        else:  # swaying, moving the weight, catching: the feet that are down (both, unless late)
            contact = state.in_contact if any(state.in_contact) else (True, True)
            cop = self._support_clamp(state, contact, cop)
        torsion = self.gains.torsion_m if swing_foot is not None else None
        contacts = None if swing_foot is None else sole_support.stance_contacts(
            state, 1 - swing_foot, self._swing_contacts[swing_foot], cop, self.gains.near_cop_m)
        joint_gains = (self._joint_gains if swing_foot is None
                       else self._swing_joint_gains[swing_foot])
        torque = stand.whole_body(state, cop, contact, joint_positions, joint_velocities,
                                  joint_gains, torsion, self.reference,
                                  moved, contacts).torque_nm
        return torque, cop, contact

    def load_swing_tick(self, state: BalanceState, joint_positions: np.ndarray,
                        joint_velocities: np.ndarray, moved: MovedReference,
                        swing: tuple[int, SwingPath, float],
                        rule_in_call: bool = False) -> CompiledLegs | None:
        """swing_tick's call loaded but the pressure centre, the caller's call's (MOVED_IN_CALL
        `moved`, the stance rule if `rule_in_call`), or None: no library, a Python state."""
        legs = self._legs_kernel
        if legs is None or state.row_address is None:
            return None
        near = None if rule_in_call else sole_support.stance_rule(state, 1 - swing[0],
                                                                  self.gains.near_cop_m)
        legs.load_swing_tick(state, self._swing_contacts[swing[0]],
                             (joint_positions, joint_velocities),
                             self._swing_joint_gains[swing[0]], self.reference, moved, swing,
                             near)
        return legs

    def swing_tick(self, state: BalanceState, joint_positions: np.ndarray,
                   joint_velocities: np.ndarray, time_s: float, cop: np.ndarray,
                   swing: tuple[int, SwingPath, float]) -> tuple[np.ndarray, np.ndarray,
                                                                 tuple[bool, bool]]:
        """torque() then finish() with `swing` (the foot, its path and the time into it):
        the torques within the effort limits, the pressure centre as kept, which soles
        carry."""
        legs = self.load_swing_tick(state, joint_positions, joint_velocities,
                                    self._moved_reference(time_s), swing)
        if legs is None:
            torque, cop, contact = self.torque(state, joint_positions, joint_velocities,
                                               time_s, cop, swing[0])
            return self.finish(state, joint_velocities, torque, contact, swing, ()), cop, contact
        torque, cop = legs.tick_at(cop)
        return torque, cop, (swing[0] != 0, swing[0] != 1)

    def support_torque(self, state: BalanceState, joint_positions: np.ndarray,
                       joint_velocities: np.ndarray, time_s: float, cop: np.ndarray,
                       feet: Sequence[Footstep]) -> tuple[np.ndarray, np.ndarray,
                                                          tuple[bool, bool]]:
        """torque() then finish() with no foot swinging (`feet`: the poses a foot not flat
        down is put back on): one C call on a compiled estimate's state."""
        legs = self._legs_kernel
        if legs is None or state.row_address is None:
            torque, cop, contact = self.torque(state, joint_positions, joint_velocities,
                                               time_s, cop, None)
            return self.finish(state, joint_velocities, torque, contact, None, feet), cop, contact
        contact = state.in_contact if any(state.in_contact) else (True, True)
        torque, cop = legs.support_tick(
            state, self.stand.contacts_for(contact, None), (joint_positions, joint_velocities),
            self._joint_gains, self.reference, self._moved_reference(time_s), cop, contact,
            (feet[0], feet[1]))
        return torque, cop, contact

    def _support_clamp(self, state: BalanceState, contact: tuple[bool, bool],
                       cop: np.ndarray) -> np.ndarray:
        """`cop` kept in the hull of the soles in `contact` shrunk by the margin (one C call
        on a compiled estimate's state)."""
        legs = self._legs_kernel
        if legs is not None and state.row_address is not None:
            return legs.support_clamp(state, contact, cop)
        stand = self.stand
        half_length, half_width = stand.sole_half_size_m
        corners = np.concatenate([
            box_corners(state.sole_centres[foot], state.sole_rotations[foot],
                        (half_length, half_width, 0.0))[:, 0:2]
            for foot in (0, 1) if contact[foot]])
        return clamp_into(convex_hull(corners), cop, stand.gains.cop_margin_m)

    def finish(self, state: BalanceState, joint_velocities: np.ndarray, torque: np.ndarray,
               contact: tuple[bool, bool], swing: tuple[int, SwingPath, float] | None,
               feet: Sequence[Footstep]) -> np.ndarray:
        """`torque` (from torque()) with the swing leg's servo added (`swing`: the foot, its
        path and the time into it), or else with each foot that should carry but is not
        flat down put back on its pose in `feet`; clipped to the effort limits, in place."""
        if swing is not None:
            foot, path, elapsed_s = swing
            torque += self.swing_torque(state, joint_velocities, foot, path, elapsed_s)
        else:
            for foot in (0, 1):
                if not contact[foot] or not self.flat_down(state, foot, feet[foot]):
                    torque += self.put_down_torque(state, joint_velocities, foot, feet[foot])
        return self.stand.layer.limit(torque)


JointGains = tuple[np.ndarray, np.ndarray]


def _stepping_joint_gains(stand: StandController, gains: LegGains
                          ) -> tuple[JointGains, tuple[JointGains, JointGains]]:
    """The Stand's joint PD (kp, kd) with the legs' posture gains off, damping leg_kd
    instead; and the same while the left, then the right foot swings, its leg damped by
    swing_leg_kd."""
    joint_kp, joint_kd = stand.gains.joint_kp.copy(), stand.gains.joint_kd.copy()
    joint_kp[LEG_JOINTS] = 0.0
    joint_kd[LEG_JOINTS] = gains.leg_kd
    swinging = []
    for foot in (0, 1):
        damped = joint_kd.copy()
        damped[LEG_OF_FOOT[foot]] = gains.swing_leg_kd
        swinging.append((joint_kp, damped))
    return (joint_kp, joint_kd), (swinging[0], swinging[1])


def _python_foot_servo(gains: LegGains, ik_damping: np.ndarray, state: BalanceState,
                       joint_velocities: np.ndarray, foot: int,
                       target: tuple[np.ndarray, np.ndarray, float, float, np.ndarray | None,
                                     float],
                       world: bool, tilt: tuple[float, float]) -> np.ndarray:
    """LegTasks.foot_servo in Python: `target` its position, velocity, yaw, yaw rate,
    acceleration (None: none fed forward) and yaw acceleration."""
    position, velocity, yaw, yaw_rate, acceleration, yaw_acceleration = target
    leg = LEG_OF_FOOT[foot]
    jacobian = state.sole_jacobians[foot][:, leg]
    columns = 2 if acceleration is None else 3
    targets = np.zeros((6, columns))  # the pose's error, the velocity asked for, ...
    targets[0:3, 0] = position - state.sole_centres[foot]
    targets[3:6, 0] = orientation_error(state.sole_rotations[foot], sole_frame(yaw, tilt))
    targets[0:3, 1] = velocity
    targets[5, 1] = yaw_rate
    if world:
        targets[:, 1] -= state.sole_velocities[foot]
    if acceleration is not None:  # ... and the acceleration
        targets[0:3, 2] = acceleration
        targets[5, 2] = yaw_acceleration
    damped = jacobian @ jacobian.T + ik_damping
    joint_targets = (jacobian.T @ np.linalg.solve(damped, targets)).T
    joint_error, joint_rate = joint_targets[0], joint_targets[1]
    if not world:
        joint_rate = joint_rate - joint_velocities[leg]
    accel = gains.swing_kp * joint_error + gains.swing_kd * joint_rate
    if acceleration is not None:
        accel += joint_targets[2]
    torque = np.zeros(len(joint_velocities))
    torque[leg] = state.joint_inertia(leg) @ accel
    return torque


def _sole_reach_m(stand: StandController) -> tuple[float, float]:
    """A sole's half length and width less the Stand's margin (m; at least 0)."""
    half_length, half_width = stand.sole_half_size_m
    margin = stand.gains.cop_margin_m
    return max(half_length - margin, 0.0), max(half_width - margin, 0.0)


def _clamp_to_sole(state: BalanceState, foot: int, reach_m: tuple[float, float],
                   point_xy: np.ndarray) -> np.ndarray:
    """`point_xy` moved to the nearest point of one sole's rectangle reaching `reach_m`
    from its centre along and across it (in the sole's frame a clamp of each coordinate:
    the rectangle's hull and a general polygon's clamp, every tick of single support, cost
    more than the rest of the step's pressure-centre work; plain floats, as numpy's calls
    on two numbers cost more than the arithmetic)."""
    (r00, r01, _), (r10, r11, _), _ = state.sole_rotations[foot].tolist()
    centre_x, centre_y, _ = state.sole_centres[foot].tolist()
    x, y = point_xy.tolist()
    dx, dy = x - centre_x, y - centre_y
    reach_x, reach_y = reach_m
    along = min(max(r00 * dx + r10 * dy, -reach_x), reach_x)
    across = min(max(r01 * dx + r11 * dy, -reach_y), reach_y)
    return np.array([centre_x + (r00 * along + r01 * across),
                     centre_y + (r10 * along + r11 * across)])
