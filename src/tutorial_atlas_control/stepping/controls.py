"""What the node's services and viewer do to the simulator between two steps: resets,
pause, control mode, ResetControls and VRCPlugin's inputs (cheats), each under the lock
that rospy's threads and the viewer share with the loop."""

from __future__ import annotations

import threading
from dataclasses import dataclass

from tutorial_atlas_control import topics
from tutorial_atlas_control.command import CommandError
from tutorial_atlas_control.msgs import AtlasUpdate, decode_atlas_command
from tutorial_atlas_control.sim import AtlasSimulator, ControlMode, Gains, SimInput
from tutorial_atlas_control.stepping.inbox import CommandInbox
from tutorial_atlas_control.stepping.outputs import LoopOutputs
from tutorial_atlas_control.stepping.watch import RunWatch
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['PAUSE_WAIT_S', 'ResetControlsRequest', 'SimControls']

#: Wall time (s) pause() waits for the loop to stop: a tick, a flush, a stalled host.
PAUSE_WAIT_S = 5.0


@dataclass(frozen=True)
class ResetControlsRequest:
    """atlas_msgs/ResetControls' request, with what the node read for it.

    Attributes:
        atlas_command: the request's AtlasCommand, serialized.
        gains: with reload_pid_from_ros, the gains on the parameter server, or the
            reason they could not be read (GainsError's text).
    """

    reset_bdi_controller: bool
    reset_pid_controller: bool
    reload_pid_from_ros: bool
    atlas_command: bytes
    gains: Gains | str | None = None


class SimControls:
    """Resets, pause, mode switches, ResetControls and cheats, from other threads."""

    def __init__(self, sim: AtlasSimulator, lock: threading.Lock, inbox: CommandInbox,
                 watch: RunWatch, outputs: LoopOutputs, paused: bool = False) -> None:
        self.sim = sim
        self.lock = lock
        self.inbox = inbox
        self.watch = watch
        self.log = outputs.log
        self._send_config = outputs.publish_config
        self._send_input = outputs.publish_input
        self.paused = paused
        #: Set by the loop while run() steps (pause() then waits for stopped_for_pause).
        self.loop_running = False
        self._stopped = threading.Event()

    def reset_controls(self, request: ResetControlsRequest) -> tuple[bool, str]:
        """atlas_msgs/ResetControls, as AtlasPlugin::ResetControls: (success, status).

        Commands received before the request are applied first. Everything is checked
        before anything is done: a refused request changes nothing.
        """
        with self.lock:
            self.inbox.apply_pending()
            atlas: AtlasUpdate | None = None
            if request.reload_pid_from_ros:
                if not isinstance(request.gains, Gains):
                    return False, (f'reload_pid_from_ros: {request.gains}; nothing was done')
            else:
                try:
                    atlas = decode_atlas_command(request.atlas_command)
                except CommandError as err:
                    return False, f'atlas_command refused: {err}; nothing was done'
            done = []
            if request.reset_bdi_controller:
                done.append('reset_bdi_controller: there is no BDI controller in this '
                            'simulator, nothing to reset')
            if request.reset_pid_controller:
                self.sim.law.reset()
                done.append('PID state reset (integral terms and previous errors)')
            if atlas is None:
                assert isinstance(request.gains, Gains)
                self.sim.commands.load_gains(request.gains)
                done.append(f'gains reloaded from {topics.GAINS_PARAM}, k_effort 255 on every '
                            'joint (atlas_command ignored)')
            else:
                done.extend(self.inbox.load_atlas_command(atlas))
        return True, '; '.join(done)

    def set_mode(self, mode: ControlMode) -> ControlMode:
        """Switch the control mode; returns the previous one.

        Commands received before the switch are applied first, as DRCSim's single callback
        queue did: the switch then sets their k_effort (AtlasPlugin::OnRobotMode).
        """
        with self.lock:
            self.inbox.apply_pending()
            previous = self.sim.mode
            self.sim.set_mode(mode)
            self.watch.new_mode()
        return previous

    def apply_input(self, item: SimInput) -> None:
        """Apply one checked VRCPlugin input between two steps, then log and publish it (the
        replay re-applies it before the same step)."""
        with self.lock:
            self.sim.apply_input(item)
            event = self.sim.last_input_event()
        if self._send_input is not None:
            self._send_input(event.to_json())
        self.watch.input_applied(item, event.time_ns)

    def publish_config(self) -> None:
        """(Re-)publish /atlas/sim_config: at start and after every reset."""
        self._send_config(self.sim.config().to_json())

    def reset_world(self, by: str = '') -> None:
        """/gazebo/reset_world, or the viewer's Reset (`by`: ' (viewer)', said in the line)."""
        with self.lock:
            self.sim.reset_world()
            self.watch.rearm()
        self.publish_config()
        self.log.info(f'reset_world{by}: robot back to its initial pose at '
                      f't={self.sim.sim_time_ns / NS_PER_S:.3f} s (torso pinned '
                      f'for {self.sim.time_to_unpin_s} s)')

    def reset_simulation(self) -> None:
        """/gazebo/reset_simulation. The commands received before it are applied first, as
        DRCSim applied each on arrival, so that their stamps (of the rewound timeline) are
        forgotten with the rest: a controller's answer to the state published before the
        first step (stamped 0, "now" by DRCSim's rule) that waited, paused, for the first
        step after a reset made that step's command age 0 instead of one step."""
        with self.lock:
            self.inbox.apply_pending()
            self.sim.reset_simulation()
            self.inbox.forget_stamp()
            self.watch.rearm()
        self.publish_config()
        self.log.info('reset_simulation: robot reset and sim time back to 0')

    def reset_after_divergence(self) -> None:
        """The robot back to its initial state after a divergence (under the loop's lock)."""
        self.sim.reset_world()
        self.watch.rearm()
        self.publish_config()

    def pause(self) -> None:
        """Stop stepping. With the loop running, returns once it has stopped and sent what
        it stepped before (/clock included): whoever paused sees no step after the reply
        (waits at most PAUSE_WAIT_S for a loop that does not answer)."""
        with self.lock:
            self.paused = True
            self._stopped.clear()
        if self.loop_running:
            self._stopped.wait(PAUSE_WAIT_S)
        self.log.info('physics paused')

    def stopped_for_pause(self) -> None:
        """The loop's word that, paused, it steps no more and has sent all it stepped."""
        self._stopped.set()

    def unpause(self) -> None:
        self.paused = False
        self.log.info('physics unpaused')
