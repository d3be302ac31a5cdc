"""The commands waiting for the next step, and their merge into the simulator.

Commands arrive on rospy's threads as undecoded bytes (receive); before each step the
loop decodes, checks and merges them, newest first (apply_pending). The inbox also keeps
what the commands say about the synchronization window: the latest AtlasCommand's
desired_controller_period_ms and the stamp of the newest applied command.
"""

from __future__ import annotations

import collections
import threading

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import AtlasSimInterface
from tutorial_atlas_control.command import (
    FIELD_NAMES,
    LAW_FIELDS,
    CommandError,
    CommandUpdate,
)
from tutorial_atlas_control.joints import NUM_JOINTS
from tutorial_atlas_control.msgs import (
    AsiCommand,
    AtlasCommandDecoder,
    AtlasUpdate,
    CommandDecoder,
    FieldCursor,
    decode_asi_command,
    decode_test,
)
from tutorial_atlas_control.sim import AtlasSimulator, CommandAgeStatistics, ControlMode
from tutorial_atlas_control.stepping.outputs import LoopLog
from tutorial_atlas_control.stepping.synchronization import DelayBudgets
from tutorial_atlas_control.stepping.watch import RunWatch

__all__ = ['CAN_SET', 'MAX_PENDING_COMMANDS', 'CommandInbox']

#: Commands waiting for the next step, at most (a second of 10 kHz of them).
MAX_PENDING_COMMANDS = 10_000
#: Rows (arrays.LAW_FIELDS indices) each command topic can set; DAMPING_ROW stands for
#: /atlas/debug/test's damping. An older message whose rows a newer one set for every
#: joint is dropped undecoded (apply_pending).
DAMPING_ROW = len(LAW_FIELDS)
CAN_SET: dict[str, frozenset[int]] = {
    topics.JOINT_COMMANDS: frozenset(range(len(FIELD_NAMES))),
    topics.ATLAS_COMMAND: frozenset(range(len(LAW_FIELDS))),
    topics.ATLAS_TEST: frozenset({DAMPING_ROW, *(LAW_FIELDS.index(name) for name in (
        'kp_position', 'ki_position', 'kd_position', 'kp_velocity', 'i_effort_min',
        'i_effort_max', 'k_effort'))}),
}
#: The AtlasSimInterface's commands: only the newest of a step's is applied (DRCSim's queue
#: of 1); another topic's message never hides its behaviour request.
ASI_TOPIC = topics.ASI_COMMAND
#: Where DRCSim takes the command's header stamp for /atlas/controller_statistics.
STAMPED_COMMANDS = (topics.JOINT_COMMANDS, topics.ATLAS_COMMAND)


