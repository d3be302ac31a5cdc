"""The behaviour library's contract: a behaviour registered with the interface is requested by
its number, takes its command, defers a Stand asked for while it says so, reports its feedback
and hands the robot over when it says, with no code of its own in the interface."""

from __future__ import annotations

from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.asi import AtlasSimInterface, Behavior, Handover, Status
from tutorial_atlas_control.balance import place_in_stand_pose
from tutorial_atlas_control.control_modes import ControlMode
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs import AsiCommand
from tutorial_atlas_control.msgs.atlas_sim_interface import ManipulateParams, StepData
from tutorial_atlas_control.msgs.atlas_sim_interface_state import StepFeedback
from tutorial_atlas_control.sim import AtlasSimulator, load_gains_yaml, load_model

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


class CountingStep:
    """A stand-in Step: balances with the Stand it is given, counts its ticks, finishes
    `busy_ticks` before it lets Stand in, and hands over to Stand by itself after
    `ticks_to_done`."""

    behavior = Behavior.STEP
    mode = ControlMode.STEP
    waits_for_stand = False

    def __init__(self, stand: object, busy_ticks: int, ticks_to_done: int) -> None:
        self.stand = stand
        self.busy_ticks, self.ticks_to_done = busy_ticks, ticks_to_done
        self.ticks = 0
        self.started = 0
        self.taken: list[bool] = []
        self.stand_asked = False

    def start(self, data: mujoco.MjData) -> None:
        self.started += 1
        self.ticks = 0
        self.stand.start(data)

    def torque(self, data: mujoco.MjData) -> np.ndarray:
        self.ticks += 1
        return self.stand.torque(data)

    def refusal(self, command: AsiCommand, running: bool) -> str | None:
        return None if command.desired_step.step_index >= 0 else 'a negative step index'

    def prepare(self, command: AsiCommand) -> None:
        pass

    def take(self, command: AsiCommand, running: bool) -> None:
        self.taken.append(running)

    def stop(self) -> bool:
        self.stand_asked = True
        return self.ticks < self.busy_ticks

    def handover(self, fallen: bool) -> Handover | None:
        if self.stand_asked and self.ticks >= self.busy_ticks:
            return Handover(Behavior.STAND, False)
        if self.ticks >= self.ticks_to_done:
            return Handover(Behavior.STAND, True)
        return None

    def feedback(self, time_s: float, sole_ahead_m: float) -> dict[str, object]:
        return {'step_feedback': StepFeedback(status_flags=2, current_step_index=self.ticks)}


def _command(behavior: int, step_index: int = 0) -> AsiCommand:
    return AsiCommand(0, behavior, (StepData(),) * 4, False, StepData(step_index=step_index),
                      False, ManipulateParams(), None, NUM_JOINTS)


