"""The AtlasSimInterface in the stepping loop: its state every step while someone listens
(genpy's bytes, stamped, counted), never built otherwise; its commands applied between
steps in order with the other commands, the newest of a step's only; refused ones said."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from support.stepping_fakes import (
    ALL_TOPICS,
    LAUNCH_RATES_HZ,
    FakeLog,
    FakeOutbox,
    header_stamp_ns,
    stops_after,
)
from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import AtlasSimInterface, Behavior, Status
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs.atlas_command import encode_atlas_command
from tutorial_atlas_control.msgs.atlas_sim_interface import (
    AsiCommand,
    ManipulateParams,
    StepData,
    encode_asi_command,
)
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def sim(atlas: atlas_model.AtlasModel) -> AtlasSimulator:
    return AtlasSimulator(atlas, load_gains_yaml(CONFIG))


def make_loop(sim: AtlasSimulator, listeners: set[str], balance: bool = False,
              hold_at_start: bool = False) -> tuple[SteppingLoop, FakeOutbox, FakeLog]:
    outbox, log = FakeOutbox(listeners), FakeLog()
    outlets = {topic: topic
               for topic in (*ALL_TOPICS, topics.ASI_STATE, topics.ASI_STATE_RECORDED)}
    loop = SteppingLoop(sim, LoopOutputs(outbox, outlets, log, lambda _text: None),
                        LoopSettings(LAUNCH_RATES_HZ, balance_stand=balance,
                                     hold_at_start=hold_at_start),
                        CommandAgeStatistics(sim.dt_s))
    return loop, outbox, log


def asi_bytes(behavior: int, k_effort: bytes = b'') -> bytes:
    command = AsiCommand(0, behavior, (StepData(),) * 4, False, StepData(), False,
                         ManipulateParams(), None, len(k_effort))
    return encode_asi_command(command, k_effort)


def test_the_state_goes_out_every_step_while_someone_listens(sim: AtlasSimulator) -> None:
    atlas_msgs = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')
    loop, outbox, _ = make_loop(sim, {topics.ASI_STATE})
    loop.run(stops_after(3))
    queued = outbox.queued()[topics.ASI_STATE]
    assert [header_stamp_ns(m) for m in queued] == [0, 0, sim.step_ns, 2 * sim.step_ns]
    for seq, framed in enumerate(queued, start=1):
        assert int.from_bytes(framed[:4], 'little') == len(framed) - 4
        message = atlas_msgs.AtlasSimInterfaceState()
        message.deserialize(bytes(framed[4:]))
        assert message.header.seq == seq
        assert message.current_behavior == Behavior.STAND
        assert message.behavior_feedback.status_flags == Status.OK
        assert len(message.f_out) == len(message.k_effort) == NUM_JOINTS


def test_an_unheard_state_is_never_built(sim: AtlasSimulator,
                                         monkeypatch: pytest.MonkeyPatch) -> None:
    built: list[int] = []
    original = AtlasSimInterface.state
    monkeypatch.setattr(AtlasSimInterface, 'state',
                        lambda self: (built.append(1), original(self))[1])
    loop, outbox, _ = make_loop(sim, {topics.JOINT_STATES})
    loop.run(stops_after(20))
    assert topics.ASI_STATE not in outbox.queued() and built == []


def test_commands_apply_in_order_and_the_newest_asi_command_only(sim: AtlasSimulator) -> None:
    loop, _, _ = make_loop(sim, set())
    # An AtlasCommand with k_effort 255, then FREEZE and USER requests: USER alone applies
    # (DRCSim's queue of 1) and, carrying no k_effort, keeps the AtlasCommand's.
    loop.receive_command(encode_atlas_command(0, {'k_effort': [255] * NUM_JOINTS}),
                         topics.ATLAS_COMMAND)
    loop.receive_command(asi_bytes(Behavior.FREEZE), topics.ASI_COMMAND)
    loop.receive_command(asi_bytes(Behavior.USER), topics.ASI_COMMAND)
    loop.apply_pending_commands()
    assert sim.mode is ControlMode.USER
    session = loop.asi.session
    assert (session.trans_from_behavior, session.trans_to_behavior) == (0, Behavior.USER)
    np.testing.assert_array_equal(sim.active_k_effort(), np.full(NUM_JOINTS, 255))
    # An ASI command's k_effort, then an AtlasCommand's: the newer one's stays.
    loop.receive_command(asi_bytes(Behavior.USER, bytes(NUM_JOINTS)), topics.ASI_COMMAND)
    loop.receive_command(encode_atlas_command(0, {'k_effort': [7] * NUM_JOINTS}),
                         topics.ATLAS_COMMAND)
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.active_k_effort(), np.full(NUM_JOINTS, 7))


def test_a_malformed_command_is_refused_in_one_line_and_a_short_k_effort_kept(
        sim: AtlasSimulator) -> None:
    loop, _, log = make_loop(sim, set())
    loop.receive_command(asi_bytes(Behavior.FREEZE)[:-3], topics.ASI_COMMAND)
    loop.apply_pending_commands()
    assert sim.mode is ControlMode.STAND
    refused, = log.of('refused')
    assert refused.startswith(f'refused {topics.ASI_COMMAND}: malformed '
                              'AtlasSimInterfaceCommand')
    loop.receive_command(asi_bytes(Behavior.FREEZE, bytes(27)), topics.ASI_COMMAND)
    loop.apply_pending_commands()
    assert sim.mode is ControlMode.FREEZE
    assert log.of('kept')[-1] == (f'{topics.ASI_COMMAND}: k_effort (27 entries) not 28 long; '
                                  'the previous blend stays')


def test_balance_stand_makes_stand_the_balancing_behaviour(sim: AtlasSimulator) -> None:
    loop, _, _ = make_loop(sim, set(), balance=True)
    assert sim.behaviours.acting is loop.asi.stand
    loop, _, _ = make_loop(AtlasSimulator(sim.atlas, sim.gains), set())
    assert loop.sim.behaviours.acting is None


def test_a_refused_request_is_said_in_one_line_and_the_remedy_is_taken(
        sim: AtlasSimulator) -> None:
    loop, _, log = make_loop(sim, set(), balance=True, hold_at_start=True)
    assert loop.asi.current_behavior == Behavior.USER  # the start's hold
    loop.receive_command(asi_bytes(Behavior.MANIPULATE), topics.ASI_COMMAND)
    loop.apply_pending_commands()
    assert log.of('refused') == [
        'refused AtlasSimInterfaceCommand behavior 6 (MANIPULATE) in USER: '
        'FAILED_TRANS_ILLEGAL_BEHAVIOR, MANIPULATE needs Stand: send STAND (behavior 0) first']
    loop.receive_command(asi_bytes(Behavior.STAND), topics.ASI_COMMAND)
    loop.receive_command(asi_bytes(Behavior.MANIPULATE), topics.ASI_COMMAND)
    loop.apply_pending_commands()  # the newest of a step's only: MANIPULATE, still refused
    loop.receive_command(asi_bytes(Behavior.STAND), topics.ASI_COMMAND)
    loop.apply_pending_commands()
    assert len(log.of('refused')) == 2 and sim.behaviours.acting is loop.asi.stand
    loop.receive_command(asi_bytes(Behavior.MANIPULATE), topics.ASI_COMMAND)
    loop.apply_pending_commands()
    assert len(log.of('refused')) == 2 and loop.asi.current_behavior == Behavior.MANIPULATE


def test_the_bags_copy_of_the_state_comes_at_50_hz_and_at_each_change(
        sim: AtlasSimulator) -> None:
    atlas_msgs = pytest.importorskip('atlas_msgs.msg', reason='needs the catkin workspace')
    loop, outbox, _ = make_loop(sim, {topics.ASI_STATE_RECORDED})
    turns = [0]

    def is_shutdown() -> bool:
        turns[0] += 1
        if turns[0] == 31:  # FREEZE before step 30: TRANSITION_SUCCESS in its state, then OK
            loop.receive_command(asi_bytes(Behavior.FREEZE), topics.ASI_COMMAND)
        return turns[0] > 45
    loop.run(is_shutdown)
    seen = []
    for framed in outbox.queued()[topics.ASI_STATE_RECORDED]:
        message = atlas_msgs.AtlasSimInterfaceState()
        message.deserialize(bytes(framed[4:]))
        seen.append((header_stamp_ns(framed) // sim.step_ns, message.current_behavior,
                     message.behavior_feedback.status_flags))
    # Stamped as the state (the step's start, ms): every 20th step, and the switch's
    # TRANSITION_SUCCESS and the OK after it, which a 50 Hz sample alone would miss.
    assert seen == [(0, Behavior.STAND, Status.OK), (19, Behavior.STAND, Status.OK),
                    (30, Behavior.FREEZE, Status.TRANSITION_SUCCESS),
                    (31, Behavior.FREEZE, Status.OK), (39, Behavior.FREEZE, Status.OK)]
    assert topics.ASI_STATE not in outbox.queued()  # the 1 kHz state: nobody listens


def test_a_client_streaming_its_requests_gets_one_first_command_line(
        sim: AtlasSimulator) -> None:
    """An AtlasSimInterfaceCommand without k_effort leaves the user command unset: the first
    command is the watch's own record, not the user command's absence (a 1 kHz client made
    one line per command, 5906 in a live minute)."""
    loop, _, log = make_loop(sim, set(), balance=True, hold_at_start=True)
    for _ in range(3):
        loop.receive_command(asi_bytes(Behavior.STAND), topics.ASI_COMMAND)
        loop.apply_pending_commands()
    firsts = [line for line in log.of('info') if line.startswith('first ')]
    assert firsts == ['first /atlas/atlas_sim_interface_command since the start or last '
                      'reset, at t=0.000 s (Stand mode)']
