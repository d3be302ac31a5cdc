"""A behaviour of your own: Stand that waves the right arm.

Load it into the simulator's AtlasSimInterface in place of the library's Stand:

    roslaunch tutorial_atlas_control atlas.launch \
        behaviour:=$(rospack find tutorial_atlas_control)/examples/arm_wave.py:ArmWave

then ask for Stand as any client does (`rostopic pub -1 /atlas/control_mode std_msgs/String
Stand`, or an AtlasSimInterfaceCommand STAND): the robot balances with a balancing Stand of
its own and, over the first second, raises its right arm partway out and then waves the
forearm at WAVE_HZ. The balance sees the arm's weight move and keeps the capture point between the
feet.

The class is called with the AtlasModel; `behavior` and `mode` say what it answers to (Stand,
in control mode Stand); `start` and `torque` are the simulator's behaviour protocol, and
BehaviourBase gives the rest of the library's contract its quiet defaults.
"""

from __future__ import annotations

import dataclasses
import math

import mujoco
import numpy as np

from tutorial_atlas_control.asi import Behavior, BehaviourBase
from tutorial_atlas_control.balance import (
    STAND_POSE_RAD,
    StandBehaviour,
    StandGains,
    smoothstep,
    smoothstep_rate,
)
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.joints import JOINT_NAMES
from tutorial_atlas_control.sim import AtlasModel

#: How long the arm takes to rise (s), and the wave's frequency (Hz) and amplitude (rad).
RAISE_S = 1.0
WAVE_HZ = 0.5
WAVE_RAD = 0.4
#: The raised arm: the shoulder 0.5 rad out from the Stand pose's 1.3, the elbow bent 1.2
#: rad. Not higher: the balancing Stand holds the centre of mass at its height, and an arm
#: raised to the horizontal lifts the whole body's by 1.7 cm, which the height PD answers by
#: taking 600 N off the feet: the robot topples forward (measured).
SHOULDER = JOINT_NAMES.index('r_arm_shx')
ELBOW = JOINT_NAMES.index('r_arm_elx')
RAISED_RAD = {SHOULDER: 0.8, ELBOW: -1.2}


class ArmWave(BehaviourBase):
    """The balancing Stand, with the right arm's shoulder and elbow pulled by the Stand's own
    joint gains to a moving target instead of the Stand pose."""

    behavior = Behavior.STAND
    mode = ControlMode.STAND

    def __init__(self, atlas: AtlasModel) -> None:
        self.atlas = atlas
        #: The arm's two joints' PD: the Stand's own gains, taken out of the balance's PD
        #: (which then only carries the arm's weight) and applied here to the wave's target.
        stand_gains = StandGains()
        self.joints = np.array(sorted(RAISED_RAD))
        self.kp = stand_gains.joint_kp[self.joints]
        self.kd = stand_gains.joint_kd[self.joints]
        joint_kp, joint_kd = stand_gains.joint_kp.copy(), stand_gains.joint_kd.copy()
        joint_kp[self.joints] = joint_kd[self.joints] = 0.0
        self.balance = StandBehaviour(atlas, dataclasses.replace(
            stand_gains, joint_kp=joint_kp, joint_kd=joint_kd))
        self.started_s = 0.0

    def start(self, data: mujoco.MjData) -> None:
        """Balance where the robot stands; the wave starts now."""
        self.balance.start(data)
        self.started_s = float(data.time)

    def arm_targets(self, time_s: float) -> dict[int, tuple[float, float]]:
        """(angle rad, rate rad/s) of the shoulder and the elbow at `time_s`."""
        elapsed = time_s - self.started_s
        rise, rise_rate = smoothstep(elapsed / RAISE_S), smoothstep_rate(elapsed / RAISE_S, RAISE_S)
        phase = 2.0 * math.pi * WAVE_HZ * elapsed
        targets = {}
        for joint, raised in RAISED_RAD.items():
            pose = float(STAND_POSE_RAD[joint])
            angle, rate = pose + rise * (raised - pose), rise_rate * (raised - pose)
            if joint == ELBOW:
                angle += rise * WAVE_RAD * math.sin(phase)
                rate += (rise * WAVE_RAD * 2.0 * math.pi * WAVE_HZ * math.cos(phase)
                         + rise_rate * WAVE_RAD * math.sin(phase))
            targets[joint] = (angle, rate)
        return targets

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        """The balance's torque, plus the arm's PD to the wave's target, within the effort
        limits."""
        torque = self.balance.torque(data).copy()
        targets = self.arm_targets(float(data.time))
        angle = np.array([targets[joint][0] for joint in self.joints])
        rate = np.array([targets[joint][1] for joint in self.joints])
        atlas = self.atlas
        torque[self.joints] += (self.kp * (angle - data.qpos[atlas.qpos_adr[self.joints]])
                                + self.kd * (rate - data.qvel[atlas.dof_adr[self.joints]]))
        limit = atlas.effort_limit_nm
        return np.clip(torque, -limit, limit)
