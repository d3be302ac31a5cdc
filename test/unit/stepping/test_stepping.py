"""The node's stepping loop without ROS: what is due when, stamps, pacing and flushes,
command merging, divergence retries. A fake outbox stands for the publishers."""

from __future__ import annotations

import threading
import time
from pathlib import Path

import numpy as np
import pytest

from support.stepping_fakes import (
    ALL_TOPICS,
    LAUNCH_RATES_HZ,
    FakeClock,
    FakeLog,
    FakeOutbox,
    clock_ns,
    command_bytes,
    complete_command,
    header_stamp_ns,
    make_loop,
    stops_after,
)
from tutorial_atlas_control import topics
from tutorial_atlas_control.joints import JOINT_INDEX, NUM_JOINTS
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.fall import FALL_HEIGHT_M
from tutorial_atlas_control.sim.model import pelvis_height_m
from tutorial_atlas_control.sim.simulator import AtlasSimulator, ControlMode, PhysicsDivergenceError
from tutorial_atlas_control.stepping import pacing
from tutorial_atlas_control.stepping.divergence import (
    DIVERGENCE_REPEAT_S,
    MAX_DIVERGENCES_IN_A_ROW,
    DivergenceGuard,
)
from tutorial_atlas_control.stepping.inbox import CommandInbox
from tutorial_atlas_control.stepping.loop import PAUSED_POLL_S, LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.pacing import Pacer
from tutorial_atlas_control.stepping.publication import DEMAND_TOPICS
from tutorial_atlas_control.stepping.schedule import step_stamp, steps_between
from tutorial_atlas_control.stepping.watch import NOT_USER_WARN_PERIOD_S
from tutorial_atlas_control.units import NS_PER_S

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def sim(atlas: atlas_model.AtlasModel) -> AtlasSimulator:
    return AtlasSimulator(atlas, load_gains_yaml(CONFIG))


# -- schedule ---------------------------------------------------------------------------

@pytest.mark.parametrize(('rate_hz', 'every'), [
    (0.0, 1), (1000.0, 1), (5000.0, 1), (500.0, 2), (333.0, 3), (100.0, 10), (1.0, 1000)])
def test_steps_between_at_a_1_ms_step(rate_hz: float, every: int) -> None:
    assert steps_between(rate_hz, 0.001) == every


def test_joint_states_carry_the_step_end_poses_and_sensors_its_start() -> None:
    assert step_stamp(topics.JOINT_STATES, 2_000_000, 1_000_000) == 2_000_000
    for topic in (topics.IMU, topics.L_FOOT_CONTACT, topics.R_FOOT_CONTACT,
                  topics.GROUND_TRUTH_ODOM, topics.TF):
        assert step_stamp(topic, 2_000_000, 1_000_000) == 1_000_000
    ends, starts = np.array([2, 3]), np.array([1, 2])
    assert step_stamp(topics.JOINT_STATES, ends, starts) is ends


# -- what is due, and its stamps ---------------------------------------------------------

def test_each_topic_is_published_at_its_rate(sim: AtlasSimulator) -> None:
    rates = {'joint_states': 1000.0, 'imu': 500.0, 'contact': 250.0, 'odom': 100.0,
             'tf': 50.0}
    loop, outbox, _, _ = make_loop(sim, rates_hz=rates)
    assert loop.run(stops_after(40)) == 0
    queued = outbox.queued()
    # The initial publication (step count 0) and then one every N of the 40 steps.
    assert {topic: len(queued[topic]) for topic in ALL_TOPICS if topic != topics.CLOCK} == {
        topics.JOINT_STATES: 41, topics.IMU: 21, topics.L_FOOT_CONTACT: 11,
        topics.R_FOOT_CONTACT: 11, topics.GROUND_TRUTH_ODOM: 5, topics.TF: 3,
        topics.CONTROLLER_STATISTICS: 40}
    # /clock: only the latest time of each flush (the wall clock stands still here: only
    # the initial one), and the last one is the run's end.
    assert len(queued[topics.CLOCK]) == outbox.flushes + 1
    assert clock_ns(queued[topics.CLOCK][-1]) == 40 * sim.step_ns


