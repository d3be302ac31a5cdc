"""Offline runs of a recorded AtlasSimInterface session: a walking client's commands, played
again into the simulator without ROS.

`run_offline.py --asi-from IN.bag` takes the /atlas/atlas_sim_interface_command messages a
live run recorded (a streaming walk_client.py, the actionlib server, a user's rostopic pub)
and plays them into a fresh simulator started as that run's was (its /atlas/sim_config's
startup_mode; the AtlasSimInterface's balancing Stand installed, as atlas.launch does), each
before the first step at or after the sim time it was recorded at; of the commands due
before one step only the newest is applied, as the live loop does (DRCSim's queue of 1).
The controller runs in lockstep with the physics, so the run is deterministic: try a change
of the walking controller against a session recorded once. It is not the recorded run: a
live command arrives a step or two before the recorder writes it down, and the client
answered the live states, not these (replay_bag.py re-creates a recorded run exactly, from
its torques).
"""

from __future__ import annotations

import dataclasses
import time
from dataclasses import dataclass
from pathlib import Path

from tutorial_atlas_control import topics
from tutorial_atlas_control.asi import AtlasSimInterface, load_user_behaviour
from tutorial_atlas_control.bags import BlockBagWriter, open_bag, read_bag
from tutorial_atlas_control.command import CommandError
from tutorial_atlas_control.msgs import decode_asi_command
from tutorial_atlas_control.offline.player import (
    DEFAULT_SETTLE_S,
    OfflinePlayer,
    OfflineRun,
    OfflineRunError,
    open_offline_bag,
    write_whole,
)
from tutorial_atlas_control.offline.world import OfflineWorld, recorded_world
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    AtlasSimulator,
    SimConfig,
    SimConfigError,
    VrcMode,
    load_gains_yaml,
    load_model,
    parse_sim_config,
)
from tutorial_atlas_control.units import NS_PER_S

__all__ = ['AsiStream', 'read_asi_stream', 'run_asi_offline', 'write_asi_bag']


@dataclass(frozen=True)
class AsiStream:
    """What a recorded session gives an offline run: the start the simulator made, and each
    AtlasSimInterfaceCommand (sim time it was recorded at, ns; its serialization)."""

    source: Path
    startup_mode: VrcMode
    commands: list[tuple[int, bytes]]
    #: The sim time (ns) of the bag's last record: the offline run goes on that long.
    end_ns: int
    #: The recorded run's model and start (its /atlas/sim_config's).
    world: OfflineWorld = OfflineWorld()


def read_asi_stream(path: Path | str) -> AsiStream:
    """The AtlasSimInterface session recorded in the bag at `path`.

    Raises:
        BagAnalysisError: not a readable bag.
        OfflineRunError: the bag holds no AtlasSimInterfaceCommand, several tries (resets),
            or no /atlas/sim_config.
    """
    source = Path(path)
    data = read_bag(source)
    if data.epoch_starts_s:
        raise OfflineRunError(f'{source}: holds {len(data.epoch_starts_s) + 1} tries (it was '
                              'reset); an AtlasSimInterface session is played from one start')
    if not data.sim_configs:
        raise OfflineRunError(f'{source}: has no {topics.SIM_CONFIG}: it does not say how the '
                              'simulator started')
    try:
        config = SimConfig.from_dict(parse_sim_config(data.sim_configs[0][1]))
        startup_mode = VrcMode(config.startup_mode)
        world = recorded_world(config)
    except (SimConfigError, ValueError) as err:
        raise OfflineRunError(f'{source}: {topics.SIM_CONFIG}: {err}') from None
    records = open_bag(source)
    try:
        connections = [c for c in records.connections if c.topic == topics.ASI_COMMAND]
        bag_ns, raws = records.raw_messages(connections) if connections else ([], [])
    finally:
        records.close()
    if not len(raws):
        raise OfflineRunError(f'{source}: holds no {topics.ASI_COMMAND} message to play')
    end_ns = int(round((data.start_time_s + data.duration_s) * NS_PER_S))
    return AsiStream(source, startup_mode, [(int(t), bytes(raw)) for t, raw in
                                            zip(list(bag_ns), raws)], end_ns, world)


