"""The node's per-step work without a ROS graph: bare mj_step, law + mj_step, and SimNode.spin.

On a shared 2-core machine a node-level figure moves with everyone else's load; these
loops run in one process, so an A/B of two variants (compiled vs numpy law, one node
loop vs another) compares like with like. `python3 bench/node_loop.py` prints µs per
step of each (interleaved rounds, best of them).
"""

from __future__ import annotations

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
            for _ in range(calls):
                publish(0)
                pending.clear()
            return time.perf_counter() - start

        repeated = unheard * UNHEARD_REPEAT
        with_s, without_s = [], []
        for _ in range(rounds):
            with_s.append(timed(repeated))
            without_s.append(timed(()))
        publisher.demand_wires = unheard
        return (min(with_s) - min(without_s)) / calls / len(repeated) * 1e6


def main() -> int:
    rounds = int(sys.argv[1]) if len(sys.argv) > 1 else 3
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
