"""DRCSim 2.6's synchronization window without ROS: the budgets with a fake wall clock,
DRCSim's freshness test, and the stepping loop waiting for (and only for) the commands
that ask for it."""

from __future__ import annotations

import io
import struct
from pathlib import Path

import numpy as np
import pytest

from support.stepping_fakes import (
    ALL_TOPICS,
    LAUNCH_RATES_HZ,
    FakeClock,
    FakeLog,
    FakeOutbox,
    atlas_bytes,
    complete_command,
    full,
    header_stamp_ns,
    stops_after,
)
from tutorial_atlas_control import topics
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.sim import model as atlas_model
from tutorial_atlas_control.sim.controller import load_gains_yaml
from tutorial_atlas_control.sim.controller_statistics import CommandAgeStatistics
from tutorial_atlas_control.sim.simulator import AtlasSimulator
from tutorial_atlas_control.stepping.loop import LoopSettings, SteppingLoop
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.pacing import MAX_LAG_S, Pacer
from tutorial_atlas_control.stepping.synchronization import (
    MAX_PER_STEP_PARAM,
    DelayBudgets,
    SyncConfigError,
    SynchronizationWindow,
    SyncOutcome,
    is_fresh,
    statistics_bytes,
)
from tutorial_atlas_control.units import NS_PER_S

CONFIG = Path(__file__).resolve().parents[3] / 'config' / 'atlas_controller.yaml'
BUDGETS = DelayBudgets(window_size_s=1.0, max_per_window_s=0.06, max_per_step_s=0.025)
STEP_NS = NS_PER_S // 1000


@pytest.fixture(scope='module')
def atlas() -> atlas_model.AtlasModel:
    return atlas_model.load_model()


@pytest.fixture
def sim(atlas: atlas_model.AtlasModel) -> AtlasSimulator:
    return AtlasSimulator(atlas, load_gains_yaml(CONFIG))


class SilentController:
    """A wait that always runs to its timeout: the controller has stopped."""

    def __init__(self, clock: FakeClock) -> None:
        self.clock = clock
        self.timeouts_s: list[float] = []

    def __call__(self, timeout_s: float) -> bool:
        self.timeouts_s.append(timeout_s)
        self.clock.now_s += timeout_s
        return False


def never_fresh() -> bool:
    return False


# -- the window's bookkeeping ------------------------------------------------------------

def test_is_fresh_is_drcsims_test_in_integer_ns() -> None:
    assert is_fresh(5 * STEP_NS, 4 * STEP_NS, 1)  # the last state's answer, period 1 ms
    assert not is_fresh(5 * STEP_NS, 4 * STEP_NS - 1, 1)
    assert is_fresh(5 * STEP_NS, 3 * STEP_NS, 2)
    assert is_fresh(5 * STEP_NS, 6 * STEP_NS, 1)  # a stamp ahead (a rewound clock) is fresh


def test_a_fresh_command_costs_no_wait() -> None:
    clock = FakeClock()
    window = SynchronizationWindow(BUDGETS, clock)
    waits: list[float] = []
    report = window.enforce(lambda: True, lambda t: waits.append(t) or True)
    assert waits == []
    assert (report.delay_in_step_s, report.delay_in_window_s, report.outcome) == (
        0.0, 0.0, SyncOutcome.FRESH)
    assert report.delay_window_remain_s == pytest.approx(1.0)


def test_the_wait_ends_when_a_fresh_command_arrives() -> None:
    clock = FakeClock()
    window = SynchronizationWindow(BUDGETS, clock)
    arrived = {'fresh': False}

    def answer_after_3_ms(timeout_s: float) -> bool:
        assert timeout_s == pytest.approx(0.025)
        clock.now_s += 0.003
        arrived['fresh'] = True
        return True
    report = window.enforce(lambda: arrived['fresh'], answer_after_3_ms)
    assert report.outcome is SyncOutcome.FRESH and report.timeouts == 0
    assert report.delay_in_step_s == pytest.approx(0.003)
    assert report.delay_in_window_s == pytest.approx(0.003)


def test_a_stale_wake_up_waits_again_for_what_is_left_of_the_step() -> None:
    clock = FakeClock()
    window = SynchronizationWindow(BUDGETS, clock)
    silent = SilentController(clock)
    calls = {'n': 0}

    def stale_then_silent(timeout_s: float) -> bool:
        calls['n'] += 1
        if calls['n'] == 1:  # a stale command (or /atlas/debug/sync_delay) after 10 ms
            clock.now_s += 0.010
            return True
        return silent(timeout_s)
    report = window.enforce(never_fresh, stale_then_silent)
    assert silent.timeouts_s == [pytest.approx(0.015)]
    assert report.outcome is SyncOutcome.STEP_BUDGET and report.timeouts == 1
    assert report.delay_in_step_s == pytest.approx(0.025)


