"""How often a short walk falls: test_asi_live's two walks offline, its live variations sampled.

A live run differs from the deterministic offline tests in small things: how long the push
before the walk lasts, when each walk starts, which states a streaming client answers and
how late, and where the physics stands to the last bit. Each run here draws those from its
seed, perturbs its start with it (start_noise: the joints' angles and rates) and plays
the live test's sequence through the AtlasSimInterface, without ROS: DRCSim 2.7's start
(bdi_stand), a 40 N sideways push, walk_client's streamed walk of four steps, then the
actionlib server's (four ego-centric steps placed by the pelvis's x, y and yaw, STAND once
the last step has begun). A run falls when the state says ERROR_FALLING.

usage: python3 bench/walk_variations.py [--stride M] [--runs N] [--first-seed K] [--workers W]
(after `source ./env.sh`; about 30 CPU s a run). Figures: bench/README.md; `run_bench.py` runs
it in its `walking` section (bench/walking.py).
"""

from __future__ import annotations

import argparse
import json
import math
import random
import sys
from collections.abc import Sequence
from concurrent.futures import ProcessPoolExecutor
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from tutorial_atlas_control.asi import AtlasSimInterface, Behavior, Status, WalkClient
from tutorial_atlas_control.msgs.atlas_sim_interface import AsiCommand, ManipulateParams, StepData
from tutorial_atlas_control.sim import AtlasSimulator, VrcMode, load_gains_yaml, load_model
from tutorial_atlas_control.sim.vrc import WrenchInput
from tutorial_atlas_control.walking import Footstep, perturb_start, placed, straight_steps

CONFIG = Path(__file__).resolve().parents[1] / 'config' / 'atlas_controller.yaml'
#: The live test's push (N, sideways) and the 1 ms step.
PUSH_N = 40.0
STEP_S = 0.001
#: The robot's width between the feet in the walks (m) and each step's duration (s).
WIDTH_M = 0.24
DURATION_S = 0.63
#: Longest run (s of sim time) and the pelvis height below which it has surely fallen.
RUN_LIMIT_S = 40.0
DOWN_M = 0.5


@dataclass(frozen=True)
class Variation:
    """What a live run may vary, drawn from a seed (seconds of sim time)."""

    seed: int
    push_start_s: float      # the push sent at 3.5-3.9 s
    push_s: float            # held 0.75-1.5 s (sent, waited for, stopped: late on a loaded host)
    walk_delay_s: float      # walk_client started 2-3 s after the push ended
    client_lag_steps: int    # it answers the state of 1-30 steps before
    client_answers: float    # the fraction of states it answers (0.6)
    demo_delay_s: float      # the actionlib goal 0.5-2 s after the first walk's end

    @classmethod
    def draw(cls, seed: int) -> Variation:
        rng = random.Random(seed)
        return cls(seed, 3.5 + rng.uniform(0.0, 0.4), 0.75 + rng.uniform(0.0, 0.75),
                   2.0 + rng.uniform(0.0, 1.0), rng.randint(1, 30), 0.6,
                   rng.uniform(0.5, 2.0))


@dataclass(frozen=True)
class Outcome:
    """One run: whether and in which walk it fell, the steps each walk took, where it ended
    (s of sim time), its worst pelvis tilt (deg)."""

    seed: int
    stride_m: float
    fell_in: str | None      # 'walk_client', 'actionlib' or None
    steps: tuple[int, int]
    end_s: float
    worst_tilt_deg: float
    lowest_pelvis_m: float


def walk_command(steps: Sequence[Footstep]) -> AsiCommand:
    """A WALK with `steps` (foot link poses) and empty slots after them."""
    queue = [StepData(step.step_index, step.foot_index, step.duration_s, (step.x_m, step.y_m, 0.0),
                      (0.0, 0.0, math.sin(0.5 * step.yaw_rad), math.cos(0.5 * step.yaw_rad)),
                      0.0) for step in steps]
    queue += [StepData()] * (4 - len(queue))
    return AsiCommand(0, Behavior.WALK, tuple(queue), False, StepData(), False,
                      ManipulateParams(), None, 0)


def command_of(behavior: Behavior) -> AsiCommand:
    return AsiCommand(0, behavior, (StepData(),) * 4, False, StepData(), False,
                      ManipulateParams(), None, 0)


def pelvis_yaw_and_tilt(quaternion_wxyz: np.ndarray) -> tuple[float, float]:
    """The pelvis's yaw (rad) and its tilt from upright (deg)."""
    w, x, y, z = (float(v) for v in quaternion_wxyz)
    yaw = math.atan2(2.0 * (w * z + x * y), 1.0 - 2.0 * (y * y + z * z))
    return yaw, math.degrees(math.acos(max(-1.0, min(1.0, 1.0 - 2.0 * (x * x + y * y)))))


def demo_steps(stride_m: float, origin_xy: tuple[float, float], yaw_rad: float) -> list[Footstep]:
    """The actionlib goal of test/support/walk_demo_goal.py, made world poses as the server
    does: four ego-centric steps, the last beside the one before."""
    ego = [Footstep(k, (k + 1) % 2, stride_m * (k if k < 4 else k - 1),
                    WIDTH_M / 2 if k % 2 else -WIDTH_M / 2, 0.0, DURATION_S)
           for k in range(1, 5)]
    return placed(ego, origin_xy, yaw_rad)