def test_stamps_follow_the_schedule_rule(sim: AtlasSimulator) -> None:
    loop, outbox, _, _ = make_loop(sim)
    loop.run(stops_after(3))
    queued = outbox.queued()
    step_ns = sim.step_ns
    ends = [k * step_ns for k in range(4)]
    # Poses and sensors carry the state's time: the start of the step (the initial
    # publication describes the state at 0).
    starts = [0, 0, step_ns, 2 * step_ns]
    assert [header_stamp_ns(m) for m in queued[topics.JOINT_STATES]] == ends
    assert [header_stamp_ns(m) for m in queued[topics.IMU]] == starts
    assert [header_stamp_ns(m) for m in queued[topics.L_FOOT_CONTACT]] == starts


def test_nothing_is_serialized_for_topics_without_listeners(sim: AtlasSimulator) -> None:
    loop, outbox, _, _ = make_loop(sim, listeners={topics.JOINT_STATES})
    loop.run(stops_after(20))
    assert set(outbox.queued()) == {topics.JOINT_STATES}
    assert loop.statistics.age_ns == 0  # not even fed


def test_without_a_tf_outlet_there_is_no_tf(sim: AtlasSimulator) -> None:
    outbox = FakeOutbox(set(ALL_TOPICS))
    outlets = {topic: topic for topic in ALL_TOPICS if topic != topics.TF}
    loop = SteppingLoop(sim, LoopOutputs(outbox, outlets, FakeLog(), lambda _text: None),
                        LoopSettings(LAUNCH_RATES_HZ), CommandAgeStatistics(sim.dt_s))
    loop.run(stops_after(20))
    queued = outbox.queued()
    assert topics.TF not in queued
    assert len(queued[topics.GROUND_TRUTH_ODOM]) == 3


# -- DRCSim's messages, filled only when heard ------------------------------------------

DRCSIM_TOPICS = tuple(topic.name for topic in DEMAND_TOPICS)


def make_drcsim_loop(sim: AtlasSimulator, listeners: set[str],
                     rates_hz: dict[str, float] | None = None) -> tuple[SteppingLoop, FakeOutbox]:
    outbox = FakeOutbox(listeners)
    outlets = {topic: topic for topic in ALL_TOPICS + DRCSIM_TOPICS}
    loop = SteppingLoop(sim, LoopOutputs(outbox, outlets, FakeLog(), lambda _text: None),
                        LoopSettings({**LAUNCH_RATES_HZ, **(rates_hz or {})}),
                        CommandAgeStatistics(sim.dt_s))
    return loop, outbox


def test_drcsim_messages_at_their_rates_and_stamps(sim: AtlasSimulator) -> None:
    """AtlasState as the joint states (step end), the sensors at the step's start; the
    debug contacts while the feet touch the ground (standing: every step)."""
    loop, outbox = make_drcsim_loop(sim, set(DRCSIM_TOPICS) | {topics.JOINT_STATES},
                                    {'force_torque_sensors': 500.0})
    loop.run(stops_after(4))
    queued = outbox.queued()
    ends = [k * sim.step_ns for k in range(5)]
    starts = [0, 0, sim.step_ns, 2 * sim.step_ns, 3 * sim.step_ns]
    assert [header_stamp_ns(m) for m in queued[topics.ATLAS_STATE]] == ends
    assert [header_stamp_ns(m) for m in queued[topics.FORCE_TORQUE_SENSORS]] == starts[::2]
    for topic in (topics.DEBUG_L_FOOT_CONTACT, topics.DEBUG_R_FOOT_CONTACT):
        assert [header_stamp_ns(m) for m in queued[topic]] == starts
    # The joint fields are the joint state's, rounded to float32.
    state, joint_state = queued[topics.ATLAS_STATE][-1], queued[topics.JOINT_STATES][-1]
    count = NUM_JOINTS
    positions = np.frombuffer(state, '<f4', count, offset=24)
    assert np.array_equal(positions, np.frombuffer(joint_state, '<f8', count,
                                                   offset=len(joint_state) - 3 * (4 + 8 * count)
                                                   + 4).astype(np.float32))


