"""The simulator node's stepping loop, without ROS.

Each turn: one tick (tick.py: the controller gives the simulator its command, by default
the commands that arrived since the last step; the step; what is due serialized into the
outbox; the AtlasSimInterface's end of step), then decide whether to send it, and wait for
wall time. Each concern is a collaborator of its own:
the command inbox (inbox.py), what is published (publication.py), the synchronization
window (sync_gate.py), resets and services (controls.py), the headless log lines
(watch.py) and divergence recovery (divergence.py); a controller plugs in as a
StepController (controller.py).

The node (node/sim_node.py) gives it LoopOutputs (rospy publishers behind
transport.WireBatch, rospy's log) and its shutdown test; tests give it fakes.
"""

from __future__ import annotations

import threading
from collections.abc import Callable, Mapping
from dataclasses import dataclass, field
from pathlib import Path

from tutorial_atlas_control.asi import AtlasSimInterface, LibraryBehaviour
from tutorial_atlas_control.sim import AtlasSimulator, CommandAgeStatistics, LinkTransforms
from tutorial_atlas_control.stepping.controller import StepController
from tutorial_atlas_control.stepping.controls import SimControls
from tutorial_atlas_control.stepping.course_scoring import CourseScoring
from tutorial_atlas_control.stepping.divergence import DivergenceRecovery
from tutorial_atlas_control.stepping.inbox import CommandInbox
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.pacing import Pacer
from tutorial_atlas_control.stepping.publication import StepPublisher
from tutorial_atlas_control.stepping.sync_gate import SyncGate
from tutorial_atlas_control.stepping.synchronization import DelayBudgets, SynchronizationWindow
from tutorial_atlas_control.stepping.tick import Tick
from tutorial_atlas_control.stepping.watch import RunWatch

__all__ = ['PAUSED_POLL_S', 'LoopSettings', 'SteppingLoop']

#: While paused, the loop looks for commands and shutdown this often (s, wall).
PAUSED_POLL_S = 0.01


@dataclass(frozen=True)
class LoopSettings:
    """How the loop runs.

    Attributes:
        rates_hz: rate (Hz of sim time; 0 = every step) of each message, by the keys of
            publication.StepPublisher (the table's defaults for those not given).
        real_time_factor: sim time per wall time; 0 = as fast as possible.
        paused: start with physics paused.
        links: with a /tf outlet, the links' transforms published in robot_state_publisher's
            stead (link_transforms.py); None: not.
        balance_stand: Stand is the open AtlasSimInterface's balancing Stand; False: the
            simulator's hold (DRCSim 2.5.2's stand-in).
        hold_at_start: with balance_stand, a (re)start in Stand holds the robot with the
            parameter gains (the tutorial's start, reported as User) until Stand is asked
            for; False: the balancing Stand acts from the start.
        user_behaviour: a behaviour of the user's own for the AtlasSimInterface (with
            balance_stand), registered over the library's; None: the library's own.
        score_dir: score the VRC course (DRCSim's VRCScoringPlugin) into score.log there,
            and /vrc_score; None: not scored.
    """

    rates_hz: Mapping[str, float] = field(default_factory=dict)
    real_time_factor: float = 0.0
    paused: bool = False
    links: LinkTransforms | None = None
    balance_stand: bool = False
    hold_at_start: bool = False
    user_behaviour: LibraryBehaviour | None = None
    score_dir: Path | None = None


