"""What an AtlasSimInterfaceState reports of the simulator: f_out, the blend in use, the
pelvis and the feet, with the library's decisions the interface hands it. ROS-free."""

from __future__ import annotations

import mujoco
import numpy as np

from tutorial_atlas_control.asi.behaviors import Behavior
from tutorial_atlas_control.asi.session import AsiSession
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs import (
    AsiState,
    BehaviorFeedback,
    ManipulateFeedback,
    StepFeedback,
    WalkFeedback,
)
from tutorial_atlas_control.sim import AtlasSimulator

__all__ = ['FOOT_BODIES', 'StateReport']

FOOT_BODIES = ('l_foot', 'r_foot')
_NO_TORQUE = np.zeros(NUM_JOINTS)
_NO_TORQUE.setflags(write=False)
_NO_BLEND = np.zeros(NUM_JOINTS, np.uint8)
_NO_BLEND.setflags(write=False)


class StateReport:
    """The state's numbers read from one simulator."""

    def __init__(self, sim: AtlasSimulator) -> None:
        self.sim = sim
        model = sim.model
        self._feet = [mujoco.mj_name2id(model, mujoco.mjtObj.mjOBJ_BODY, name)
                      for name in FOOT_BODIES]
        free_joint = int(model.body_jntadr[sim.atlas.pelvis_body_id])
        self._free_dof = int(model.jnt_dofadr[free_joint])

    def f_out(self) -> np.ndarray:
        """The behaviour's joint torques this tick (N m): the Stand behaviour's or a hold's;
        none in User, ragdoll and the start's hold (the PID alone holds the robot)."""
        sim = self.sim
        if sim.mode in (ControlMode.USER, ControlMode.RAGDOLL) or sim.behaviours.holding_start:
            return _NO_TORQUE
        return sim.torque_nm if sim.commands.blend_command is None else sim.law.f_out_nm

    def k_effort(self) -> np.ndarray:
        """The blend in use (uint8, (28,)): the user command's in User; the hold's PID
        during the start's hold; elsewhere the blended user command's, 0 on every joint when
        the behaviour alone acts."""
        sim = self.sim
        if sim.mode is ControlMode.USER or sim.behaviours.holding_start \
                or sim.commands.blend_command is not None:
            return sim.active_k_effort()
        return _NO_BLEND

    def foot_poses(self) -> np.ndarray:
        """foot_pos_est: each foot link's position and orientation (x, y, z, qx, qy, qz, qw)."""
        data = self.sim.data
        feet = np.empty((2, 7))
        for row, body in enumerate(self._feet):
            feet[row, 0:3] = data.xpos[body]
            w, x, y, z = data.xquat[body]
            feet[row, 3:7] = (x, y, z, w)
        return feet

    def state(self, current: Behavior, session: AsiSession, falling: bool,
              manipulate: ManipulateFeedback, walk: WalkFeedback,
              step: StepFeedback) -> AsiState:
        """The AtlasSimInterfaceState of the tick just run, with the library's values."""
        sim, data = self.sim, self.sim.data
        adr, dof = sim.atlas.free_qpos_adr, self._free_dof
        return AsiState(
            stamp_ns=sim.state_time_ns, error_code=int(session.error_code),
            current_behavior=int(current), desired_behavior=session.desired_behavior,
            f_out_nm=self.f_out().copy(),
            pelvis_position_m=tuple(data.qpos[adr:adr + 3]),
            pelvis_velocity_m_s=tuple(data.qvel[dof:dof + 3]), foot_poses=self.foot_poses(),
            behavior_feedback=BehaviorFeedback(session.status_flags(current, falling),
                                               session.trans_from_behavior,
                                               session.trans_to_behavior),
            manipulate_feedback=manipulate, walk_feedback=walk, step_feedback=step,
            k_effort=self.k_effort())

