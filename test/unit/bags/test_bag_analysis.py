"""Tests of bag_analysis: the metrics of synthetic bags, with known answers."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from rosbags.rosbag1 import Writer

from support.synthetic_bags import (
    clock,
    control_mode,
    joint_commands,
    joint_state,
    odometry,
    tracking_records,
    write_bag,
    write_run_bag,
)
from tutorial_atlas_control.bags.analysis import EFFORT_LIMITS_NM, analyze, analyze_bag
from tutorial_atlas_control.bags.reader import read_bag
from tutorial_atlas_control.errors import BagAnalysisError
from tutorial_atlas_control.joints import JOINT_NAMES, NUM_JOINTS

ELX = JOINT_NAMES.index('l_arm_elx')
KNY = JOINT_NAMES.index('l_leg_kny')


def states(times_s, value_at=lambda t_s: np.zeros(NUM_JOINTS), **kwargs):
    return [joint_state(t_s, value_at(t_s), **kwargs) for t_s in times_s]


def with_joint(index: int, value: float) -> np.ndarray:
    position = np.zeros(NUM_JOINTS)
    position[index] = value
    return position


# ---------------------------------------------------------------- modes and fall


def test_mode_timeline_collapses_repeats_and_uses_bag_time(tmp_path: Path) -> None:
    records = [clock(0.5), control_mode(0.5, 'Stand'), control_mode(0.75, 'Stand'),
               control_mode(1.5, 'User'), control_mode(2.25, 'Freeze'),
               control_mode(2.5, 'ragdoll')]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.mode_timeline == [(0.0, 'Stand'), (1.0, 'User'), (1.75, 'Freeze'),
                                      (2.0, 'ragdoll')]
    assert analysis.to_dict()['mode_timeline'][1] == {'time': 1.0, 'mode': 'User'}


def test_applied_vrc_inputs_join_the_mode_timeline(tmp_path: Path) -> None:
    from support.synthetic_bags import TYPESTORE, Record
    from tutorial_atlas_control.bags.report import format_summary
    from tutorial_atlas_control.sim import vrc

    def applied(t_s: float, item: vrc.SimInput, seq: int) -> Record:
        event = vrc.InputEvent(round(t_s * 1e9), 0, seq, item)
        msg = TYPESTORE.types['std_msgs/msg/String'](data=event.to_json())
        return Record('/atlas/sim_inputs', 'std_msgs/String', t_s, msg)
    trajectory = vrc.TrajectoryInput((0, 3), ((0.1, 0.2), (0.3, 0.4)), (0, 10**8), 0)
    records = [clock(0.5), control_mode(0.5, 'Stand'), control_mode(1.5, 'User'),
               applied(1.25, vrc.ModeInput(vrc.VrcMode.HARNESSED), 0),
               applied(2.0, vrc.WrenchInput((300.0, 0.0, 0.0), (0.0, 0.0, 0.0)), 1),
               applied(2.5, trajectory, 2)]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.input_timeline == [
        (0.75, '/atlas/mode mode=harnessed'),
        (1.5, '/atlas/apply_pelvis_force force=[300.0, 0.0, 0.0], torque=[0.0, 0.0, 0.0]'),
        (2.0, '/joint_trajectory 2 joints, 2 points')]
    text = format_summary(analysis)
    assert ('  0.000 s  Stand\n      0.750 s  /atlas/mode mode=harnessed\n'
            '      1.000 s  User\n      1.500 s  /atlas/apply_pelvis_force') in text
    assert analysis.to_dict()['inputs'][0] == {'time': 0.75,
                                               'input': '/atlas/mode mode=harnessed'}


def test_fall_time_is_first_pelvis_height_below_threshold(tmp_path: Path) -> None:
    # Bag starts at 0.25 s sim time; the pelvis first dips below 0.5 m at 3.137 s.
    fall_s = 3.137
    records = [clock(0.25)] + [odometry(t_s, 0.93 if t_s < fall_s else 0.3)
                               for t_s in np.round(0.25 + np.arange(500) * 0.001 * 11, 6)]
    records.append(odometry(fall_s, 0.49))
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.fell is True
    assert analysis.fall_time_s == pytest.approx(fall_s - 0.25, abs=1e-3)
    assert analysis.min_pelvis_height_m == pytest.approx(0.3)


def test_no_fall_when_pelvis_stays_up(tmp_path: Path) -> None:
    records = [odometry(t_s, 0.5 + 0.1 * t_s) for t_s in np.arange(10) * 0.1]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert (analysis.fell, analysis.fall_time_s) == (False, None)
    assert 'joints' in analysis.unavailable


# ---------------------------------------------------------------- tracking and commands


@pytest.mark.parametrize('names_style', ['bare', 'prefixed', 'empty', 'subset'])
def test_tracking_error_known_answer(tmp_path: Path, names_style: str) -> None:
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', tracking_records(names_style)))
    assert list(analysis.joints) == ['l_arm_elx']
    joint = analysis.joints['l_arm_elx']
    assert joint.samples == 10
    assert joint.commanded
    assert joint.rms_error_rad == pytest.approx(np.sqrt((5 * 0.05**2 + 5 * 0.15**2) / 10), abs=1e-6)
    assert joint.max_error_rad == pytest.approx(0.15, abs=1e-6)
    assert analysis.to_dict()['joints']['l_arm_elx']['max_error'] == pytest.approx(0.15, abs=1e-6)


def test_subset_commands_hold_each_joints_last_value(tmp_path: Path) -> None:
    """A command for l_arm_elx only must not erase the held value of l_leg_kny."""
    records = [joint_commands(0.0, [0.3, 0.1], names=['l_leg_kny', 'atlas::l_arm_elx']),
               joint_commands(0.01, [0.2], names=['l_arm_elx'])]
    records += states([0.005, 0.015], lambda _: with_joint(KNY, 0.3) + with_joint(ELX, 0.2))
    data = read_bag(write_bag(tmp_path / 'run.bag', records))
    np.testing.assert_allclose(data.commands.held[1, [KNY, ELX]], [0.3, 0.2])
    assert np.isnan(data.commands.position[1, KNY])
    analysis = analyze(data)
    assert analysis.joints['l_arm_elx'].max_error_rad == pytest.approx(0.1)
    assert 'l_leg_kny' not in analysis.joints  # commanded constant, measured constant


def test_joint_that_moved_without_command_is_reported(tmp_path: Path) -> None:
    records = states(np.arange(10) * 0.01, lambda t_s: with_joint(KNY, t_s))
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert list(analysis.joints) == ['l_leg_kny']
    joint = analysis.joints['l_leg_kny']
    assert (joint.commanded, joint.rms_error_rad, joint.samples) == (False, None, 0)
    assert joint.measured_range_rad == pytest.approx(0.09)
    assert 'commands' in analysis.unavailable and 'command_age' in analysis.unavailable


def test_command_rate_and_age(tmp_path: Path) -> None:
    records = [joint_commands(t_s, np.zeros(NUM_JOINTS)) for t_s in (0.0, 0.02, 0.04)]
    records += states([0.005, 0.015, 0.025, 0.045])
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.command_rate_hz == pytest.approx(50.0)
    assert analysis.command_age_mean_s == pytest.approx((0.005 + 0.015 + 0.005 + 0.005) / 4)
    assert analysis.command_age_max_s == pytest.approx(0.015)


@pytest.mark.parametrize('compression', ['bz2', 'lz4'])
def test_compressed_bag(tmp_path: Path, compression: str) -> None:
    path = write_bag(tmp_path / 'run.bag', tracking_records('bare'), compression=compression)
    assert analyze_bag(path).joints['l_arm_elx'].max_error_rad == pytest.approx(0.15)


# ---------------------------------------------------------------- effort saturation


def test_effort_limit_time(tmp_path: Path) -> None:
    """l_leg_kny at +-limit (or within tolerance) for 20 of 100 1-kHz samples -> 20 ms."""
    limit = EFFORT_LIMITS_NM['l_leg_kny']
    records = []
    for step in range(100):
        effort = np.zeros(NUM_JOINTS)
        if 10 <= step < 30:
            effort[KNY] = (limit, -limit, limit - 0.005)[step % 3]
        elif step == 50:
            effort[KNY] = limit - 1.0  # close, but not at the limit
        effort[JOINT_NAMES.index('neck_ay')] = 4.0
        records.append(joint_state(step * 0.001, np.zeros(NUM_JOINTS), effort=effort))
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert list(analysis.effort_saturation) == ['l_leg_kny']
    saturation = analysis.effort_saturation['l_leg_kny']
    assert saturation.duration_s == pytest.approx(0.020, abs=1e-9)
    assert saturation.first_time_s == pytest.approx(0.010)
    assert (saturation.samples, saturation.limit_nm) == (20, 220.0)


def test_effort_limit_table() -> None:
    assert list(EFFORT_LIMITS_NM) == list(JOINT_NAMES)
    assert EFFORT_LIMITS_NM['back_mby'] == 206.843
    assert EFFORT_LIMITS_NM['r_leg_lhy'] == EFFORT_LIMITS_NM['l_leg_lhy'] == 260.0
    assert EFFORT_LIMITS_NM['r_arm_mwx'] == 60.0


# ---------------------------------------------------------------- missing data


def test_bag_without_joint_states_still_summarizes(tmp_path: Path) -> None:
    records = [control_mode(0.0, 'Stand'), odometry(0.0, 0.9), odometry(1.0, 0.2),
               joint_commands(0.5, np.zeros(NUM_JOINTS))]
    analysis = analyze_bag(write_bag(tmp_path / 'run.bag', records))
    assert analysis.fell is True and analysis.fall_time_s == pytest.approx(1.0)
    assert analysis.joints == {} and analysis.effort_saturation is None
    assert set(analysis.unavailable) == {'joints', 'command_age', 'effort_saturation'}
    assert '/atlas/joint_states' in analysis.unavailable['joints']


def test_an_empty_bag_is_refused(tmp_path: Path) -> None:
    path = tmp_path / 'empty.bag'
    with Writer(path):
        pass
    with pytest.raises(BagAnalysisError, match=(
            r'^.*empty\.bag holds no message \(a launch that stopped before its simulator was '
            r'ready records nothing\); give a bag of a run\.$')):
        analyze_bag(path)


def test_analysis_is_deterministic(tmp_path: Path) -> None:
    path = write_run_bag(tmp_path / 'run.bag', 3.0, with_imu=False, fall_time_s=1.5)
    first, second = analyze_bag(path).to_dict(), analyze_bag(path).to_dict()
    assert first == second
    # The pelvis sinks 0.73 m/s from 0.93 m at 1.5 s: below 0.5 m after 1.5 + 0.43/0.73 s,
    # seen at the next 100 Hz odometry sample.
    assert first['fell'] and first['fall_time'] == pytest.approx(2.09, abs=1e-6)
