"""The gazebo_tutorials Atlas walking tutorial's clients (test/support/walking_tutorial.py),
offline and deterministic, from atlas.launch's default start: the tutorial's hold, an ASI
STAND, then the client on every state. The static client (its counter from 0, advancing on
the first SWAYING, step_index 1, poses from the first pos_est) takes its first 8 static
steps round its circle, each landing within 5 cm and 0.1 rad of its pose (planted, Step
taking the newest target instead of the one desired at touchdown: it fell at its third); the
dynamic client streams its window from next_step_index_needed (0 before the walk) for 10
steps. No fall, the pelvis above 0.8 m and on its way round. The whole circle, 60 of 60 for
both, was measured once offline and live (docs/controllers.md); 60 static steps are about
50 CPU s, a sixth of make test's offline part. About 20 CPU s.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from pathlib import Path

import pytest

from support.walking_tutorial import (
    DynamicCircleClient,
    StaticCircleClient,
    command,
    landing_errors,
)
from tutorial_atlas_control.asi import AtlasSimInterface, Behavior, Status
from tutorial_atlas_control.sim import AtlasSimulator, load_gains_yaml, load_model

#: Offline (no ROS, no claim about time): `make test` runs it at the lowest priority.
pytestmark = pytest.mark.offline

CONFIG = Path(__file__).resolve().parents[2] / 'config' / 'atlas_controller.yaml'
#: The ASI STAND (past the 1 s pin) and the client's first state (s of sim time).
STAND_AT_S = 1.5
CLIENT_AT_S = 3.5
#: The static client's steps and the dynamic client's (a seventh and a sixth of the circle).
STATIC_STEPS = 8
DYNAMIC_STEPS = 10
#: A static step takes about 3.1 s; a walking one 0.63 s.
STATIC_LIMIT_S = 4.0 * STATIC_STEPS
DYNAMIC_LIMIT_S = 1.0 * DYNAMIC_STEPS
LANDING_WITHIN_M = 0.05
LANDING_TURN_WITHIN_RAD = 0.1
PELVIS_ABOVE_M = 0.8
STEPPING = 2
#: Round the circle, the pelvis goes to the start's left: past this (m) by its 8th static
#: step (0.51 m) and its 10th walking one (1.0 m).
FAR_SIDE_M = 0.35


@dataclass
class Went:
    """What the state said while a client drove the robot."""

    landings: list[tuple[float, float]] = field(default_factory=list)
    walked: int = 0
    lowest_pelvis_m: float = math.inf
    fell: bool = False
    #: The pelvis's furthest y (m): the circle's far side is 2 R to the walker's left.
    furthest_y_m: float = -math.inf


def from_the_default_start() -> AtlasSimInterface:
    """atlas.launch's default start, STAND asked for at STAND_AT_S, run to CLIENT_AT_S."""
    sim = AtlasSimulator(load_model(), load_gains_yaml(CONFIG))
    interface = AtlasSimInterface(sim, hold_at_start=True)
    for k in range(round(CLIENT_AT_S / sim.dt_s)):
        if k == round(STAND_AT_S / sim.dt_s):
            assert interface.current_behavior == Behavior.USER
            interface.apply(command(Behavior.STAND))
        sim.step()
        interface.end_step()
    assert interface.current_behavior == Behavior.STAND
    return interface


def drive(interface: AtlasSimInterface, client: StaticCircleClient | DynamicCircleClient,
          limit_s: float) -> Went:
    sim, went = interface.sim, Went()
    previous_flags = 0
    for _ in range(round(limit_s / sim.dt_s)):
        state = interface.state()
        went.lowest_pelvis_m = min(went.lowest_pelvis_m, state.pelvis_position_m[2])
        went.furthest_y_m = max(went.furthest_y_m, state.pelvis_position_m[1])
        if state.behavior_feedback.status_flags == Status.ERROR_FALLING:
            went.fell = True
            break
        flags = state.step_feedback.status_flags
        went.walked = max(went.walked, state.walk_feedback.current_step_index)
        if isinstance(client, StaticCircleClient):
            interface.apply(client.on_state(state))
            if previous_flags == STEPPING and flags != STEPPING:
                assert client.origin_xy is not None
                went.landings.append(landing_errors(state.foot_poses, client.counter - 2,
                                                    client.origin_xy))
            previous_flags = flags
            if len(went.landings) == STATIC_STEPS:
                break
        else:
            if went.walked >= DYNAMIC_STEPS:
                break
            interface.apply(client.on_state(state))
        sim.step()
        interface.end_step()
    return went


def test_the_static_client_steps_round_its_circle() -> None:
    client = StaticCircleClient()
    went = drive(from_the_default_start(), client, STATIC_LIMIT_S)
    worst_m = max(distance for distance, _ in went.landings)
    worst_rad = max(turn for _, turn in went.landings)
    print(f'figures: static client {len(went.landings)} steps, worst landing '
          f'{worst_m * 100:.1f} cm / {worst_rad:.3f} rad, lowest pelvis '
          f'{went.lowest_pelvis_m:.3f} m')
    assert not went.fell and len(went.landings) == STATIC_STEPS
    assert worst_m < LANDING_WITHIN_M and worst_rad < LANDING_TURN_WITHIN_RAD
    assert went.lowest_pelvis_m > PELVIS_ABOVE_M
    assert client.origin_xy is not None  # on its way round
    assert went.furthest_y_m - client.origin_xy[1] > FAR_SIDE_M


def test_the_dynamic_client_walks_round_its_circle() -> None:
    client = DynamicCircleClient()
    went = drive(from_the_default_start(), client, DYNAMIC_LIMIT_S)
    print(f'figures: dynamic client {went.walked} steps, lowest pelvis '
          f'{went.lowest_pelvis_m:.3f} m')
    assert not went.fell and went.walked >= DYNAMIC_STEPS
    assert went.lowest_pelvis_m > PELVIS_ABOVE_M
    assert client.origin_xy is not None
    assert went.furthest_y_m - client.origin_xy[1] > FAR_SIDE_M
