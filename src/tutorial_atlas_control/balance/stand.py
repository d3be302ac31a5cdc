"""The Stand controller: balance on both feet at DRCSim's Stand pose.

Each 1 ms step it turns a BalanceState into the 28 joint torques, in three parts:
1. a desired centroidal wrench: the horizontal force of the capture-point law (the centre
   of pressure p = xi + k (xi - xi_ref), kept inside the support polygon, gives
   F_xy = m omega^2 (c - p)), the weight plus a PD on the centre-of-mass height, and a PD
   moment holding the pelvis upright at its reference yaw;
2. that wrench shared between the feet (contact_wrench) and turned into joint torques by
   inverse statics, tau = bias - J_c^T lambda (gravity and Coriolis of the whole body
   included, so no joint has to sag to hold its weight);
3. a joint PD to the Stand pose on top: stiff for the back, neck and arms (the balance
   treats them as a rigid load), light damping only on the legs, whose angles follow from
   where the pelvis is held.
With the capture-point gain at 0 the pressure centre sits on the capture point, which then
stops but never returns: that is the planted defect the tests show falling.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from tutorial_atlas_control.balance import contact_wrench, lipm, support
from tutorial_atlas_control.balance.estimator import BalanceState
from tutorial_atlas_control.balance.stand_pose import STAND_POSE_RAD

#: Joint PD to the Stand pose (N m/rad, N m s/rad), tutorial order. Back, neck and arms:
#: DRCSim's atlas_controller gains (config/atlas_controller.yaml), stable at 1 kHz on the
#: light wrists. Legs: a posture regulator weaker than the tutorial's hold, with nothing on
#: the ankles, whose torque the balance alone decides.
STAND_JOINT_KP: np.ndarray = np.array([
    20.0, 4000.0, 2000.0, 20.0,
    300.0, 300.0, 500.0, 500.0, 0.0, 0.0,
    300.0, 300.0, 500.0, 500.0, 0.0, 0.0,
    2000.0, 1000.0, 200.0, 200.0, 50.0, 100.0,
    2000.0, 1000.0, 200.0, 200.0, 50.0, 100.0])
STAND_JOINT_KD: np.ndarray = np.array([
    0.1, 2.0, 1.0, 1.0,
    3.0, 3.0, 5.0, 5.0, 1.0, 1.0,
    3.0, 3.0, 5.0, 5.0, 1.0, 1.0,
    3.0, 20.0, 3.0, 3.0, 0.1, 0.2,
    3.0, 20.0, 3.0, 3.0, 0.1, 0.2])


@dataclass(frozen=True)
class StandGains:
    """The Stand controller's numbers (ours: BDI never published theirs)."""

    #: k of p = xi + k (xi - xi_ref): the capture point's error decays at omega * k (1/s).
    capture_gain: float = 1.0
    #: How far inside the support polygon the pressure centre is kept (m).
    cop_margin_m: float = 0.015
    #: Centre-of-mass height PD (1/s^2, 1/s): a critically damped 3.2 Hz.
    height_kp: float = 400.0
    height_kd: float = 40.0
    #: Pelvis orientation PD (N m/rad, N m s/rad).
    orientation_kp: float = 3000.0
    orientation_kd: float = 300.0
    #: Joint PD to the Stand pose (N m/rad, N m s/rad), tutorial order.
    joint_kp: np.ndarray = field(default_factory=STAND_JOINT_KP.copy)
    joint_kd: np.ndarray = field(default_factory=STAND_JOINT_KD.copy)