def run(seed: int | None, stride_m: float) -> Outcome:
    """The live test's sequence under the variation of `seed`, its start perturbed by the
    seed too (start_noise); seed None: seed 0's variation from an unperturbed start."""
    variation = Variation.draw(0 if seed is None else seed)
    rng = random.Random(variation.seed + 1_000_003)
    sim = AtlasSimulator(load_model(), load_gains_yaml(CONFIG), startup_mode=VrcMode.BDI_STAND)
    interface = AtlasSimInterface(sim, True)
    perturb_start(sim.atlas, sim.data, seed, on_ground=False)  # pinned in the air at first
    push_start = round(variation.push_start_s / STEP_S)
    push_end = push_start + round(variation.push_s / STEP_S)
    walk_start = push_end + round(variation.walk_delay_s / STEP_S)
    lag = variation.client_lag_steps
    seen: list[tuple[int, int, int, int]] = []  # (behaviour, status, current, needed)
    client: WalkClient | None = None
    phase, demo_start, stand_sent = 'stand', 0, False
    worst_tilt, lowest = 0.0, math.inf
    taken = {'walk_client': 0, 'actionlib': 0}
    for k in range(round(RUN_LIMIT_S / STEP_S)):
        if k == push_start:
            sim.apply_input(WrenchInput((0.0, PUSH_N, 0.0), (0.0, 0.0, 0.0)))
        elif k == push_end:
            sim.apply_input(WrenchInput((0.0, 0.0, 0.0), (0.0, 0.0, 0.0)))
        late = seen[-lag] if len(seen) >= lag else None
        if k == walk_start:
            feet = interface.state().foot_poses
            origin = (0.5 * float(feet[0][0] + feet[1][0]), 0.5 * float(feet[0][1] + feet[1][1]))
            client = WalkClient(placed(straight_steps(4, stride_m, WIDTH_M, DURATION_S),
                                       origin, 0.0))
            phase = 'walk_client'
        if phase == 'walk_client' and client is not None and late is not None \
                and rng.random() < variation.client_answers:
            steps = client.on_state(*late)
            if steps is not None:
                interface.apply(walk_command(steps))
            elif client.outcome is not None:
                phase, demo_start = 'between', k + round(variation.demo_delay_s / STEP_S)
        if phase == 'between' and k == demo_start:
            pelvis = interface.state().pelvis_position_m
            yaw, _ = pelvis_yaw_and_tilt(sim.data.qpos[3:7])
            interface.apply(walk_command(demo_steps(stride_m, (float(pelvis[0]),
                                                               float(pelvis[1])), yaw)))
            phase = 'actionlib'
        elif phase == 'actionlib' and not stand_sent and late is not None and late[2] >= 3:
            interface.apply(command_of(Behavior.STAND))
            stand_sent = True
        sim.step()
        state = interface.state()
        interface.end_step()
        feedback = state.walk_feedback
        seen.append((state.current_behavior, state.behavior_feedback.status_flags,
                     feedback.current_step_index, feedback.next_step_index_needed))
        if phase in taken:
            taken[phase] = max(taken[phase], feedback.current_step_index)
        _, tilt = pelvis_yaw_and_tilt(sim.data.qpos[3:7])
        worst_tilt, lowest = max(worst_tilt, tilt), min(lowest, float(sim.data.qpos[2]))
        if state.behavior_feedback.status_flags == Status.ERROR_FALLING \
                or sim.data.qpos[2] < DOWN_M:
            return Outcome(variation.seed, stride_m, phase,
                           (taken['walk_client'], taken['actionlib']), round(k * STEP_S, 3),
                           round(worst_tilt, 1), round(lowest, 3))
        if stand_sent and state.current_behavior == Behavior.STAND and len(seen) > lag \
                and k > demo_start + round(3.0 / STEP_S):
            break
    return Outcome(variation.seed, stride_m, None, (taken['walk_client'], taken['actionlib']),
                   round(k * STEP_S, 3), round(worst_tilt, 1), round(lowest, 3))


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog='walk_variations.py', description=__doc__.split('\n\n')[0],
        epilog='Prints one JSON line a run, then a summary line.')
    parser.add_argument('--stride', type=float, default=0.2, help='stride (m; default 0.2)')
    parser.add_argument('--runs', type=int, default=12, help='runs (default 12)')
    parser.add_argument('--first-seed', type=int, default=1,
                        help='the first run\'s seed (default 1)')
    parser.add_argument('--workers', type=int, default=2, help='processes (default 2)')
    return parser


def main(argv: Sequence[str] | None = None) -> int:
    parser = _parser()
    args = parser.parse_args(argv)
    if args.runs < 1 or args.workers < 1 or args.first_seed < 0 \
            or not 0.0 < args.stride <= 0.4:
        parser.error('--runs and --workers are at least 1, --first-seed at least 0, '
                     '--stride in (0, 0.4] m')
    seeds = range(args.first_seed, args.first_seed + args.runs)
    with ProcessPoolExecutor(args.workers) as pool:
        outcomes = []
        for outcome in pool.map(run, seeds, [args.stride] * args.runs):
            outcomes.append(outcome)
            print(json.dumps(asdict(outcome)), flush=True)
    fell = [o for o in outcomes if o.fell_in is not None]
    tilts = np.array([o.worst_tilt_deg for o in outcomes if o.fell_in is None] or [math.nan])
    print(f'walk_variations: stride {args.stride:g} m: {len(fell)} of {len(outcomes)} runs fell'
          f' ({", ".join(f"seed {o.seed} in {o.fell_in}" for o in fell) or "none"}); worst '
          f'pelvis tilt of the others: median {np.median(tilts):.1f} deg, max '
          f'{np.max(tilts):.1f}')
    return 0


if __name__ == '__main__':
    sys.exit(main())
