"""The node's per-step work without a ROS graph: bare mj_step, law + mj_step, and SimNode.spin.

On a shared 2-core machine a node-level figure moves with everyone else's load; these
loops run in one process, so an A/B of two variants (compiled vs numpy law, one node
loop vs another) compares like with like. `python3 bench/node_loop.py` prints µs per
step of each (interleaved rounds, best of them); `--phases` splits the tick of a node
serving a 1 kHz controller into its phases (controller_phases_run).
"""

from __future__ import annotations

import argparse
import contextlib
import os
import sys
import time
from collections.abc import Iterator
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
# The fake rospy the unit tests use too: test/support, imported as `support`.
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))

import offline
from offline import make_simulator

from support import fake_rospy

#: The node's law runs this long (s of sim time) before the bare physics is timed: past
#: the 1 s torso pin, feet in contact, the robot standing.
STANDING_AFTER_S = 1.5
#: The bare loop restores the standing snapshot this often, so the held torques never let
#: the robot drift far from standing (a falling robot has other contacts, another cost):
#: with the torques held, the pelvis sinks 2 mm in 200 steps, 14 mm in 500 (by then on one
#: contact instead of 8) and 20 cm in 1000.
RESTORE_EVERY_STEPS = 200
#: unheard_topic_run times the unheard outlets this many times over.
UNHEARD_REPEAT = 25


def bare_physics_run(steps: int = 5000) -> float:
    """Steps per wall second of mujoco.mj_step alone, from the standing state.

    The node's law runs until STANDING_AFTER_S; the state is snapshot (mj_getState,
    mjSTATE_INTEGRATION) and mj_step timed with the last torques held in ctrl, the
    snapshot restored every RESTORE_EVERY_STEPS steps (outside the timed blocks).
    """
    import mujoco
    import numpy as np

    sim = make_simulator()
    while sim.sim_time_ns < STANDING_AFTER_S * 1e9:
        sim.step()
    model, data = sim.model, sim.data
    spec = mujoco.mjtState.mjSTATE_INTEGRATION
    snapshot = np.empty(mujoco.mj_stateSize(model, spec))
    mujoco.mj_getState(model, data, snapshot, spec)
    step = mujoco.mj_step
    elapsed_s = 0.0
    done = 0
    while done < steps:
        mujoco.mj_setState(model, data, snapshot, spec)
        block = min(RESTORE_EVERY_STEPS, steps - done)
        start = time.perf_counter()
        for _ in range(block):
            step(model, data)
        elapsed_s += time.perf_counter() - start
        done += block
    return steps / elapsed_s


@contextlib.contextmanager
def fake_ros_node(steps: int, warmup_steps: int = 1500, compiled_law: bool = True,
                  tcp: bool = False) -> Iterator[Any]:
    """A real SimNode (real_time_factor 0, the launch's rates) on fake rospy, standing
    (support.fake_rospy); rospy.is_shutdown() ends spin() after `steps` steps."""
    sim = make_simulator(compiled_law)
    for _ in range(warmup_steps):
        sim.step()
    with fake_rospy.fake_ros_node(sim, steps, tcp=tcp) as node:
        yield node


def node_spin_run(steps: int = 5000, warmup_steps: int = 1500, compiled_law: bool = True,
                  tcp: bool = False) -> float:
    """CPU µs (this process, user + system) per step of the real SimNode.spin at rtf 0.

    What is left without ROS is the node's own per-step work: commands, law, mj_step,
    serializing, batching and the writes.
    """
    with fake_ros_node(steps, warmup_steps, compiled_law, tcp) as node:
        start = time.process_time()
        node.spin()
        return (time.process_time() - start) / steps * 1e6


#: Where the tick of a node serving a 1 kHz controller goes (controller_phases_run).
PHASES = ('command in', 'inbox', 'sim.step', 'publish', 'end_step', 'flush')
#: The topics heard in the controller section's runs (bench/controller.py): the bench's
#: /clock and statistics probes, and the controller's /atlas/atlas_state.
CONTROLLER_RUN_TOPICS = ('/clock', '/atlas/controller_statistics', '/atlas/atlas_state')