@dataclass(frozen=True)
class StandReference:
    """Where Stand holds the robot: the capture point, the CoM height, the pelvis frame."""

    capture_point: np.ndarray    # (2,) m, world
    com_height_m: float
    pelvis_rotation: np.ndarray  # (3, 3)
    posture_rad: np.ndarray = field(default_factory=lambda: STAND_POSE_RAD.copy())
    #: How fast a moving reference moves (the PDs' damping is about these, so that a
    #: reference on its way is followed rather than dragged behind): the CoM height's rate
    #: (m/s), the pelvis frame's angular velocity (rad/s, world) and the posture's (rad/s).
    com_height_rate_m_s: float = 0.0
    pelvis_angular_velocity: np.ndarray = field(default_factory=lambda: np.zeros(3))
    posture_rate_rad_s: np.ndarray = field(default_factory=lambda: np.zeros(28))

    @classmethod
    def from_state(cls, state: BalanceState, posture_rad: np.ndarray = STAND_POSE_RAD,
                   forward_offset_m: float = 0.0) -> StandReference:
        """Hold the robot where it stands: the capture point over the soles' midpoint
        (`forward_offset_m` ahead along the pelvis's heading), the CoM at its height,
        the pelvis upright with its current yaw."""
        heading = state.pelvis_rotation[:, 0].copy()
        heading[2] = 0.0
        heading /= np.linalg.norm(heading)
        upright = yaw_rotation(np.arctan2(heading[1], heading[0]))
        middle = state.sole_centres[:, :2].mean(axis=0) + forward_offset_m * heading[:2]
        return cls(middle, float(state.com[2]), upright, np.array(posture_rad, dtype=float))


def yaw_of(rotation: np.ndarray) -> float:
    """The heading (rad) of a frame's x axis about the world z axis."""
    return float(np.arctan2(rotation[1, 0], rotation[0, 0]))


def yaw_rotation(yaw_rad: float) -> np.ndarray:
    """An upright frame turned by `yaw_rad` about z."""
    c, s = math.cos(yaw_rad), math.sin(yaw_rad)
    return np.array([[c, -s, 0.0], [s, c, 0.0], [0.0, 0.0, 1.0]])


def pitch_of(rotation: np.ndarray) -> float:
    """The pitch (rad, + leaning forward) of a frame's x axis below the horizontal."""
    return float(np.arctan2(-rotation[2, 0], np.hypot(rotation[0, 0], rotation[1, 0])))


def pelvis_frame(yaw_rad: float, pitch_rad: float = 0.0) -> np.ndarray:
    """A frame turned by `yaw_rad` about z, then pitched by `pitch_rad` about its own y."""
    c, s = np.cos(pitch_rad), np.sin(pitch_rad)
    return yaw_rotation(yaw_rad) @ np.array([[c, 0.0, s], [0.0, 1.0, 0.0], [-s, 0.0, c]])


def orientation_error(rotation: np.ndarray, reference: np.ndarray) -> np.ndarray:
    """The small rotation (rad, world axis) that takes `rotation` to `reference`."""
    (d00, d01, d02), (d10, d11, d12), (d20, d21, d22) = (reference @ rotation.T).tolist()
    return np.array([0.5 * (d21 - d12), 0.5 * (d02 - d20), 0.5 * (d10 - d01)])


@dataclass(frozen=True)
class StandOutput:
    """One step's decision, kept for feedback and tests."""

    torque_nm: np.ndarray          # (28,)
    desired_cop: np.ndarray        # (2,) m, after clamping into the support polygon
    force_n: np.ndarray            # (3,) desired total contact force
    moment_nm: np.ndarray          # (3,) desired moment about the CoM
    contact_wrenches: np.ndarray   # (2, 6) per foot, after making them feasible


