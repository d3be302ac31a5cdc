"""Atlas started away from the origin and turned, offline: DRCSim's VRC start (bdi_stand:
pinned in the Stand pose, released at 1 s, the balancing Stand at 2 s) stands where it
started, on the flat plane and on a plane raised to the VRC course's ground (z 0.03);
DRCSim's fixed Walk queue walks from there, along the start's heading; and an offline run
from the start replays exactly.

About 0.3 s of CPU per simulated second; 30 s simulated in all.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from tutorial_atlas_control.asi import AtlasSimInterface
from tutorial_atlas_control.balance.stand import yaw_of
from tutorial_atlas_control.course import parse_start
from tutorial_atlas_control.offline import OfflineWorld, replay_bag, run_offline
from tutorial_atlas_control.sim import (
    DEFAULT_GAINS_FILE,
    MODEL_PATH,
    STANDING_PELVIS_M,
    AtlasSimulator,
    ControlMode,
    VrcMode,
    load_gains_yaml,
    load_model,
)

pytestmark = pytest.mark.offline

#: 3 m east, 2 m south, facing north (+y): away from the origin and turned 90 degrees.
TURNED = parse_start('3 -2 0.9 1.5707963267948966')
#: The raised plane's height (m): the VRC course's flat ground is at about z 0.03.
RAISED_M = 0.03
#: The pelvis's height (m) standing in the Stand at the origin (test_stand_balance's 0.912).
STAND_PELVIS_M = 0.911
FLOOR = '<geom name="floor" type="plane" size="0 0 0.05"'


def raised_model(tmp_path: Path) -> Path:
    text = MODEL_PATH.read_text()
    assert FLOOR in text
    path = tmp_path / 'atlas_raised.xml'
    path.write_text(text.replace(FLOOR, f'{FLOOR} pos="0 0 {RAISED_M}"'))
    return path


def vrc_start(model: Path) -> tuple[AtlasSimulator, AtlasSimInterface]:
    """The VRC launches' simulator: bdi_stand at TURNED, the library's Stand as atlas.launch
    installs it."""
    sim = AtlasSimulator(load_model(model), load_gains_yaml(DEFAULT_GAINS_FILE),
                         startup_mode=VrcMode.BDI_STAND, start=TURNED)
    return sim, AtlasSimInterface(sim, hold_at_start=True)


def run(sim: AtlasSimulator, interface: AtlasSimInterface, seconds: float) -> float:
    """Step `seconds`; the lowest pelvis height (m) on the way."""
    lowest = math.inf
    for _ in range(int(round(seconds / sim.dt_s))):
        sim.step()
        interface.end_step()
        lowest = min(lowest, float(sim.data.qpos[2]))
    return lowest


@pytest.mark.parametrize('ground_m', [0.0, RAISED_M])
def test_the_vrc_start_stands_where_it_started(ground_m: float, tmp_path: Path) -> None:
    sim, interface = vrc_start(raised_model(tmp_path) if ground_m else MODEL_PATH)
    # DRCSim's times: pinned in the Stand pose under the user's PID, released at 1 s, the
    # Stand (BDI's, here the balancing one) at 2 s.
    run(sim, interface, 0.999)
    assert sim.pinned and sim.mode is ControlMode.USER
    np.testing.assert_allclose(sim.data.qpos[:2], (3.0, -2.0), atol=1e-3)
    run(sim, interface, 0.002)
    assert not sim.pinned and sim.mode is ControlMode.USER
    run(sim, interface, 0.998)
    assert sim.mode is ControlMode.USER
    run(sim, interface, 0.002)
    assert sim.mode is ControlMode.STAND
    run(sim, interface, 0.5)
    stand = interface.stand
    assert stand.last_state is not None
    feet = stand.last_state.sole_centres.copy()
    lowest = run(sim, interface, 5.0)  # from 2.5 s to 7.5 s: 6.5 s after the release
    pelvis = sim.data.qpos[:3]
    travel = float(np.max(np.linalg.norm(stand.last_state.sole_centres - feet, axis=1)))
    heading = yaw_of(sim.data.xmat[sim.atlas.pelvis_body_id].reshape(3, 3))
    print(f'\nground {ground_m} m: pelvis {pelvis.round(4).tolist()}, yaw {heading:.4f} rad, '
          f'lowest {lowest:.4f} m, feet moved {travel * 1000:.3f} mm')
    assert lowest > ground_m + STANDING_PELVIS_M
    assert pelvis[2] == pytest.approx(ground_m + STAND_PELVIS_M, abs=0.01)
    np.testing.assert_allclose(pelvis[:2], (3.0, -2.0), atol=0.02)
    assert heading == pytest.approx(math.pi / 2, abs=0.02)
    assert travel < 0.001


def test_drcsims_walk_queue_walks_along_the_starts_heading() -> None:
    """/atlas/control_mode Walk: DRCSim's four steps of 0.2 m, made for a robot at the origin
    facing +x, carried to the start: the robot walks north from (3, -2)."""
    sim, interface = vrc_start(MODEL_PATH)
    run(sim, interface, 4.0)
    sim.set_mode(ControlMode.WALK)
    lowest = run(sim, interface, 8.0)
    x, y, _z = sim.data.qpos[:3].tolist()
    print(f'\nwalked to ({x:.3f}, {y:.3f}), lowest pelvis {lowest:.3f} m')
    assert sim.mode is ControlMode.STAND  # back in Stand by itself
    assert lowest > STANDING_PELVIS_M
    assert x == pytest.approx(3.0, abs=0.05)
    assert y == pytest.approx(-2.0 + 0.7, abs=0.1)


def test_an_offline_run_from_the_start_replays_exactly(tmp_path: Path) -> None:
    bag = tmp_path / 'turned.bag'
    run_offline('Traj_data2.yaml', 'touchdown', bag, settle_s=0.5,
                world=OfflineWorld(MODEL_PATH, TURNED))
    result = replay_bag(bag)
    assert result.config.start == '3.0 -2.0 0.9 1.5707963267948966'
    assert result.reproduced
    assert result.pelvis_position is not None and result.pelvis_position.max_abs == 0.0