def test_unheard_drcsim_messages_are_never_filled(sim: AtlasSimulator,
                                                  monkeypatch: pytest.MonkeyPatch) -> None:
    from tutorial_atlas_control.sim.sim_messages import SimMessages

    fills: list[str] = []
    for name in ('fill_atlas_state', 'fill_force_torque_sensors', 'fill_debug_contact'):
        original = getattr(SimMessages, name)
        monkeypatch.setattr(SimMessages, name, lambda self, *args, _o=original, _n=name: (
            fills.append(_n), _o(self, *args))[1])
    loop, outbox = make_drcsim_loop(sim, {topics.JOINT_STATES})
    loop.run(stops_after(20))
    assert set(outbox.queued()) == {topics.JOINT_STATES}
    assert fills == []
    loop, outbox = make_drcsim_loop(sim, {topics.FORCE_TORQUE_SENSORS})
    loop.run(stops_after(2))
    assert fills == ['fill_force_torque_sensors'] * 3


# -- commands ------------------------------------------------------------------------------

def test_commands_between_steps_merge_oldest_first(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    loop.receive_command(complete_command(0.1))
    loop.receive_command(command_bytes(['neck_ay'], position=[0.3]))
    loop.receive_command(command_bytes(['neck_ay', 'back_lbz'], position=[0.2, 0.4]))
    loop.apply_pending_commands()
    position = sim.user_command.position
    assert position[JOINT_INDEX['neck_ay']] == 0.2  # the newest of the two partial ones
    assert position[JOINT_INDEX['back_lbz']] == 0.4
    assert position[JOINT_INDEX['l_leg_kny']] == 0.1  # the complete one underneath
    assert log.of('info') == [
        'first /atlas/joint_commands since the start or last reset, at t=0.000 s (Stand mode)']
    assert not loop.inbox.pending


def test_a_complete_command_hides_older_ones_undecoded(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    loop.receive_command(b'not a command')  # older: never decoded, so never refused
    loop.receive_command(command_bytes(['neck_ay'], position=[0.3]))
    loop.receive_command(complete_command(0.1, stamp_ns=7 * NS_PER_S))
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.user_command.position, [0.1] * NUM_JOINTS)
    assert log.of('refused') == []
    assert loop.statistics.command_stamp_ns == 7 * NS_PER_S  # the newest applied


def test_of_complete_commands_only_the_newest_is_decoded(
        sim: AtlasSimulator, monkeypatch: pytest.MonkeyPatch) -> None:
    """A flood costs one decode per step: the newest complete command hides the rest."""
    loop, _, _, _ = make_loop(sim)
    decoded: list[bytes] = []
    original = loop.inbox._decode
    monkeypatch.setattr(loop.inbox, '_decode', lambda topic, raw: (decoded.append(raw),
                                                                   original(topic, raw))[1])
    sent = [complete_command(0.1 * k, stamp_ns=k * NS_PER_S) for k in (1, 2, 3)]
    for raw in sent:
        loop.receive_command(raw)
    loop.apply_pending_commands()
    assert decoded == [sent[-1]]
    np.testing.assert_array_equal(sim.user_command.position, [0.1 * 3] * NUM_JOINTS)
    assert loop.statistics.command_stamp_ns == 3 * NS_PER_S


def test_a_refused_command_keeps_the_previous_one(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    loop.receive_command(complete_command(0.1, stamp_ns=3 * NS_PER_S))
    loop.receive_command(command_bytes(['neck_ay'], kd_position=[1e12], stamp_ns=4 * NS_PER_S))
    loop.apply_pending_commands()
    np.testing.assert_array_equal(sim.user_command.position, [0.1] * NUM_JOINTS)
    assert len(log.of('refused')) == 1
    assert log.of('refused')[0].startswith('refused /atlas/joint_commands: kd_position[0]')
    assert loop.statistics.command_stamp_ns == 3 * NS_PER_S


def test_commands_are_applied_while_paused_without_stepping(sim: AtlasSimulator) -> None:
    loop, outbox, _, _ = make_loop(sim, paused=True)
    loop.receive_command(complete_command(0.1))
    loop.run(stops_after(3))
    assert sim.sim_time_ns == 0 and loop.step_count == 0
    np.testing.assert_array_equal(sim.user_command.position, [0.1] * NUM_JOINTS)
    assert len(outbox.queued()[topics.JOINT_STATES]) == 1  # the initial state only
    assert loop.pacer.clock.slept_s == [PAUSED_POLL_S] * 3


class CountingController:
    """A StepController of its own: what users sent, then a note of the step it is for."""

    def __init__(self, inbox: CommandInbox, sim: AtlasSimulator) -> None:
        self.inbox, self.sim = inbox, sim
        self.steps_ns: list[int] = []

    def before_step(self) -> None:
        self.inbox.apply_pending()
        self.steps_ns.append(self.sim.sim_time_ns)


def test_a_controller_plugs_in_and_is_called_once_before_each_step(sim: AtlasSimulator) -> None:
    """Once per step, before it, never while paused; what users sent still acts."""
    outbox = FakeOutbox(set(ALL_TOPICS))
    made: list[CountingController] = []
    loop = SteppingLoop(sim, LoopOutputs(outbox, {t: t for t in ALL_TOPICS}, FakeLog(),
                                         lambda _text: None),
                        LoopSettings(LAUNCH_RATES_HZ), CommandAgeStatistics(sim.dt_s),
                        controller=lambda inbox: made.append(CountingController(inbox, sim))
                        or made[-1])
    loop.receive_command(complete_command(0.1))
    loop.run(stops_after(5))
    loop.pause()
    loop.run(stops_after(3))
    assert [controller.steps_ns for controller in made] == [[k * sim.step_ns for k in range(5)]]
    np.testing.assert_array_equal(sim.user_command.position, [0.1] * NUM_JOINTS)


def wait_for(condition, what: str, timeout_s: float = 30.0) -> None:
    """Poll `condition` (another thread makes it true) until it holds, or fail naming it."""
    deadline = time.monotonic() + timeout_s
    while not condition():
        assert time.monotonic() < deadline, f'waited {timeout_s} s for {what}'
        time.sleep(0.001)


def test_pause_returns_once_the_loop_has_stopped_and_sent_what_it_stepped(
        sim: AtlasSimulator) -> None:
    """/gazebo/pause_physics from another thread: when it returns, the last /clock sent is
    the paused time, and no step follows (the loop's batches are flushed first)."""
    loop, outbox, _, _ = make_loop(sim)  # its wall clock stands still: nothing is flushed
    stop = threading.Event()           # until the loop pauses
    runner = threading.Thread(target=loop.run, args=(stop.is_set,))
    runner.start()
    try:
        wait_for(lambda: sim.sim_time_ns >= 20 * sim.step_ns, '20 steps')
        loop.pause()
        paused_ns = sim.sim_time_ns
        assert clock_ns(outbox.sent[topics.CLOCK][-1]) == paused_ns
        flushes = outbox.flushes
        wait_for(lambda: outbox.flushes >= flushes + 20, '20 polls while paused')
        assert sim.sim_time_ns == paused_ns
    finally:
        stop.set()
        runner.join()
    assert not loop.controls.loop_running


# -- services ------------------------------------------------------------------------------

def test_resets_republish_the_config_and_set_mode_returns_the_previous(
        sim: AtlasSimulator) -> None:
    loop, _, log, configs = make_loop(sim)
    loop.run(stops_after(5))
    assert loop.set_mode(ControlMode.USER) is ControlMode.STAND
    loop.reset_world()
    assert sim.sim_time_ns == 5 * sim.step_ns  # sim time kept
    loop.reset_simulation()
    assert sim.sim_time_ns == 0
    assert len(configs) == 2
    assert log.of('info')[-2:] == [
        'reset_world: robot back to its initial pose at t=0.005 s (torso pinned for 1.0 s)',
        'reset_simulation: robot reset and sim time back to 0']
    loop.reset_world(by=' (viewer)')
    assert log.of('info')[-1] == ('reset_world (viewer): robot back to its initial pose at '
                                  't=0.000 s (torso pinned for 1.0 s)')


# -- headless feedback: falls and commands the mode ignores -------------------------------

def first_step_below_fall_height(atlas: atlas_model.AtlasModel, steps: int) -> int:
    """The same limp robot stepped by hand: the step after which its pelvis is first below
    FALL_HEIGHT_M (determinism makes it the loop's too)."""
    twin = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    twin.set_mode(ControlMode.RAGDOLL)
    for step in range(1, steps + 1):
        twin.step()
        if pelvis_height_m(atlas, twin.data) < FALL_HEIGHT_M:
            return step
    raise AssertionError(f'the limp robot did not fall within {steps} steps')


def test_a_fall_is_logged_once_and_again_after_a_reset(atlas: atlas_model.AtlasModel) -> None:
    limp = AtlasSimulator(atlas, load_gains_yaml(CONFIG), time_to_unpin_s=0.0)
    loop, _, log, _ = make_loop(limp)
    loop.set_mode(ControlMode.RAGDOLL)
    fall_step = first_step_below_fall_height(atlas, 3000)
    loop.run(stops_after(fall_step + 500))  # lying on the ground 0.5 s on: still one line
    assert pelvis_height_m(atlas, limp.data) < FALL_HEIGHT_M
    falls = [line for line in log.of('info') if 'fell' in line]
    assert falls == [f'the robot fell: pelvis below 0.5 m at sim time {fall_step / 1000:.3f} s, '
                     'before any command of the try']

    loop.reset_world()
    start_ns = limp.sim_time_ns
    loop.receive_command(complete_command(0.0))  # ignored in ragdoll, but the first command
    loop.run(stops_after(fall_step))
    falls = [line for line in log.of('info') if 'fell' in line]
    assert len(falls) == 2
    assert falls[1] == (f'the robot fell: pelvis below 0.5 m at sim time '
                        f'{(start_ns / NS_PER_S) + fall_step / 1000:.3f} s, '
                        f"{fall_step / 1000:.3f} s after the try's first command")


def test_a_standing_robot_logs_no_fall(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    loop.run(stops_after(2000))
    assert pelvis_height_m(sim.atlas, sim.data) > 0.8
    assert not [line for line in log.of('info') if 'fell' in line]


NOT_USER_WARNING = ('/atlas/joint_commands arrive in {mode} mode, which does not apply them; '
                    'switch to User mode: '
                    'rostopic pub /atlas/control_mode std_msgs/String -- "User"')


def test_commands_outside_user_mode_warn_at_once_then_throttled(sim: AtlasSimulator) -> None:
    loop, _, log, _ = make_loop(sim)
    period_steps = int(NOT_USER_WARN_PERIOD_S * 1000)

    def play(steps: int) -> None:  # a command every step, as a 1 kHz controller
        for _ in range(steps):
            loop.receive_command(complete_command(0.0))
            loop.run(stops_after(1))

    play(period_steps)  # 5 s of commands in Stand: one warning
    assert log.of('warn') == [NOT_USER_WARNING.format(mode='Stand')]
    play(2)  # the period is over: a second one
    assert log.of('warn') == [NOT_USER_WARNING.format(mode='Stand')] * 2
    loop.set_mode(ControlMode.USER)
    play(10)
    assert len(log.of('warn')) == 2  # applied: nothing to say
    loop.set_mode(ControlMode.FREEZE)  # a new mode that ignores them: at once
    play(1)
    assert log.of('warn')[2:] == [NOT_USER_WARNING.format(mode='Freeze')]


def test_inputs_apply_between_steps_publish_their_event_and_log_once_a_second(
        sim: AtlasSimulator) -> None:
    from tutorial_atlas_control.sim.vrc import InputEvent, wrench_input

    outbox = FakeOutbox(set(ALL_TOPICS))
    log, events = FakeLog(), []
    outputs = LoopOutputs(outbox, {topic: topic for topic in ALL_TOPICS}, log,
                          lambda text: None, publish_input=events.append)
    loop = SteppingLoop(sim, outputs, LoopSettings(LAUNCH_RATES_HZ),
                        CommandAgeStatistics(sim.dt_s))
    loop.run(stops_after(3))
    for _ in range(5):  # a 1 kHz wrench stream
        loop.apply_input(wrench_input((1.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        loop.run(stops_after(1))
    parsed = [InputEvent.from_json(text) for text in events]
    assert [(e.time_ns, e.seq) for e in parsed] == [(3_000_000 + k * 1_000_000, k)
                                                    for k in range(5)]
    assert log.of('info')[-1] == ('applied at t=0.003 s: /atlas/apply_pelvis_force '
                                  'force=[1.0, 0.0, 0.0], torque=[0.0, 0.0, 0.0]')
    assert sum('applied at' in text for text in log.of('info')) == 1


# -- pacing --------------------------------------------------------------------------------

def test_unpaced_runs_flush_every_flush_period() -> None:
    clock = FakeClock()
    pacer = Pacer(0.0, clock, clock.sleep)
    pacer.restart(0)
    pacer.flushed()
    decisions = []
    for step in range(1, 11):
        clock.now_s += 1 / 1024  # a step takes just under 1 ms (exact in binary)
        decisions.append(pacer.flush_due(step * 1_000_000))
        pacer.wait(step * 1_000_000)
    assert pacing.FLUSH_PERIOD_S == 0.004
    assert decisions == [False, False, False, False, True, False, False, False, False, True]
    assert clock.slept_s == []


def test_paced_runs_flush_every_step_on_time_and_sleep_until_due() -> None:
    clock = FakeClock()
    pacer = Pacer(0.5, clock, clock.sleep)  # half real time: 1 ms of sim in 2 ms of wall
    pacer.restart(0)
    pacer.flushed()
    clock.now_s += 0.0005  # the step took 0.5 ms
    assert pacer.flush_due(1_000_000)
    pacer.wait(1_000_000)
    assert clock.slept_s == [pytest.approx(0.0015)]


def test_a_lagging_paced_run_flushes_less_until_it_has_caught_up() -> None:
    clock = FakeClock()
    pacer = Pacer(1.0, clock, clock.sleep)
    pacer.restart(0)
    pacer.flushed()
    clock.now_s += 0.125  # a stall: 125 ms behind after the first step
    decisions = []
    for step in range(1, 8):
        decisions.append(pacer.flush_due(step * 1_000_000))
        pacer.wait(step * 1_000_000)
        clock.now_s += 1 / 256  # each step takes just under 4 ms: it stays behind
    assert decisions == [True, False, True, False, True, False, True]
    assert clock.slept_s == []  # still behind: no sleep


def test_a_stalled_paced_run_catches_up_at_twice_the_factor_not_in_a_burst() -> None:
    """After a 100 ms stall at real time, steps of 0.1 ms go no closer than half their 1 ms
    share (a client's answer still has 0.4 ms to arrive), until the run is on schedule."""
    clock = FakeClock()
    pacer = Pacer(1.0, clock, clock.sleep)
    pacer.restart(0)
    clock.now_s += 0.100  # the stall, before the first step
    released = []
    for step in range(1, 301):
        clock.now_s += 0.0001  # the step
        pacer.wait(step * 1_000_000)
        released.append(clock.now_s)
    gaps_ms = np.diff(released) * 1e3
    assert pacing.CATCH_UP_SPEEDUP == 2.0
    # The lag shrinks by 0.5 ms a step: caught up after about 200 steps, then 1 ms a step.
    assert gaps_ms[:190] == pytest.approx(np.full(190, 0.5))
    assert gaps_ms[210:] == pytest.approx(np.full(89, 1.0))
    assert clock.now_s == pytest.approx(pacer.due_s(300 * 1_000_000))


def test_a_run_too_far_behind_gives_up_catching_up() -> None:
    clock = FakeClock()
    pacer = Pacer(1.0, clock, clock.sleep)
    pacer.restart(0)
    clock.now_s += pacing.MAX_LAG_S + 0.5
    pacer.wait(1_000_000)
    assert clock.slept_s == []
    # Rescheduled: the next step is due a step of sim time from now.
    pacer.wait(2_000_000)
    assert clock.slept_s == [pytest.approx(0.001)]


def test_a_rewind_restarts_the_schedule() -> None:
    clock = FakeClock()
    pacer = Pacer(1.0, clock, clock.sleep)
    pacer.restart(5 * NS_PER_S)
    pacer.flush_due(1_000_000)  # reset_simulation: sim time back near 0
    assert pacer.sim0_ns == 1_000_000
    pacer.wait(2_000_000)
    assert clock.slept_s == [pytest.approx(0.001)]


# -- divergence ------------------------------------------------------------------------------

def test_divergences_in_a_row_stop_spaced_ones_do_not() -> None:
    guard = DivergenceGuard()
    repeat_ns = int(DIVERGENCE_REPEAT_S * NS_PER_S)
    assert guard.retry(10 * NS_PER_S)
    assert guard.retry(10 * NS_PER_S + repeat_ns + 1)  # too late to be "in a row"
    assert guard.retry(10 * NS_PER_S + 2 * repeat_ns)  # 2nd in a row
    assert MAX_DIVERGENCES_IN_A_ROW == 3
    assert not guard.retry(10 * NS_PER_S + 2 * repeat_ns + 1)  # 3rd in a row: stop


def test_a_rewind_between_divergences_does_not_count_as_in_a_row() -> None:
    guard = DivergenceGuard()
    assert guard.retry(5 * NS_PER_S)
    assert guard.retry(5 * NS_PER_S)
    assert guard.retry(1_000_000)  # reset_simulation rewound: 1st again
    assert guard.in_a_row == 1


def test_a_model_that_keeps_diverging_stops_the_loop(sim: AtlasSimulator,
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    loop, _, log, configs = make_loop(sim)

    def diverge() -> None:
        raise PhysicsDivergenceError('physics diverged at t=0.001 s')
    monkeypatch.setattr(sim, 'step', diverge)
    assert loop.run(stops_after(100)) == 1
    assert loop.exit_status == 1
    assert len(log.of('error')) == MAX_DIVERGENCES_IN_A_ROW - 1
    assert len(configs) == MAX_DIVERGENCES_IN_A_ROW - 1  # re-published after each reset
    assert log.of('fatal') == [
        f'physics diverged at t=0.001 s: 3 times in a row, each within 1.0 s of the reset; '
        f'the model {sim.atlas_path} is unstable; stopping the simulator']
    assert loop.step_count == MAX_DIVERGENCES_IN_A_ROW - 1