class StandController:
    """Capture-point balance on both feet. Each step's torque depends on that step's state
    alone; the only thing kept is the support region prepared for the estimator's polygon."""

    def __init__(self, mass_kg: float, effort_limit_nm: np.ndarray, reference: StandReference,
                 sole_half_size_m: tuple[float, float],
                 gains: StandGains | None = None) -> None:
        """`sole_half_size_m`: (half length, half width) of a sole box (m)."""
        self.mass_kg = mass_kg
        self.effort_limit_nm = np.asarray(effort_limit_nm, dtype=float)
        self.reference = reference
        self.sole_half_size_m = sole_half_size_m
        self.gains = gains or StandGains()
        self._region: tuple[np.ndarray, support.Region] | None = None

    def desired_cop(self, state: BalanceState) -> np.ndarray:
        """The capture-point law's pressure centre, inside the support polygon."""
        cop = lipm.dcm_feedback_cop(state.capture_point, self.reference.capture_point,
                                    self.gains.capture_gain)
        polygon = state.support_polygon
        if len(polygon) < 3:
            return cop
        if self._region is None or self._region[0] is not polygon:
            # The estimator hands over the same polygon while the feet stay put.
            self._region = (polygon, support.Region(polygon, self.gains.cop_margin_m))
        return self._region[1].clamp(cop)

    def centroidal_wrench(self, state: BalanceState,
                          cop: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(force (3,) N, moment about the CoM (3,) N m) the contacts should exert."""
        gains, reference, mass = self.gains, self.reference, self.mass_kg
        # In plain floats (every 1 ms step), in numpy's order of operations: the same bits.
        com_x, com_y, com_z = state.com.tolist()
        cop_x, cop_y = np.asarray(cop, dtype=np.float64).tolist()
        stiffness = state.omega * state.omega  # lipm.com_acceleration's omega^2 (c - p)
        vertical = (gains.height_kp * (reference.com_height_m - com_z)
                    + gains.height_kd * (reference.com_height_rate_m_s
                                         - float(state.com_velocity[2])))
        force = np.array([mass * (stiffness * (com_x - cop_x) + 0.0),
                          mass * (stiffness * (com_y - cop_y) + 0.0),
                          mass * (vertical + lipm.GRAVITY_M_S2)])
        error = orientation_error(state.pelvis_rotation, reference.pelvis_rotation).tolist()
        kp, kd = gains.orientation_kp, gains.orientation_kd
        moment = np.array([kp * e + kd * (w_ref - w) for e, w_ref, w in zip(
            error, reference.pelvis_angular_velocity.tolist(),
            state.pelvis_angular_velocity.tolist())])
        return force, moment

    def step(self, state: BalanceState, joint_positions: np.ndarray,
             joint_velocities: np.ndarray) -> StandOutput:
        """The 28 joint torques (N m) for this step, clamped to the effort limits."""
        output = self.whole_body(state, self.desired_cop(state), state.in_contact,
                                 joint_positions, joint_velocities)
        np.clip(output.torque_nm, -self.effort_limit_nm, self.effort_limit_nm,
                out=output.torque_nm)
        return output

    def whole_body(self, state: BalanceState, cop: np.ndarray, contact: tuple[bool, bool],
                   joint_positions: np.ndarray, joint_velocities: np.ndarray,
                   joint_gains: tuple[np.ndarray, np.ndarray] | None = None,
                   torsion_m: float | None = None) -> StandOutput:
        """The torques that make the soles in `contact` press the centroidal wrench for
        `cop` (inverse statics, each sole's wrench made feasible: `torsion_m`, its yaw
        moment too), plus the joint PD to the posture (`joint_gains` (kp, kd), else the
        Stand's); not yet clamped to the effort limits (Walk adds its swing leg's first)."""
        force, moment = self.centroidal_wrench(state, cop)
        wrenches = contact_wrench.split_wrench(force, moment, state.sole_centres, state.com,
                                               contact)
        half_length, half_width = self.sole_half_size_m
        for foot in (0, 1):
            wrenches[foot] = contact_wrench.make_feasible(
                wrenches[foot], state.sole_rotations[foot], half_length, half_width, torsion_m)
        torque = state.bias_nm - state.sole_jacobians.reshape(12, -1).T @ wrenches.reshape(12)
        joint_kp, joint_kd = joint_gains or (self.gains.joint_kp, self.gains.joint_kd)
        reference = self.reference
        torque += (joint_kp * (reference.posture_rad - joint_positions)
                   + joint_kd * (reference.posture_rate_rad_s - joint_velocities))
        return StandOutput(torque, cop, force, moment, wrenches)
