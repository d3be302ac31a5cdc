"""The inbox of a node serving a 1 kHz controller, before and after its lone-command path, in
one process: `python3 bench/inbox_ab.py [BLOCKS]` (by hand, not a section).

Two processes on a shared host differ by more than the change (bare mj_step 34-204 µs from
one run to the next, 2026-11-30); in one process, blocks of 100 of node_loop.py --phases'
steps alternate between the inbox as main had it before (every step's messages through the
general path, the decoder's full-message path: both still there) and as it is, and each
block pair gives a ratio.
"""

from __future__ import annotations

import os
import statistics
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

sys.path.insert(0, str(Path(__file__).resolve().parent))
sys.path.insert(0, str(Path(__file__).resolve().parents[1] / 'test'))

from node_loop import (
    CONTROLLER_RUN_TOPICS,
    PHASES,
    _timed_steps,
    bare_physics_run,
    controller_command,
)
from offline import make_simulator

from support import fake_rospy

#: Steps per block (one side's turn).
BLOCK_STEPS = 100


def general_variant(inbox: Any) -> tuple[Callable[[], None], Callable[[bytes], Any]]:
    """(before_step, decode) as main had them before: every message through the general
    path (_apply_received), the decoder's _decode_full before its general decode."""
    from tutorial_atlas_control.msgs import atlas_command

    def apply_pending() -> None:
        pending = inbox.pending
        received = []
        while pending:
            received.append(pending.popleft())
        inbox._apply_received(received)

    def decode(raw: bytes) -> Any:
        full = atlas_command._decode_full(raw, inbox.atlas_decoder.memo)
        return full if full is not None else atlas_command.decode_atlas_command(raw)
    return apply_pending, decode


def inbox_ab_run(blocks: int) -> dict[str, list[list[float]]]:
    """µs per step of each of PHASES, per block, for 'before' and 'after', interleaved."""
    sim = make_simulator()
    for _ in range(1500):
        sim.step()
    raw = controller_command(sim)
    runs: dict[str, list[list[float]]] = {'before': [], 'after': []}
    with fake_rospy.fake_ros_node(sim, 0, tcp=True, heard=CONTROLLER_RUN_TOPICS) as node:
        inbox = node.loop.tick.controller
        variants = {'before': general_variant(inbox),
                    'after': (inbox.apply_pending, inbox.atlas_decoder.decode)}
        for block in range(blocks):
            for name in ('before', 'after') if block % 2 == 0 else ('after', 'before'):
                inbox.before_step, inbox.atlas_decoder.decode = variants[name]
                spent = _timed_steps(node.loop, raw, BLOCK_STEPS)
                runs[name].append([value / BLOCK_STEPS * 1e6 for value in spent])
    return runs


def main() -> int:
    blocks = int(sys.argv[1]) if len(sys.argv) > 1 else 60
    runs = inbox_ab_run(blocks)
    bare_us = 1e6 / bare_physics_run(3000)
    print(f'{blocks} blocks of {BLOCK_STEPS} steps a side, load {os.getloadavg()[0]:.1f}, '
          f'bare mj_step {bare_us:.1f} µs beside; p25 / median, µs per step:')
    for name, rows in runs.items():
        columns = [*zip(*rows), [sum(row) for row in rows]]
        print(f'  {name}: ' + '; '.join(
            f'{phase} {statistics.quantiles(column, n=4)[0]:.1f} / {statistics.median(column):.1f}'
            for phase, column in zip((*PHASES, 'tick'), columns)))
    ratios = [sum(after[:2]) / sum(before[:2])
              for after, before in zip(runs['after'], runs['before'])]
    quartiles = statistics.quantiles(ratios, n=4)
    print(f'after/before of command in + inbox, per block pair: median {quartiles[1]:.3f} '
          f'(p25 {quartiles[0]:.3f}, p75 {quartiles[2]:.3f})')
    return 0


if __name__ == '__main__':
    sys.exit(main())