def _interface(busy_ticks: int, ticks_to_done: int) -> tuple[AtlasSimInterface, CountingStep]:
    sim = AtlasSimulator(load_model(), load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    place_in_stand_pose(sim.atlas, sim.data)
    interface = AtlasSimInterface(sim)
    behaviour = CountingStep(interface.stand, busy_ticks, ticks_to_done)
    interface.register(behaviour)
    return interface, behaviour


def _tick(interface: AtlasSimInterface, ticks: int = 1) -> None:
    for _ in range(ticks):
        interface.sim.step()
        interface.end_step()


def test_a_registered_behaviour_runs_reports_and_hands_over_by_itself() -> None:
    interface, behaviour = _interface(busy_ticks=0, ticks_to_done=50)
    _tick(interface, 10)
    interface.apply(_command(Behavior.STEP))
    assert interface.sim.mode is ControlMode.STEP and behaviour.started == 1
    assert behaviour.taken == [False]
    _tick(interface, 20)
    interface.apply(_command(Behavior.STEP))
    assert behaviour.taken == [False, True]  # the running behaviour's command
    state = interface.state()
    assert state.current_behavior == Behavior.STEP
    assert (state.step_feedback.status_flags, state.step_feedback.current_step_index) == (2, 20)
    _tick(interface, 30)
    assert interface.sim.mode is ControlMode.STAND
    state = interface.state()
    assert state.current_behavior == Behavior.STAND
    assert state.behavior_feedback.status_flags == Status.WARNING_AUTO_TRANS
    assert state.step_feedback == StepFeedback()


def test_stand_asked_for_waits_while_the_behaviour_finishes() -> None:
    interface, behaviour = _interface(busy_ticks=40, ticks_to_done=10_000)
    interface.apply(_command(Behavior.STEP))
    _tick(interface, 10)
    interface.apply(_command(Behavior.STAND))
    assert interface.sim.mode is ControlMode.STEP
    assert interface.state().behavior_feedback.status_flags == Status.TRANSITION_IN_PROGRESS
    _tick(interface, 29)
    assert interface.sim.mode is ControlMode.STEP
    _tick(interface, 1)
    assert interface.sim.mode is ControlMode.STAND
    assert interface.state().behavior_feedback.status_flags == Status.TRANSITION_SUCCESS


def test_a_request_the_behaviour_refuses_names_its_reason() -> None:
    interface, behaviour = _interface(busy_ticks=0, ticks_to_done=50)
    interface.apply(_command(Behavior.STEP, step_index=-1))
    assert interface.sim.mode is ControlMode.STAND and behaviour.started == 0
    assert interface.take_refusal() == ('ignored AtlasSimInterfaceCommand behavior 5 (STEP) '
                                        'in STAND: a negative step index')


@pytest.mark.parametrize('mode', [ControlMode.WALK, ControlMode.STEP])
def test_walk_and_step_are_served_through_the_library(mode: ControlMode) -> None:
    sim = AtlasSimulator(load_model(), load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    interface = AtlasSimInterface(sim)
    assert interface.serves(mode)
    assert sim.behaviours.installed[mode] is interface.library[Behavior[mode.name]]
    assert not AtlasSimInterface(sim, balance=False).serves(mode)


def test_the_steps_a_client_sends_land_on_the_worlds_surface() -> None:
    """A step's height and surface come from the world under the sole: on a 0.2 m block its
    top, on a 10 degree ramp its height and tilt, on the ground the robot starts on as sent."""
    import mujoco

    from tutorial_atlas_control.asi.library import on_ground
    from tutorial_atlas_control.sim import Ground
    from tutorial_atlas_control.walking import Footstep

    tilt = np.radians(10.0)
    xml = f'''<mujoco><worldbody>
      <geom name="floor" type="plane" size="0 0 1"/>
      <geom name="block" type="box" size="0.2 0.2 0.1" pos="1 0 0.1"/>
      <geom name="ramp" type="box" size="0.5 0.5 0.01" pos="-2 0 0.3"
            euler="0 {-np.degrees(tilt)} 0"/>
    </worldbody></mujoco>'''
    model = mujoco.MjModel.from_xml_string(xml)
    ground = Ground(model)
    steps = [Footstep(1, 0, 1.0, 0.05, 0.0), Footstep(2, 1, 3.0, 0.0, 0.0),
             Footstep(3, 0, -2.0, 0.0, 0.0)]
    block, floor, ramp = on_ground(steps, ground)
    assert block.z_m == pytest.approx(0.2, abs=1e-9)
    assert block.normal == pytest.approx((0.0, 0.0, 1.0))
    assert floor.z_m == pytest.approx(0.0, abs=1e-9)
    assert ramp.z_m == pytest.approx(0.3 + 0.01 / np.cos(tilt), abs=1e-9)  # its top face
    assert ramp.normal == pytest.approx((-np.sin(tilt), 0.0, np.cos(tilt)), abs=1e-9)
    flat = Ground(mujoco.MjModel.from_xml_string(
        '<mujoco><worldbody><geom type="plane" size="0 0 1"/></worldbody></mujoco>'))
    assert on_ground(steps, flat) is steps


def test_manipulate_is_a_library_entry_nested_in_the_running_stand() -> None:
    """Manipulate is registered like Walk and Step but not installed: Stand keeps running,
    servoed by each command while Manipulate is current, and leaves it when Stand restarts."""
    sim = AtlasSimulator(load_model(), load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    place_in_stand_pose(sim.atlas, sim.data)
    interface = AtlasSimInterface(sim)
    assert interface.library[Behavior.MANIPULATE].mode is ControlMode.STAND
    assert sim.behaviours.installed[ControlMode.STAND] is interface.stand
    assert not interface.serves(ControlMode.STAND)
    _tick(interface, 10)
    interface.apply(AsiCommand(0, Behavior.MANIPULATE, (StepData(),) * 4, False, StepData(),
                               False, ManipulateParams(True, 0.85, 0.0, 0.0), None, 0))
    assert sim.behaviours.acting is interface.stand
    assert interface.state().current_behavior == Behavior.MANIPULATE
    assert interface.stand.servo_target is not None
    assert interface.stand.servo_target.height_m == 0.85
    sim.set_mode(ControlMode.STAND)  # a restart made elsewhere ends it
    _tick(interface)
    assert interface.state().current_behavior == Behavior.STAND
