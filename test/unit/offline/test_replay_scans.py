"""The head laser's recorded scans: an offline run's bag holds them at 40 Hz, a replay casts
them again bit for bit (and finds a changed one), and analyze_bag's cloud places a scan's
floor hits on the floor."""

from __future__ import annotations

import dataclasses
import math
from pathlib import Path

import mujoco
import numpy as np
import pytest

from tutorial_atlas_control.bags import read_bag, read_laser_scans, scan_cloud
from tutorial_atlas_control.bags.feet import RecordedKinematics
from tutorial_atlas_control.offline.player import run_offline
from tutorial_atlas_control.offline.replay import load_recording, replay
from tutorial_atlas_control.sensors import HOKUYO, MAX_SPINDLE_SPEED, HokuyoLaser

REPO = Path(__file__).resolve().parents[3]
CONFIG = REPO / 'config' / 'atlas_controller.yaml'


@pytest.fixture(scope='module')
def still_run(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """0.6 s offline: the pin, then the head pitched down 0.6 rad (neck_ay, the fourth joint),
    so that the level scan plane tilts onto the floor ahead."""
    tmp = tmp_path_factory.mktemp('scans')
    trajectory = tmp / 'still.yaml'
    trajectory.write_text('still:\n  - [0.1, "0 0 0 0.6 ' + ' '.join(['0'] * 24) + '"]\n')
    bag = tmp / 'run.bag'
    run_offline(str(trajectory), 'still', bag, settle_s=0.3, start_after_s=0.3,
                gains_file=CONFIG, scans=True)
    return bag


def test_an_offline_run_records_the_scans_and_a_replay_casts_them_again(still_run: Path
                                                                         ) -> None:
    scans = read_laser_scans(still_run)
    assert scans is not None and scans.frame_id == 'head_hokuyo_frame'
    assert set(np.diff(scans.stamp_ns[1:])) == {25_000_000}
    assert scans.ranges.shape[1] == HOKUYO.samples
    assert np.isfinite(scans.ranges[-1]).sum() > 300  # the floor ahead, with noise
    result = replay(load_recording(still_run))
    assert result.scans is not None and result.scans.compared == len(scans.stamp_ns)
    assert result.scans.same and result.reproduced
    changed = dataclasses.replace(load_recording(still_run), scans=dataclasses.replace(
        scans, ranges=scans.ranges.copy()))
    changed.scans.ranges[5, 100] = 12.5
    result = replay(changed)
    assert result.scans.differing == 1 and not result.reproduced
    assert result.scans.first_difference_s == pytest.approx(scans.stamp_ns[5] / 1e9)


def test_the_cloud_puts_a_spinning_scans_floor_hits_on_the_floor(still_run: Path) -> None:
    """The spindle simulated again from a recorded command (50 RPM from 0.1 s), each scan cast
    on the recorded pose at that angle: the points of the rays that hit the floor are at
    z = 0 within 1 mm (float32 ranges at grazing angles): the cloud's geometry is the laser's."""
    data = read_bag(still_run)
    scans = dataclasses.replace(read_laser_scans(still_run),
                                spindle_commands=[(100_000_000, MAX_SPINDLE_SPEED)])
    from tutorial_atlas_control.bags import spindle_angles

    angles = spindle_angles(scans)
    assert angles[0] == 0.0 and angles[-1] > 1.0
    kinematics = RecordedKinematics(data)
    laser = HokuyoLaser(kinematics.atlas.model)
    floor = mujoco.mj_name2id(kinematics.atlas.model, mujoco.mjtObj.mjOBJ_GEOM, 'floor')
    ranges = np.full(scans.ranges.shape, np.inf, np.float32)
    on_floor = 0
    for row, stamp in enumerate(scans.stamp_ns.tolist()):
        placed = kinematics.place(data.run_time_s(stamp / 1e9, 0))
        distance = laser.cast(placed, float(angles[row]))
        hit = laser.geom_id == floor
        ranges[row, hit] = distance[hit]
        on_floor += int(hit.sum())
    cloud = scan_cloud(data, dataclasses.replace(scans, ranges=ranges))
    assert on_floor > 100 and len(cloud) == on_floor
    np.testing.assert_allclose(cloud[:, 2], 0.0, atol=1e-3)  # float32 ranges, grazing rays
    assert math.isfinite(float(cloud[:, 0].max()))
