"""The simulator node on the VRC course, standing, its CPU per step split by part (by hand).

`vrc_task_2.launch` as launched (the course's model from the pen, bdi_stand, the balancing
Stand, scored, the links' /tf from the simulator) on fake rospy: every recorded topic heard
over loopback TCP as by the recorder, the laser's scan included, no pacing. After 3 s (the
pin, the take-over to Stand) the node's own spin() runs `steps` steps with each part's
callable wrapped in a thread-time clock: the Stand's torque, the rest of `sim.step` (the law,
`mj_step`, the mud, the checks), the fall watch, the laser's scan, the rest of the
publication, the scoring, the interface's end_step, the sends. Not a `make bench` section:

    python3 bench/course_node.py [--steps N] [--rounds R] [--spindle RAD_S]

prints each round's process CPU per step (µs) and its parts, and the same as ms of CPU per
second of sim time, beside a bare `mj_step` of the Atlas world timed in the same round.
"""

from __future__ import annotations

import argparse
import contextlib
import functools
import os
import sys
import tempfile
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))

from node_loop import bare_physics_run
from offline import GAINS_YAML

from support import fake_rospy

#: Sim time (s) before the timed steps: the 1 s pin, the balancing Stand from 2 s.
SETTLE_S = 3.0
#: The parts, in the order printed; 'other' is the process's CPU the parts do not hold.
PARTS = ('stand', 'physics', 'fall watch', 'laser', 'publish', 'scoring', 'end_step', 'flush',
         'other')


def course_path() -> Path:
    from tutorial_atlas_control.course import WORLD_MODEL_FILE
    from tutorial_atlas_control.resources import package_path

    return package_path('sim', WORLD_MODEL_FILE)


def course_simulator() -> Any:
    """The simulator as vrc_task_2.launch builds it (node/sim_node.build_node)."""
    from tutorial_atlas_control.course import world_start
    from tutorial_atlas_control.sim import controller, model
    from tutorial_atlas_control.sim.simulator import AtlasSimulator
    from tutorial_atlas_control.sim.startup_pin import VrcMode

    path = course_path()
    return AtlasSimulator(model.load_model(path), controller.load_gains_yaml(GAINS_YAML), 1.0,
                          startup_mode=VrcMode('bdi_stand'), start=world_start('vrc_task_2'))


@contextlib.contextmanager
def course_node(spindle_rad_s: float = 0.0) -> Iterator[Any]:
    """The course's node on fake rospy, SETTLE_S into its run; `node.steps(n)` spins n more."""
    from tutorial_atlas_control.joints import JOINT_NAMES
    from tutorial_atlas_control.node import sim_node
    from tutorial_atlas_control.sim import LinkTransforms
    from tutorial_atlas_control.sim.urdf import matching_urdf, read_joints

    sim = course_simulator()
    _path, description = matching_urdf(course_path(), sim.model)
    links = LinkTransforms(read_joints(description)[1], JOINT_NAMES)
    settings = functools.partial(fake_rospy.LoopSettings, balance_stand=True,
                                 hold_at_start=True, links=links)
    left = {'steps': int(SETTLE_S / sim.dt_s)}

    def steps(count: int) -> None:
        left['steps'] = count
        node.spin()

    def is_shutdown() -> bool:
        left['steps'] -= 1
        return left['steps'] < 0

    with tempfile.TemporaryDirectory() as score_dir, \
            contextlib.ExitStack() as stack:
        stack.enter_context(_patched(fake_rospy, 'LoopSettings', settings))
        node = stack.enter_context(fake_rospy.fake_ros_node(sim, 0, tcp=True,
                                                            score_dir=Path(score_dir)))
        stack.enter_context(_patched(sim_node.rospy, 'is_shutdown', is_shutdown))
        node.spin()
        node.loop.set_spindle_speed(spindle_rad_s)
        node.steps = steps
        yield node


@contextlib.contextmanager
def _patched(owner: Any, name: str, value: Any) -> Iterator[None]:
    old = getattr(owner, name)
    setattr(owner, name, value)
    try:
        yield
    finally:
        setattr(owner, name, old)


def _timed(spent: dict[str, float], part: str, call: Callable[..., Any]) -> Callable[..., Any]:
    clock = time.thread_time

    def timed(*args: Any, **kwargs: Any) -> Any:
        start = clock()
        try:
            return call(*args, **kwargs)
        finally:
            spent[part] += clock() - start
    return timed


def parts_run(steps: int = 3000, spindle_rad_s: float = 0.0) -> dict[str, float]:
    """CPU µs per step of each of PARTS and 'cpu' (the process's), the node on the course
    standing (course_node) for `steps` steps."""
    spent = dict.fromkeys(PARTS, 0.0)
    with course_node(spindle_rad_s) as node:
        loop, sim = node.loop, node.loop.sim
        tick, publisher = loop.tick, loop.publisher
        stand = sim.behaviours.acting
        if stand is None:
            raise RuntimeError('no behaviour acting: the balancing Stand should by now')
        stand.torque = _timed(spent, 'stand', stand.torque)
        sim.step = _timed(spent, 'physics', sim.step)
        loop.watch.watch_fall = _timed(spent, 'fall watch', loop.watch.watch_fall)
        publisher.head.scan = _timed(spent, 'laser', publisher.head.scan)
        publisher.publish_step = _timed(spent, 'publish', publisher.publish_step)
        tick.score = _timed(spent, 'scoring', tick.score)
        tick.end_step = _timed(spent, 'end_step', tick.end_step)
        loop.outbox.flush = _timed(spent, 'flush', loop.outbox.flush)
        start = time.process_time()
        node.steps(steps)
        cpu_s = time.process_time() - start
    spent['physics'] -= spent['stand']  # inside sim.step
    spent['publish'] -= spent['laser']  # inside publish_step
    spent['other'] = cpu_s - sum(spent.values())
    figures = {part: value / steps * 1e6 for part, value in spent.items()}
    figures['cpu'] = cpu_s / steps * 1e6
    return figures


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument('--steps', type=int, default=3000)
    parser.add_argument('--rounds', type=int, default=3)
    parser.add_argument('--spindle', type=float, default=0.0,
                        help='the laser spindle speed (rad/s; default 0, as launched)')
    args = parser.parse_args(argv)
    for _ in range(args.rounds):
        bare_us = 1e6 / bare_physics_run(3000)
        figures = parts_run(args.steps, args.spindle)
        print(f'cpu {figures["cpu"]:.1f} us/step ({figures["cpu"] / bare_us:.1f}x bare mj_step '
              f'{bare_us:.1f}; load {os.getloadavg()[0]:.2f}): '
              + ', '.join(f'{part} {figures[part]:.1f}' for part in PARTS), flush=True)
    return 0


if __name__ == '__main__':
    sys.exit(main())