class CommandInbox:
    """The pending commands (bounded, emptied every step) and what the newest said.

    It is also the loop's default StepController (controller.py): before each step it
    hands the simulator what users sent, and the simulator's law does the rest.
    """

    def __init__(self, sim: AtlasSimulator, log: LoopLog, statistics: CommandAgeStatistics,
                 watch: RunWatch, budgets: DelayBudgets,
                 asi: AtlasSimInterface | None = None) -> None:
        self.sim = sim
        self.asi = asi
        self.log = log
        self.statistics = statistics
        self.watch = watch
        self.budgets = budgets
        self.decoder = CommandDecoder()
        self.atlas_decoder = AtlasCommandDecoder()
        # Bounded, so that a stalled loop cannot make it grow without limit.
        self.pending: collections.deque[tuple[str, bytes]] = collections.deque(
            maxlen=MAX_PENDING_COMMANDS)
        # DRCSim 2.6's synchronization window (synchronization.py): on while the latest
        # AtlasCommand's desired_controller_period_ms is non-zero. A command wakes its wait.
        self.period_ms = 0
        self.command_stamp_ns = 0  # header.stamp of the newest applied command, as sent
        self.arrived = threading.Event()

    def receive(self, raw: bytes, topic: str = topics.JOINT_COMMANDS) -> None:
        """Queue a serialized osrf_msgs/JointCommands (or, by `topic`, an
        atlas_msgs/AtlasCommand or Test) for the next step, undecoded.

        Nothing else happens in the receiving thread: decoding there would make several
        fast publishers' threads and the loop fight over the GIL. One queue keeps the
        topics' messages in the order they came: the newest sets the fields it carries.
        """
        self.pending.append((topic, raw))
        if self.period_ms:
            self.arrived.set()  # the window may be waiting for it

    def _decode(self, topic: str, raw: bytes) -> CommandUpdate | AtlasUpdate | AsiCommand:
        if topic == topics.JOINT_COMMANDS:
            return self.decoder.decode(raw)
        if topic == topics.ATLAS_COMMAND:
            return self.atlas_decoder.decode(raw)
        if topic == ASI_TOPIC:
            return decode_asi_command(raw)
        return decode_test(raw)

    def apply_pending(self) -> None:
        """Decode, check and merge the commands received since the last step, in order.

        Newest first: a message that sets some fields for every joint hides those fields
        of all that came before it, so an older message with nothing else to set is
        dropped undecoded (DRCSim, too, applied only the latest command at each step).
        Controllers send such complete commands, so a flood costs one decode per step,
        not one per message.
        """
        pending = self.pending
        if not pending:
            return
        received = [pending.popleft()]
        if not pending and received[0][0] == topics.ATLAS_COMMAND:
            self._apply_atlas_command(received[0][1])  # a 1 kHz controller's every step
            return
        while pending:
            received.append(pending.popleft())
        self._apply_received(received)

    def _apply_received(self, received: list[tuple[str, bytes]]) -> None:
        """apply_pending's general path: `received` oldest first, the newest decoded first."""
        hidden: set[int] = set()
        decoded: list[tuple[str, CommandUpdate | AtlasUpdate | AsiCommand]] = []
        stamped = asi_seen = False
        for topic, raw in reversed(received):
            if topic == ASI_TOPIC:
                if asi_seen or self.asi is None:
                    continue
                asi_seen = True
            elif CAN_SET[topic] <= hidden:
                continue
            try:
                result = self._decode(topic, raw)
            except CommandError as err:
                self.log.refused_command(f'refused {topic}: {err}; previous command kept', topic)
                continue
            if not stamped and topic in STAMPED_COMMANDS:  # the newest applied command
                self._note_command_stamp(result.stamp_ns if isinstance(result, AtlasUpdate)
                                         else FieldCursor(raw).header_stamp_ns())
                stamped = True
            decoded.append((topic, result))
            if isinstance(result, AsiCommand):
                continue  # its k_effort may not apply (length); it hides nothing
            update = result if isinstance(result, CommandUpdate) else result.update
            if update.all_joints:
                hidden.update(update.rows)
            if isinstance(result, AtlasUpdate) and result.damping is not None:
                hidden.add(DAMPING_ROW)
        if decoded:
            self._apply(decoded[::-1])

    #: The default StepController: what users sent, for the simulator's law.
    before_step = apply_pending

    def _apply_atlas_command(self, raw: bytes) -> None:
        """apply_pending of one AtlasCommand alone (what a controller sends before each
        step): the same decode, refusal, stamp and merge, without the general path's
        bookkeeping of what hides what."""
        topic = topics.ATLAS_COMMAND
        try:
            result = self.atlas_decoder.decode(raw)
        except CommandError as err:
            self.log.refused_command(f'refused {topic}: {err}; previous command kept', topic)
            return
        self._note_command_stamp(result.stamp_ns)
        first = self.watch.first_command_ns is None  # since the start or last reset
        if result.ignored:
            self.log.kept_fields(f'{topic}: {result.ignored_text()}', topic)
        if result.desired_controller_period_ms is not None:
            self.store_period(result.desired_controller_period_ms)
        self.sim.receive_updates((result.update,))
        if first:
            self.watch.first_command(topic)

    def _apply(self, decoded: list[tuple[str, CommandUpdate | AtlasUpdate | AsiCommand]]
               ) -> None:
        """Apply decoded messages, oldest first."""
        first = self.watch.first_command_ns is None  # since the start or last reset
        updates: list[CommandUpdate] = []
        for topic, result in decoded:
            if isinstance(result, CommandUpdate):
                updates.append(result)
                continue
            if isinstance(result, AsiCommand):
                self._apply_asi(result, updates)
                updates = []
                continue
            if result.ignored:
                self.log.kept_fields(f'{topic}: {result.ignored_text()}', topic)
            if result.damping is not None:
                self.sim.set_joint_damping(result.damping)
            if result.desired_controller_period_ms is not None:
                self.store_period(result.desired_controller_period_ms)
            updates.append(result.update)
        self.sim.receive_updates(updates)
        if (self.sim.mode is not ControlMode.USER
                and any(topic == topics.JOINT_COMMANDS for topic, _ in decoded)):
            self.watch.warn_not_user()  # AtlasCommands with k_effort act in any mode
        if first:
            self.watch.first_command(decoded[0][0])

    def _apply_asi(self, command: AsiCommand, before: list[CommandUpdate]) -> None:
        """The commands before it, then the AtlasSimInterfaceCommand (in that order: its
        k_effort overrides theirs)."""
        assert self.asi is not None  # not decoded without one
        if before:
            self.sim.receive_updates(before)
        if command.ignored_text():
            self.log.kept_fields(f'{ASI_TOPIC}: {command.ignored_text()}', ASI_TOPIC)
        self.asi.apply(command)
        refusal = self.asi.take_refusal()
        if refusal is not None:
            self.log.refused_command(refusal, ASI_TOPIC)

    def _note_command_stamp(self, stamp_ns: int) -> None:
        """The command stamped `stamp_ns` is applied from the coming step on: remember it."""
        self.command_stamp_ns = stamp_ns
        self.statistics.command_applied(stamp_ns, self.sim.sim_time_ns + self.sim.step_ns)

    def forget_stamp(self) -> None:
        """After reset_simulation: the newest command's stamp lies in the rewound future."""
        self.statistics.forget_command()
        self.command_stamp_ns = 0

    def load_atlas_command(self, atlas: AtlasUpdate) -> list[str]:
        """ResetControls' atlas_command applied as an AtlasCommand; what was done."""
        done = []
        if atlas.update.rows:
            self.sim.receive_updates([atlas.update])
            done.append('atlas_command loaded: ' + ', '.join(atlas.fields_set()))
        else:
            done.append(f'atlas_command has no array of {NUM_JOINTS}: no field loaded')
        if atlas.ignored:
            done.append(atlas.ignored_text())
        assert atlas.desired_controller_period_ms is not None
        self.store_period(atlas.desired_controller_period_ms)
        return done

    def store_period(self, period_ms: int) -> None:
        """An AtlasCommand's desired_controller_period_ms; a line when the window turns
        on or off."""
        previous = self.period_ms
        self.period_ms = period_ms
        if bool(previous) == bool(period_ms):
            return
        if period_ms:
            budgets = self.budgets
            self.log.info(f'synchronization window on ({topics.ATLAS_COMMAND} '
                          f'desired_controller_period_ms = {period_ms}): each step waits for '
                          f'a command stamped no more than {period_ms} ms before its end, at '
                          f'most {budgets.max_per_step_s:g} s per step and '
                          f'{budgets.max_per_window_s:g} s per {budgets.window_size_s:g} s')
        else:
            self.log.info('synchronization window off (desired_controller_period_ms = 0)')