def controller_command(sim: Any) -> bytes:
    """An AtlasCommand as echo_controller sends it: every array of 28, the target the
    joints' positions now, the same gains in every message."""
    from tutorial_atlas_control.joints import NUM_JOINTS
    from tutorial_atlas_control.msgs import encode_atlas_command

    def full(value: float) -> list[float]:
        return [value] * NUM_JOINTS

    return encode_atlas_command(sim.sim_time_ns, {
        'position': sim.joint_positions().tolist(), 'velocity': full(0.0), 'effort': full(0.0),
        'kp_position': full(100.0), 'ki_position': full(0.0), 'kd_position': full(1.0),
        'kp_velocity': full(0.0), 'k_effort': [255] * NUM_JOINTS, 'i_effort_min': full(-1.0),
        'i_effort_max': full(1.0)})


def controller_phases_run(steps: int = 3000, answered: bool = True) -> dict[str, float]:
    """CPU µs per step of each of PHASES (this thread's: a loaded host's waits are not
    counted; six clock reads of about 1 µs each are), and 'cpu' (this process), of the
    loop's turn (loop.py, tick.py) on fake rospy serving a 1 kHz controller: an AtlasCommand
    received before every step (`answered` False: none), the CONTROLLER_RUN_TOPICS heard
    over loopback TCP, sent after every step as at real time, no pacing, no rospy threads.
    """
    sim = make_simulator()
    for _ in range(1500):
        sim.step()
    raw = controller_command(sim)
    with fake_rospy.fake_ros_node(sim, 0, tcp=True, heard=CONTROLLER_RUN_TOPICS) as node:
        cpu_start = time.process_time()
        spent = _timed_steps(node.loop, raw if answered else None, steps)
        figures = {'cpu': (time.process_time() - cpu_start) / steps * 1e6}
    figures.update({name: value / steps * 1e6 for name, value in zip(PHASES, spent)})
    return figures


def _timed_steps(loop: Any, raw: bytes | None, steps: int) -> list[float]:
    """The thread CPU (s) of each of PHASES over `steps` turns of `loop`; `raw` (an
    AtlasCommand) received before each step, or None: no command."""
    tick, outbox, lock, clock = loop.tick, loop.outbox, loop.lock, time.thread_time
    sim = loop.sim
    receive = loop.receive_command if raw is not None else (lambda *_args: None)
    before, step, publish, end = (tick.controller.before_step, sim.step,
                                  loop._publish_step, tick.end_step)
    spent = [0.0] * len(PHASES)
    for _ in range(steps):
        t0 = clock()
        receive(raw, '/atlas/atlas_command')
        with lock:
            t1 = clock()
            before()
            t2 = clock()
            step()
            t3 = clock()
            publish()
            t4 = clock()
            end()
            t5 = clock()
        outbox.flush()
        for index, elapsed in enumerate((t1 - t0, t2 - t1, t3 - t2, t4 - t3, t5 - t4,
                                         clock() - t5)):
            spent[index] += elapsed
    return spent


def unheard_topic_run(calls: int = 20000, rounds: int = 5) -> float:
    """µs per step that one published topic nobody subscribes to costs the node's loop.

    The node on fake rospy as launched (DRCSim's on-demand topics advertised, unheard:
    support.fake_rospy.UNHEARD_TOPICS); its StepPublisher.publish() is timed with those
    topics' outlets and without them (interleaved rounds, best of each, the queued bytes
    dropped after each call), and the difference divided by their number. Those outlets
    are repeated UNHEARD_REPEAT times so that their cost stands out of publish()'s own
    (several µs, and its noise on a shared machine).
    """
    with fake_ros_node(0, warmup_steps=0) as node:
        loop = node.loop
        pending = loop.outbox.pending
        publisher = loop.publisher
        publish = publisher.publish
        unheard = publisher.demand_wires
        if not unheard or any(loop.outbox.wanted(wire[3]) for wire in unheard):
            raise RuntimeError('expected the on-demand topics advertised and unheard')

        def timed(demand_wires: tuple[Any, ...]) -> float:
            publisher.demand_wires = demand_wires
            start = time.perf_counter()
            for count in range(1, calls + 1):  # what is due at each step, as in the node
                publish(count)
                pending.clear()
            return time.perf_counter() - start

        repeated = unheard * UNHEARD_REPEAT
        with_s, without_s = [], []
        for _ in range(rounds):
            with_s.append(timed(repeated))
            without_s.append(timed(()))
        publisher.demand_wires = unheard
        return (min(with_s) - min(without_s)) / calls / len(repeated) * 1e6