def test_a_silent_controller_spends_the_step_then_the_window_budget() -> None:
    clock = FakeClock()
    window = SynchronizationWindow(BUDGETS, clock)
    silent = SilentController(clock)
    reports = [window.enforce(never_fresh, silent) for _ in range(4)]
    # 25 ms, 25 ms, then the 10 ms left of the window's 60 ms; then no wait at all.
    assert silent.timeouts_s == [pytest.approx(0.025), pytest.approx(0.025),
                                 pytest.approx(0.010)]
    assert [report.outcome for report in reports] == [
        SyncOutcome.STEP_BUDGET, SyncOutcome.STEP_BUDGET, SyncOutcome.WINDOW_BUDGET,
        SyncOutcome.WINDOW_BUDGET]
    assert [report.delay_in_step_s for report in reports] == pytest.approx(
        [0.025, 0.025, 0.010, 0.0])
    assert [report.delay_in_window_s for report in reports] == pytest.approx(
        [0.025, 0.050, 0.060, 0.060])
    assert [report.delay_window_remain_s for report in reports] == pytest.approx(
        [1.0, 0.975, 0.950, 0.940])
    # The window ends 1 s after it opened: the next step waits again.
    clock.now_s += 0.940
    report = window.enforce(never_fresh, silent)
    assert report.outcome is SyncOutcome.STEP_BUDGET
    assert (report.delay_in_step_s, report.delay_in_window_s) == pytest.approx((0.025, 0.025))
    assert report.delay_window_remain_s == pytest.approx(1.0)


def test_budgets_from_params_default_to_drcsims() -> None:
    assert DelayBudgets.from_params(lambda _name, default: default) == DelayBudgets(
        5.0, 0.25, 0.025)
    set_ = {MAX_PER_STEP_PARAM: 0.002}
    assert DelayBudgets.from_params(lambda name, default: set_.get(name, default)) == \
        DelayBudgets(5.0, 0.25, 0.002)


@pytest.mark.parametrize('value', [-0.1, float('nan'), 'fast', True])
def test_a_bad_budget_is_refused_naming_the_parameter(value: object) -> None:
    with pytest.raises(SyncConfigError) as info:
        DelayBudgets.from_params(
            lambda name, default: value if name == MAX_PER_STEP_PARAM else default)
    assert str(info.value) == (f'parameter /atlas/delay_max_per_step is {value!r}; it must '
                               'be a number of seconds >= 0 (default 0.025)')


def test_statistics_bytes_are_the_message_on_the_wire() -> None:
    window = SynchronizationWindow(BUDGETS, FakeClock())
    report = window.enforce(lambda: True, lambda _t: True)
    data = statistics_bytes(report)
    assert struct.unpack('<I3d', data) == (24, 0.0, 0.0, pytest.approx(1.0))


# -- the stepping loop -------------------------------------------------------------------

SYNC_TOPICS = (*ALL_TOPICS, topics.SYNCHRONIZATION_STATISTICS)


def make_sync_loop(sim: AtlasSimulator, budgets: DelayBudgets = BUDGETS
                   ) -> tuple[SteppingLoop, FakeOutbox, FakeLog, FakeClock]:
    outbox = FakeOutbox(set(SYNC_TOPICS))
    log = FakeLog()
    clock = FakeClock()
    outputs = LoopOutputs(outbox, {topic: topic for topic in SYNC_TOPICS}, log,
                          lambda _text: None)
    loop = SteppingLoop(sim, outputs, LoopSettings(LAUNCH_RATES_HZ),
                        CommandAgeStatistics(sim.dt_s), pacer=Pacer(0.0, clock, clock.sleep),
                        synchronization=SynchronizationWindow(budgets, clock))
    return loop, outbox, log, clock


def command_ages_ns(outbox: FakeOutbox) -> list[int]:
    return [int(round(struct.unpack_from('<d', data, len(data) - 32)[0] * NS_PER_S))
            for data in outbox.queued()[topics.CONTROLLER_STATISTICS]]