class _AsiFeed:
    """The tick's inputs (a StepController): before each step, the newest recorded command
    due, decoded and applied (and written to the offline bag at its recorded time)."""

    def __init__(self, stream: AsiStream, interface: AtlasSimInterface, sim: AtlasSimulator,
                 sink: BlockBagWriter) -> None:
        self.commands = stream.commands
        self.next = 0
        self.interface = interface
        self.sim = sim
        self.sink = sink
        self.applied = 0

    def before_step(self) -> None:
        commands, due, now_ns = self.commands, self.next, self.sim.sim_time_ns
        while due < len(commands) and commands[due][0] <= now_ns:
            self.sink.write(topics.ASI_COMMAND, commands[due][0], commands[due][1])
            due += 1
        if due == self.next:
            return
        newest = commands[due - 1][1]
        self.next = due
        try:
            command = decode_asi_command(newest)
        except CommandError:  # the live simulator refused it too (and said so then)
            return
        self.interface.apply(command)
        self.applied += 1


def write_asi_bag(stream: AsiStream, bag: Path, settle_s: float,
                  gains_file: Path = DEFAULT_GAINS_FILE, behaviour: str = '') -> OfflineRun:
    """Play `stream` offline and write the run to `bag` (a new file); `behaviour`: a user's
    own (`module:Class` or `file.py:Class`), as atlas.launch's argument."""
    sim = AtlasSimulator(load_model(stream.world.model_path), load_gains_yaml(gains_file),
                         startup_mode=stream.startup_mode, start=stream.world.start,
                         mud_damping=stream.world.mud_damping)
    user = load_user_behaviour(behaviour, sim.atlas) if behaviour else None
    # atlas.launch's default start
    interface = AtlasSimInterface(sim, hold_at_start=True, user_behaviour=user)
    sink = open_offline_bag(bag)
    started_s = time.perf_counter()
    try:
        feed = _AsiFeed(stream, interface, sim, sink)
        player = OfflinePlayer(sim, sink, controller=feed, interface=interface)
        player.write_config()
        player.publish()
        player.advance(stream.end_ns / NS_PER_S + settle_s)
        # The commands recorded up to the last step's end are in the bag too, as in the
        # recording (applied to no step).
        feed.before_step()
        player.write_steps()
    finally:
        sink.close()
    return OfflineRun(bag, feed.applied, sim.sim_time_ns / NS_PER_S, player.steps,
                      time.perf_counter() - started_s)


def run_asi_offline(source: Path | str, bag: Path | str, settle_s: float = DEFAULT_SETTLE_S,
                    gains_file: Path = DEFAULT_GAINS_FILE, behaviour: str = '',
                    world: OfflineWorld | None = None) -> OfflineRun:
    """Play the AtlasSimInterface session recorded in `source` offline into the bag `bag`
    (written under a temporary name beside it and renamed when complete: a failed run
    leaves nothing); `settle_s` of sim time after the recording's end; `behaviour`: a
    user's own, as the live run had it (atlas.launch's `behaviour`); `world`: another model
    and start than the recorded run's.

    Raises:
        BagAnalysisError, OfflineRunError, GainsError, UserBehaviourError: bad inputs
            (checked before simulating), a bag that cannot be written, or physics that
            diverged.
    """
    stream = read_asi_stream(source)
    if world is not None:
        stream = dataclasses.replace(stream, world=world)
    load_gains_yaml(gains_file)
    if behaviour:
        load_user_behaviour(behaviour, load_model())
    target = Path(bag)
    if target.exists() and target.resolve() == stream.source.resolve():
        raise OfflineRunError(f'{target} is the bag played: give another file name')
    return write_whole(target, lambda partial: write_asi_bag(stream, partial, settle_s,
                                                             gains_file, behaviour))