class SteppingLoop:
    """Owns the simulator's lock and the stepping loop; its collaborators own the rest.

    Args:
        pacer: the wall-time decisions (default: a Pacer at the settings' real_time_factor;
            tests give one with a fake clock).
        synchronization: DRCSim 2.6's synchronization window (default: DRCSim's budgets);
            its statistics go to the topics.SYNCHRONIZATION_STATISTICS outlet, if any.
        controller: makes, from the loop's command inbox, what gives the simulator each
            step's command (default: the inbox itself, which applies what users sent).
    """

    def __init__(self, sim: AtlasSimulator, outputs: LoopOutputs, settings: LoopSettings,
                 statistics: CommandAgeStatistics, pacer: Pacer | None = None,
                 synchronization: SynchronizationWindow | None = None,
                 controller: Callable[[CommandInbox], StepController] | None = None
                 ) -> None:
        self.sim = sim
        self.lock = threading.Lock()
        self.outbox = outputs.outbox
        self.statistics = statistics
        self.pacer = pacer if pacer is not None else Pacer(settings.real_time_factor)
        self.step_count = 0
        self.exit_status = 0
        window = (synchronization if synchronization is not None
                  else SynchronizationWindow(DelayBudgets()))
        self.watch = RunWatch(sim, outputs.log)
        #: The AtlasSimInterface: its commands come through the inbox, its state is published.
        self.asi = AtlasSimInterface(sim, settings.balance_stand, settings.hold_at_start,
                                     settings.user_behaviour)
        self.inbox = CommandInbox(sim, outputs.log, statistics, self.watch, window.budgets,
                                  self.asi)
        self.controller: StepController = (controller(self.inbox) if controller is not None
                                           else self.inbox)
        self.publisher = StepPublisher(sim, outputs, settings.rates_hz, statistics,
                                       settings.links, self.asi)
        self.gate = SyncGate(sim, self.lock, self.inbox, outputs, self.pacer, window)
        self.controls = SimControls(sim, self.lock, self.inbox, self.watch, outputs,
                                    settings.paused)
        self.divergence = DivergenceRecovery(sim, outputs.log,
                                             self.controls.reset_after_divergence)
        #: The VRC course's scoring, in lockstep with the physics (None: not scored).
        self.scoring = (CourseScoring(sim, settings.score_dir, outputs.publish_score)
                        if settings.score_dir is not None else None)
        #: One step with its inputs before and its state and the interface's handover after.
        self.tick = Tick(sim, self.controller, self._publish_step, self.asi.end_step,
                         self.divergence.recover, self.scoring)
        # The node's and tests' entry points, the collaborators' own methods.
        self.receive_command = self.inbox.receive
        self.apply_pending_commands = self.inbox.apply_pending
        self.wake, self.stop_waiting = self.gate.wake, self.gate.stop_waiting
        controls = self.controls
        self.reset_controls, self.set_mode = controls.reset_controls, controls.set_mode
        self.apply_input, self.publish_config = controls.apply_input, controls.publish_config
        self.reset_world, self.reset_simulation = controls.reset_world, controls.reset_simulation
        self.pause, self.unpause = controls.pause, controls.unpause

    def set_spindle_speed(self, speed: float) -> None:
        """The laser spindle's speed from the next step on (rad/s, within its limits)."""
        with self.lock:
            self.publisher.head.spindle.command(speed)

    @property
    def real_time_factor(self) -> float:
        """Sim time per wall time (the pacer's); 0 = as fast as possible."""
        return self.pacer.real_time_factor

    @property
    def paused(self) -> bool:
        return self.controls.paused

    def _publish_step(self) -> None:
        """After a step (or a recovered divergence): count it, watch for a fall, publish."""
        self.step_count += 1
        watch = self.watch
        if watch.fall_armed:
            watch.watch_fall()
        self.publisher.publish_step(self.step_count)

    def run(self, is_shutdown: Callable[[], bool]) -> int:
        """Step, publish and pace against wall time until `is_shutdown()`; the exit status
        (1: stopped because the physics kept diverging)."""
        sim, lock, outbox, pacer, controls = (self.sim, self.lock, self.outbox, self.pacer,
                                              self.controls)
        pacer.restart(sim.sim_time_ns)
        with lock:
            self.publisher.publish(self.step_count)  # /clock and the state before the first step
        outbox.flush()
        pacer.flushed()
        controls.loop_running = True
        try:
            self._step_until(is_shutdown)
        finally:
            controls.loop_running = False
            controls.stopped_for_pause()  # nobody waits for a loop that has ended
        return self.exit_status

    def _step_until(self, is_shutdown: Callable[[], bool]) -> None:
        """run()'s loop: a tick at a time, or, paused, the commands and a poll."""
        sim, lock, outbox, pacer = self.sim, self.lock, self.outbox, self.pacer
        controls, inbox, gate, tick = self.controls, self.inbox, self.gate, self.tick
        paced = pacer.real_time_factor > 0.0  # else there is nothing to wait for
        while not is_shutdown():
            if controls.paused:
                with lock:
                    inbox.apply_pending()
                outbox.flush()
                controls.stopped_for_pause()
                pacer.sleep(PAUSED_POLL_S)
                pacer.restart(sim.sim_time_ns)
                continue
            if inbox.period_ms:
                gate.before_step()
            with lock:
                if controls.paused:  # pause() came after the check above: no more steps
                    continue
                if not tick():  # the physics kept diverging
                    self.exit_status = 1
                    break
                sim_ns = sim.sim_time_ns
            # Send outside the lock, in batches when allowed (pacing.py): TCPROS is a byte
            # stream, one sendall carries many messages.
            if pacer.flush_due(sim_ns):
                outbox.flush()
            if paced:
                pacer.wait(sim_ns)