def sync_statistics(outbox: FakeOutbox) -> list[tuple[float, float, float]]:
    return [struct.unpack('<I3d', data)[1:]
            for data in outbox.queued().get(topics.SYNCHRONIZATION_STATISTICS, [])]


class EchoController:
    """Answers the latest joint state it was sent (flushed), as a controller would: an
    AtlasCommand stamped with the state's stamp, holding its positions."""

    def __init__(self, loop: SteppingLoop, outbox: FakeOutbox, clock: FakeClock,
                 period_ms: int = 1) -> None:
        self.loop, self.outbox, self.clock, self.period_ms = loop, outbox, clock, period_ms
        self.answered: list[int] = []

    def answer(self, timeout_s: float) -> bool:
        states = self.outbox.sent.get(topics.JOINT_STATES, [])
        stamp_ns = header_stamp_ns(states[-1])
        if self.answered and self.answered[-1] == stamp_ns:
            return SilentController(self.clock)(timeout_s)  # nothing new to answer
        self.answered.append(stamp_ns)
        self.clock.now_s += 0.0002
        self.loop.receive_command(atlas_bytes(
            stamp_ns, self.period_ms, position=list(self.loop.sim.joint_positions()),
            k_effort=full(255)), topics.ATLAS_COMMAND)
        return True


def test_with_the_window_every_step_obeys_the_answer_to_the_state_before(
        sim: AtlasSimulator) -> None:
    loop, outbox, log, clock = make_sync_loop(sim)
    echo = EchoController(loop, outbox, clock)
    loop.gate.wait_for_command = echo.answer
    # The first command, stamped 0, asks for the window and is applied at the first step;
    # from the second step on, each step waits for the answer to the last state.
    loop.receive_command(atlas_bytes(0, 1, k_effort=full(255), position=full(0.0)),
                         topics.ATLAS_COMMAND)
    loop.run(stops_after(50))
    assert echo.answered == [step * STEP_NS for step in range(1, 50)]
    # (the first command's zero stamp counts as "when applied": age 0)
    assert command_ages_ns(outbox) == [0] + [STEP_NS] * 49
    assert [line for line in log.of('warn')] == []
    delays = sync_statistics(outbox)
    assert len(delays) == 49
    assert all(step == pytest.approx(0.0002) for step, _, _ in delays)
    assert delays[-1][1] == pytest.approx(49 * 0.0002)  # all in the same window


def test_an_answer_received_before_a_reset_is_not_the_first_steps(
        sim: AtlasSimulator) -> None:
    """A controller's answer to the state published before the first step (stamped 0) that
    arrived while paused, then /gazebo/reset_simulation: the steps after the reset are
    answered each by the state before, the first's age one step (not 0, the stamp-0
    command's "when applied": the rostest sync_lockstep once saw that)."""
    loop, outbox, _, clock = make_sync_loop(sim)
    loop.receive_command(atlas_bytes(0, 1, k_effort=full(255),
                                     position=list(sim.joint_positions())),
                         topics.ATLAS_COMMAND)
    loop.reset_simulation()
    echo = EchoController(loop, outbox, clock)
    loop.gate.wait_for_command = echo.answer
    loop.run(stops_after(20))
    assert command_ages_ns(outbox) == [STEP_NS] * 20


def test_the_state_is_sent_before_the_wait(sim: AtlasSimulator) -> None:
    # At real_time_factor 0 the loop batches sends (pacing.FLUSH_PERIOD_S); a wait with
    # the state still queued would wait for an answer to a state nobody received.
    loop, outbox, _, clock = make_sync_loop(sim)
    seen: list[int] = []

    def wait(timeout_s: float) -> bool:
        seen.append(header_stamp_ns(outbox.sent[topics.JOINT_STATES][-1]))
        assert topics.JOINT_STATES not in outbox.pending
        return SilentController(clock)(timeout_s)
    loop.gate.wait_for_command = wait
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    loop.run(stops_after(3))
    assert seen == [STEP_NS, 2 * STEP_NS]