def phases_main(rounds: int) -> int:
    """`node_loop.py --phases [ROUNDS]`: controller_phases_run with and without the
    controller's commands, and bare mj_step, interleaved; each figure's best round."""
    best: dict[str, dict[str, float]] = {}
    for _ in range(rounds):
        runs = {'bare mj_step': {'cpu': 1e6 / bare_physics_run(3000)},
                'with a controller': controller_phases_run(),
                'no controller': controller_phases_run(answered=False)}
        for name, figures in runs.items():
            kept = best.setdefault(name, figures)
            for key, value in figures.items():
                kept[key] = min(kept[key], value)
    bare_us = best['bare mj_step']['cpu']
    print(f'best of {rounds} (µs per step, x bare mj_step {bare_us:.1f} µs; '
          f'load {os.getloadavg()[0]:.1f}):')
    for name in ('with a controller', 'no controller'):
        figures = best[name]
        print(f'  {name}: cpu {figures["cpu"]:.1f} ({figures["cpu"] / bare_us:.2f}x); '
              + ', '.join(f'{phase} {figures[phase]:.1f} ({figures[phase] / bare_us:.2f}x)'
                          for phase in PHASES))
    return 0


def parse_args(argv: list[str]) -> argparse.Namespace:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('rounds', nargs='?', type=int, default=3,
                        help='interleaved rounds; each figure is its best round (default 3)')
    parser.add_argument('--phases', action='store_true',
                        help="split the tick of a node serving a 1 kHz controller into phases")
    args = parser.parse_args(argv)
    if args.rounds < 1:
        parser.error('rounds must be >= 1')
    return args


def main(argv: list[str] | None = None) -> int:
    args = parse_args(sys.argv[1:] if argv is None else argv)
    if args.phases:
        return phases_main(args.rounds)
    rounds = args.rounds
    best: dict[str, float] = {}
    for _ in range(rounds):
        figures = {
            'bare mj_step': 1e6 / bare_physics_run(),
            'law (C) + mj_step': 1e6 / offline.physics_run(compiled_law=True),
            'law (numpy) + mj_step': 1e6 / offline.physics_run(compiled_law=False),
            'node spin, C law': node_spin_run(),
            'node spin, numpy law': node_spin_run(compiled_law=False),
            'node spin, C law, TCP': node_spin_run(tcp=True),
            'one unheard topic': unheard_topic_run(),
        }
        for name, value in figures.items():
            best[name] = min(best.get(name, value), value)
        print('  '.join(f'{name}: {value:.1f}' for name, value in figures.items()), flush=True)
    print(f'best of {rounds} (µs per step, load {os.getloadavg()[0]:.1f}):')
    for name, value in best.items():
        print(f'  {name:<24} {value:8.1f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())


def head_sensors_run(scans: int = 200, steps: int = 5000) -> dict[str, float]:
    """The MultiSense SL head's cost on the standing robot (sensors/head.py, as the node's
    loop calls it), each subscribed topic in wall ms per second of sim time at its default
    rate: `laser_ms_per_sim_s` (40 scans: 720 rays cast, noised, serialized),
    `head_imu_ms_per_sim_s` and `head_joint_states_ms_per_sim_s` (1000 messages each);
    `spindle_step_us`, the spinning spindle's step (µs; at rest and asked for 0, a test)."""
    with fake_ros_node(0) as node:
        head = node.loop.publisher.head
        sim = node.loop.sim
        rate_hz = head.laser.spec.rate_hz
        start = time.perf_counter()
        for k in range(scans):
            head.scan(sim.state_time_ns + k)
        scan_s = (time.perf_counter() - start) / scans
        head.spindle.command(5.0)
        start = time.perf_counter()
        for _ in range(steps):
            head.step()
        step_s = (time.perf_counter() - start) / steps
        start = time.perf_counter()
        for k in range(steps):
            head.imu(k)
        imu_s = (time.perf_counter() - start) / steps
        start = time.perf_counter()
        for k in range(steps):
            head.joint_state(k)
        joints_s = (time.perf_counter() - start) / steps
    return {'laser_ms_per_sim_s': scan_s * rate_hz * 1e3, 'spindle_step_us': step_s * 1e6,
            'head_imu_ms_per_sim_s': imu_s * 1e6, 'head_joint_states_ms_per_sim_s': joints_s * 1e6}