def test_a_silent_controller_is_waited_for_within_the_budgets(sim: AtlasSimulator) -> None:
    loop, outbox, log, clock = make_sync_loop(sim)
    silent = SilentController(clock)
    loop.gate.wait_for_command = silent
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    loop.run(stops_after(6))
    assert sim.sim_time_ns == 6 * STEP_NS  # the simulation went on
    assert silent.timeouts_s == [pytest.approx(0.025), pytest.approx(0.025),
                                 pytest.approx(0.010)]
    # From the second step (the first applied the command asking for the window):
    assert [value for stat in sync_statistics(outbox) for value in stat[:2]] == pytest.approx(
        [0.025, 0.025, 0.025, 0.05, 0.01, 0.06, 0.0, 0.06, 0.0, 0.06])
    assert command_ages_ns(outbox) == [step * STEP_NS for step in range(6)]  # stale, growing
    assert log.of('warn') == [
        'synchronization window: no command stamped within 1 ms of t=0.002 s (step budget '
        'spent, 0.025 s waited in this window); stepping on with the latest command (1 step(s) '
        'so since the last such line; controller stopped or messages lost?)']


@pytest.mark.parametrize('command', ['joint_commands', 'period_0'])
def test_2_5_era_commands_never_wait(sim: AtlasSimulator, command: str) -> None:
    loop, outbox, log, clock = make_sync_loop(sim)

    def no_wait(_timeout_s: float) -> bool:
        raise AssertionError('the loop waited')
    loop.gate.wait_for_command = no_wait
    if command == 'joint_commands':
        loop.receive_command(complete_command(0.1, stamp_ns=0))
    else:
        loop.receive_command(atlas_bytes(0, 0, position=full(0.1), k_effort=full(255)),
                             topics.ATLAS_COMMAND)
    loop.run(stops_after(5))
    assert sim.sim_time_ns == 5 * STEP_NS
    assert sync_statistics(outbox) == []
    assert not any('synchronization' in line for _, line in log.lines)


def test_a_period_0_command_turns_the_window_off(sim: AtlasSimulator) -> None:
    loop, outbox, log, clock = make_sync_loop(sim)
    waits: list[float] = []

    def turn_off(_timeout_s: float) -> bool:
        waits.append(_timeout_s)
        loop.receive_command(atlas_bytes(0, 0, position=full(0.0)), topics.ATLAS_COMMAND)
        return True
    loop.gate.wait_for_command = turn_off
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    loop.run(stops_after(4))
    assert len(waits) == 1  # at the second step; the third and fourth do not wait
    assert len(sync_statistics(outbox)) == 1
    assert log.of('info')[-1] == 'synchronization window off (desired_controller_period_ms = 0)'
    np.testing.assert_array_equal(sim.user_command.position, np.zeros(NUM_JOINTS))


def test_a_command_wakes_the_wait_only_while_the_window_is_on(sim: AtlasSimulator) -> None:
    loop, _, _, _ = make_sync_loop(sim)
    loop.receive_command(complete_command(0.1))
    assert not loop.inbox.arrived.is_set()  # 2.5-era traffic costs no wake-up
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    loop.apply_pending_commands()
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    assert loop.gate.wait_for_command(0.0)


def test_shutdown_ends_the_wait(sim: AtlasSimulator) -> None:
    loop, _, _, clock = make_sync_loop(sim, DelayBudgets(1000.0, 1000.0, 100.0))
    state = {'down': False, 'waits': 0}

    def wait(timeout_s: float) -> bool:
        state['waits'] += 1
        if state['waits'] == 1:
            state['down'] = True  # rospy shuts down during the wait; its hook:
            loop.stop_waiting()
            return True
        clock.now_s += timeout_s  # (a wait that went on would wait out the step's 100 s)
        return False
    loop.gate.wait_for_command = wait
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    turns = stops_after(3)
    loop.run(lambda: turns() or state['down'])
    assert state['waits'] == 1  # woken, it saw the shutdown and waited no more


def test_statistics_match_genpy_and_the_latch_is_what_rospy_sends() -> None:
    from atlas_msgs.msg import SynchronizationStatistics
    from rospy.msg import serialize_message

    from tutorial_atlas_control.node.sim_node import RawLatched

    clock = FakeClock()
    window = SynchronizationWindow(BUDGETS, clock)
    report = window.enforce(never_fresh, SilentController(clock))
    data = statistics_bytes(report)
    buff = io.BytesIO()
    SynchronizationStatistics(report.delay_in_step_s, report.delay_in_window_s,
                              report.delay_window_remain_s).serialize(buff)
    assert data[4:] == buff.getvalue()
    sent = io.BytesIO()
    serialize_message(sent, 7, RawLatched(data[4:]))  # rospy's latch to a new subscriber
    assert sent.getvalue() == data


def test_the_latest_statistics_are_kept_for_later_subscribers(sim: AtlasSimulator) -> None:
    outbox = FakeOutbox(set(ALL_TOPICS))  # nobody subscribes to the statistics
    clock = FakeClock()
    latched: list[bytes] = []
    outputs = LoopOutputs(outbox, {topic: topic for topic in SYNC_TOPICS}, FakeLog(),
                          lambda _text: None, latch_synchronization=latched.append)
    loop = SteppingLoop(sim, outputs, LoopSettings(LAUNCH_RATES_HZ),
                        CommandAgeStatistics(sim.dt_s), pacer=Pacer(0.0, clock, clock.sleep),
                        synchronization=SynchronizationWindow(BUDGETS, clock))
    loop.gate.wait_for_command = SilentController(clock)
    loop.receive_command(atlas_bytes(0, 1), topics.ATLAS_COMMAND)
    loop.run(stops_after(3))
    assert sync_statistics(outbox) == []
    assert [struct.unpack('<3d', data)[:2] for data in latched] == [
        pytest.approx((0.025, 0.025)), pytest.approx((0.025, 0.05))]


# -- the window at real_time_factor > 0: the factor a ceiling, waits caught up --------------
#: Wall time (s) the physics of one step takes in these runs, and the steps run.
PHYSICS_S = 0.0001
PACED_STEPS = 1000


def paced_run(real_time_factor: float, wait_s: dict[int, float]) -> tuple[FakeClock, Pacer,
                                                                          list[float]]:
    """PACED_STEPS steps of 1 ms as the loop paces them: the controller's wait (wait_s[k] at
    step k, else none), the physics, then the pacer's wait. Returns the clock, the pacer and
    how far ahead of wall time sim time was after each step (s; <= 0: never ahead)."""
    clock = FakeClock()
    pacer = Pacer(real_time_factor, clock, clock.sleep)
    pacer.restart(0)
    start_s, ahead_s = clock(), []
    for step in range(1, PACED_STEPS + 1):
        clock.now_s += wait_s.get(step, 0.0) + PHYSICS_S
        sim_ns = step * 1_000_000
        pacer.wait(sim_ns)
        ahead_s.append(sim_ns / NS_PER_S / real_time_factor - (clock() - start_s))
    return clock, pacer, ahead_s


def test_a_controller_answering_within_the_step_costs_no_wait() -> None:
    """README: at real_time_factor > 0 an answer within the step's share costs no wall time:
    the pacer sleeps what is left of the step; the run takes its 1 s, not 1 s + the answers."""
    answer_s = 0.0003
    clock, _pacer, ahead_s = paced_run(1.0, dict.fromkeys(range(1, PACED_STEPS + 1), answer_s))
    assert clock.now_s - 100.0 == pytest.approx(PACED_STEPS * 0.001, abs=1e-9)
    assert clock.slept_s == pytest.approx([0.001 - answer_s - PHYSICS_S] * PACED_STEPS)
    assert max(ahead_s) <= 1e-9


def test_a_late_answer_is_caught_up_and_the_factor_stays_a_ceiling() -> None:
    """README: a 20 ms wait (within the step's 25 ms budget) makes the loop late; it then
    runs at up to twice the factor until it is back on schedule (within MAX_LAG_S), and sim
    time is never ahead of wall time x the factor."""
    for factor in (0.5, 1.0):
        clock, _pacer, ahead_s = paced_run(factor, {100: 0.020})
        assert clock.now_s - 100.0 == pytest.approx(PACED_STEPS * 0.001 / factor, abs=1e-9)
        assert max(ahead_s) <= 1e-9, 'sim time ran ahead of real time x the factor'
        behind = [step for step, ahead in enumerate(ahead_s, 1) if ahead < -1e-9]
        # Late from step 100 until the 20 ms are made up (a step's share less its physics
        # each step): one stretch, then on schedule to the end.
        assert behind and behind[0] == 100 and behind == list(range(100, behind[-1] + 1))
        assert behind[-1] < PACED_STEPS


def test_a_wait_beyond_the_lag_limit_restarts_the_schedule() -> None:
    """Behind by more than MAX_LAG_S the pacer stops catching up: sim time due from then."""
    wait_s = MAX_LAG_S + 0.5
    clock, pacer, _ahead_s = paced_run(1.0, {100: wait_s})
    assert pacer.sim0_ns == 100 * 1_000_000
    # 99 steps on schedule, step 100 with its wait (the new reference), 900 steps of 1 ms.
    assert clock.now_s - 100.0 == pytest.approx(0.099 + wait_s + PHYSICS_S + 0.900, abs=1e-9)
